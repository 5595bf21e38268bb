"""physcam.analysis: what a lens does to the picture, one package per concept (issue 43).

- :mod:`~physcam.analysis.image_quality`: MTF, PSF, spot, wavefront, Huygens, colour, relative illumination, ghosts
- :mod:`~physcam.analysis.distortion`: the distortion field, fitted models, ST-maps, distortion across focus
- :mod:`~physcam.analysis.framing`: field of view from real chief rays, focus breathing, a zoom's figure
- :mod:`~physcam.analysis.defocus`: real depth of field, bokeh, the defocus of a render, light fields
- :mod:`~physcam.analysis.calibration`: a lens measured from chart photographs and flat fields
- :mod:`~physcam.analysis.lens_cards`: the lens diagram, the lens card, the probes of ``physcam lens check``

The modules at this level (``_chief``, ``_plot``, ``_camera``, ``centroid``) are what every package shares.
The analyses' old flat paths (``physcam.analysis.mtf`` ...) answer for one version (:mod:`physcam._moved`).
"""
