"""What a ray analysis (spot, bokeh, relative illumination, colour, ghosts) asks of its camera (issue 43):
the camera came through the one door (:func:`physcam.optics.state.takes_camera`), so it is a
:class:`~physcam.optics.state.CameraState` -- the focused lens, its film plane, the iris sized by the
one rule, the iris shape, the primary wavelength and the sensor.

A camera built from a bare lens (no focus, no film plane given) leaves the film to the analysis's own
rule (``film_from_analysis``: the paraxial image at its wavelength), and a lens as its file stops it
leaves the iris unset (None: the file's stop), as the analyses did before the door. Lengths in mm,
lens space (docs/conventions.md).
"""

from __future__ import annotations

from ..optics.state import CameraState


def ray_view(camera: CameraState, *, wavelength_nm=None):
    """(lens traced, object z, film z or None, iris semi-diameter or None, iris shape, wavelength, sensor
    (width, height) or None) of ``camera`` (module notes); ``wavelength_nm`` replaces its primary. The
    iris semi-diameter is the one its shape is drawn inside: a bladed iris's corner radius, so that the
    polygon has the round iris's area (:attr:`~physcam.optics.state.CameraState.iris_corner_semi`,
    docs/conventions.md)."""
    film = None if camera.film_from_analysis else camera.film_z
    bladed = camera.aperture is not None and not camera.aperture.is_circular
    stop = camera.iris_corner_semi if camera.iris_set or bladed else None
    wl = camera.wavelengths_nm[0] if wavelength_nm is None else wavelength_nm
    return camera.focused, camera.object_z, film, stop, camera.aperture, wl, camera.sensor_mm


def sensor_or_default(camera: CameraState) -> tuple[float, float]:
    """The camera's sensor (width, height), or the default sensor's
    (:data:`physcam.data.default_sensor.DEFAULT_SENSOR`, Super 35)."""
    from ..data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM

    return camera.sensor_mm or (DEFAULT_SENSOR_WIDTH_MM, DEFAULT_SENSOR_HEIGHT_MM)
