"""Names and defaults of the fitted distortion models, without numpy (the CLI's parser reads them).

See :mod:`physcam.analysis.distortion.models`.
"""

#: The largest residual (pixels) a fitted model may have and still be called good.
DEFAULT_MAX_RESIDUAL_PX = 0.5
#: ``--fit`` names: brown = Brown-Conrady D-U and U-D, 3de4 = 3DE4 Radial - Standard, Degree 4,
#: usd = Hydra lensDistortion, nuke = a Nuke script applying the ST-maps (no fit); 3de4-anamorphic-4 and -6 =
#: 3DE4 Anamorphic - Standard, Degree 4 / 6 (physcam.analysis.distortion.anamorphic).
MODEL_CHOICES = ("brown", "3de4", "usd", "nuke", "3de4-anamorphic-4", "3de4-anamorphic-6")
ANAMORPHIC_CHOICES = {"3de4-anamorphic-4": 4, "3de4-anamorphic-6": 6}
