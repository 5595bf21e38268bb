"""Small lenses whose answers are known in closed form, for the analysis tests."""

from physcam.lens.prescription import LensMetadata, Medium, Prescription, Surface

GLASS_15 = Medium(1.5, 0.0)
N_BK7 = Medium(1.5168, 64.17, "N-BK7")


def concentric(radius=50.0, stop_sd=1.0, front_sd=45.0):
    """One refracting sphere (n = 1.5 behind it) with the stop at its centre of curvature.

    Every chief ray goes through the centre, hits the sphere normally and is not deviated; the
    centre is both nodal points, so the image height on the flat film is EFL tan(theta) exactly
    (no distortion), EFL = R / (n - 1). The pupil is only foreshortened off axis, so the relative
    illumination follows cos^4 (for a small stop).
    """
    return Prescription(
        (Surface(radius, radius, GLASS_15, front_sd), Surface(0.0, 2.0 * radius, GLASS_15, stop_sd, kind="stop")),
        LensMetadata(name="concentric sphere"),
    ).validate()


def plano_convex(f=100.0, thickness=1.0, stop_sd=5.0):
    """N-BK7 plano-convex lens, curved side first, stop in contact in front: EFL = R / (nd - 1) exactly."""
    r = f * (N_BK7.nd - 1.0)
    return Prescription(
        (Surface(0.0, 0.0, semi_diameter=stop_sd, kind="stop"), Surface(r, thickness, N_BK7, 6.0),
         Surface(0.0, f, semi_diameter=6.0)),
        LensMetadata(name="plano-convex N-BK7"),
    ).validate()


def plate(thickness=10.0, n=1.5):
    """A plane-parallel plate behind a stop (afocal: give film_z)."""
    return Prescription(
        (Surface(0.0, 5.0, semi_diameter=10.0, kind="stop"), Surface(0.0, thickness, Medium(n, 0.0), 10.0, kind="flat"),
         Surface(0.0, 20.0, semi_diameter=10.0, kind="flat")),
        LensMetadata(name="plate"),
    ).validate()
