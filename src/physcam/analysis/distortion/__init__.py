"""Lens distortion: the real distortion field (:mod:`.field`), models fitted to it (:mod:`.models`,
:mod:`.anamorphic`), ST-maps over the whole frame (:mod:`.stmap`), distortion across focus
(:mod:`.across_focus`) and OpenTrackIO's coefficients (:mod:`.openlensio`) (docs/distortion.md).

``physcam.analysis.distortion`` was the module now at :mod:`.field`: its names answer here for one
version, with a DeprecationWarning (:mod:`physcam._moved`).
"""

from ..._moved import folded_names

__getattr__ = folded_names(__name__)
