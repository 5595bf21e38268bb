"""Image quality: MTF, PSF, spot diagrams, wavefront error, the Huygens PSF, longitudinal and lateral
colour, relative illumination and ghosts (docs/image-quality.md)."""
