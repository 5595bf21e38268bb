"""What a ray analysis (spot, bokeh, relative illumination, colour, ghosts) takes from its first
argument (issue 28): a :class:`~physcam.optics.state.CameraState` as it is -- the focused lens, its
film plane, the iris sized by the one rule, the iris shape, the primary wavelength and the sensor --
or a :class:`~physcam.lens.prescription.Prescription` with the function's own film plane, stop and
sensor keywords (an ``fstop`` sized by :func:`physcam.optics.state.camera_state`, the one place).

A CameraState already says where the film is and how the lens is stopped: giving it together with
``film_z``, ``fstop``, ``stop_semi_diameter`` or a sensor of its own is an InputError. A wavelength
or an iris shape given with it replaces the state's (as for the MTF). Lengths in mm, lens space
(docs/conventions.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError
from ..lens.prescription import Prescription
from ..optics.state import CameraState, camera_state


@dataclass(frozen=True)
class Camera:
    """The lens an analysis traces, and where and how: from a CameraState or a Prescription."""

    lens: Prescription  # the prescription traced (the focused one of a CameraState)
    object_z: float  # lens space; -inf: the object (light) at infinity
    film_z: float | None  # lens space; None: the analysis's own default (paraxial image of infinity)
    stop_semi_diameter: float | None  # mm; None: as the file stops it
    aperture: object  # physcam.trace.aperture.Aperture or None (round)
    wavelength_nm: float | None  # None: the analysis's own default (the design wavelength)
    sensor_mm: tuple[float, float] | None  # (width, height); None: the analysis's own default
    state: CameraState | None  # the state it came from, if any

    @property
    def at_infinity(self) -> bool:
        return math.isinf(self.object_z)


def camera_of(lens, *, film_z=None, fstop=None, stop_semi_diameter=None, aperture=None, wavelength_nm=None,
              sensor_mm=None) -> Camera:
    """The :class:`Camera` of an analysis's first argument ``lens`` (module notes). A Prescription
    keeps its file's focus; ``fstop`` sizes its iris by :func:`~physcam.optics.state.camera_state`."""
    if aperture is not None:
        from ..errors import require_type
        from ..trace.aperture import Aperture

        require_type("aperture", aperture, Aperture, "physcam.trace.aperture.Aperture(nsides, ...)")
    if isinstance(lens, CameraState):
        given = {"film_z": film_z, "fstop": fstop, "stop_semi_diameter": stop_semi_diameter}
        if lens.sensor_mm is not None:
            given["the sensor size"] = sensor_mm
        extra = [k for k, v in given.items() if v is not None]
        if extra:
            raise InputError(f"a CameraState carries its own focus, stop and sensor: give {', '.join(extra)} to "
                             "camera_state() (or pass the lens itself), not here")
        return Camera(lens.focused, lens.object_z, lens.film_z, lens.stop_semi_diameter,
                      lens.aperture if aperture is None else aperture,
                      lens.wavelengths_nm[0] if wavelength_nm is None else wavelength_nm,
                      lens.sensor_mm if sensor_mm is None else sensor_mm, lens)
    if fstop is not None:
        if stop_semi_diameter is not None:
            raise InputError("give the stop as fstop or stop_semi_diameter, not both")
        stop_semi_diameter = camera_state(lens, fstop=fstop).stop_semi_diameter
    return Camera(lens, -math.inf, film_z, stop_semi_diameter, aperture, wavelength_nm, sensor_mm, None)


def sensor_size(width_mm, height_mm):
    """A sensor keyword pair as one value for :func:`camera_of`: None when it is the keywords' default
    (the default sensor, :data:`physcam.data.default_sensor.DEFAULT_SENSOR`), so a CameraState's own
    sensor is used; the pair otherwise."""
    from ..data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM

    # "not given" is the keywords' own default objects (identity, not equality): an explicit 24.89 x 18.66
    # is a sensor given, refused next to a state's own like any other
    if width_mm is DEFAULT_SENSOR_WIDTH_MM and height_mm is DEFAULT_SENSOR_HEIGHT_MM:
        return None
    return (width_mm, height_mm)
