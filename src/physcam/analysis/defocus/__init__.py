"""Defocus: depth of field from real rays (:mod:`.real_dof`), bokeh (:mod:`.bokeh`, measured by
:mod:`.blob`), the lens's own defocus applied to a render with depth (:mod:`.render`, :mod:`.kernels`,
:mod:`.exr`) and light-field images (:mod:`.lightfield`) (docs/defocus.md).

``physcam.analysis.defocus`` was the module now at :mod:`.render`: its names answer here for one
version, with a DeprecationWarning (:mod:`physcam._moved`).
"""

from ..._moved import folded_names

__getattr__ = folded_names(__name__)
