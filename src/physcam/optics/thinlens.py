"""Thin-lens (Gaussian) imaging: conjugates, magnification, field of view.

Gaussian imaging law 1/f = 1/s + 1/s' with s measured from the front principal
plane H1 toward the subject and s' from the rear principal plane H2 toward the
film (docs/conventions.md). Source: E. Hecht, *Optics*, 5th ed., §5.2.3 (thin-lens
equation) and §5.2.3 Eq. 5.26 (transverse magnification m = -s'/s; physcam reports
its magnitude, the image is inverted).

All functions broadcast over numpy arrays; lengths in mm, angles in radians unless
the name says ``_deg``. Every one answers with a finite number (infinity only where the
docstring says) or raises a :class:`~physcam.errors.PhysCamError`: a focal length must be above
0, a distance above 0 (or infinite, a subject at infinity).
"""

from __future__ import annotations

import math

from ..errors import OpticsError
from . import _num as nx

__all__ = [
    "MIN_F_NUMBER",
    "MAX_F_NUMBER",
    "require_f_number",
    "MIN_FOCAL_LENGTH_MM",
    "MAX_FOCAL_LENGTH_MM",
    "require_focal_length",
    "image_distance",
    "object_distance",
    "magnification",
    "object_distance_for_marked",
    "minimum_marked_distance",
    "field_of_view",
]


#: The fastest f-number a lens in air can have: N = 1 / (2 n' sin u') with sin u' <= 1 and n' = 1
#: (Abbe sine condition; Kingslake & Johnson, *Lens Design Fundamentals*, 2nd ed., 4.3).
MIN_F_NUMBER = 0.5
#: The slowest f-number accepted: pinhole cameras reach f/500 or so; beyond f/4096 a typo is likelier.
MAX_F_NUMBER = 4096.0


def require_f_number(name: str, value) -> float:
    """``value`` as a float between :data:`MIN_F_NUMBER` and :data:`MAX_F_NUMBER`, else InputError (the
    one f-number range of the camera state and the on-set report)."""
    from ..errors import InputError, require_positive

    v = require_positive(name, value, unit="")
    if not MIN_F_NUMBER <= v <= MAX_F_NUMBER:
        why = ("no lens in air is faster than f/0.5 (N = 1 / (2 sin u'), sin u' <= 1)" if v < MIN_F_NUMBER
               else f"f-numbers above {MAX_F_NUMBER:g} are not camera apertures")
        raise InputError(f"{name} {v:g} is out of range: {why}")
    return v


#: The shortest focal length accepted (mm): the shortest lenses made for cameras are phones' ultra-wides (1.54 mm
#: in the iPhone 11 to 15's EXIF) and board cameras' fisheyes of about 1 mm; a lens-set file's floor too
#: (onset/lens_set.py). Below it a value is a slip (``--focal 0.001`` gave "hyperfocal 0.0 mm").
MIN_FOCAL_LENGTH_MM = 1.0
#: The longest (mm): 100 m, far beyond any camera lens (the longest made are about 5 m, Canon's 5200 mm f/14).
MAX_FOCAL_LENGTH_MM = 1.0e5


def require_focal_length(value, name: str = "focal length") -> float:
    """``value`` (mm) as a float between :data:`MIN_FOCAL_LENGTH_MM` and :data:`MAX_FOCAL_LENGTH_MM`, else an
    InputError in one line (the one focal-length range of the thin-lens and datasheet models, the on-set
    report, close-up lenses and the CLI's ``--focal``)."""
    from ..errors import InputError, require_positive

    f = require_positive(name, value)
    if f > MAX_FOCAL_LENGTH_MM:
        raise InputError(f"{name} {f:g} mm is beyond any camera lens; give it in mm (e.g. --focal 50)")
    if f < MIN_FOCAL_LENGTH_MM:
        raise InputError(f"{name} {f:g} mm is shorter than any camera lens (at least {MIN_FOCAL_LENGTH_MM:g} mm); "
                         "give it in mm (e.g. --focal 50)")
    return f


def image_distance(focal_length, object_distance):
    """s' = s f / (s - f): image distance behind H2 for an object ``object_distance`` in front of H1.

    Raises :class:`OpticsError` when the object is at or inside the focal length
    (no real image). An object at infinity images at the focal length, s' = f (the form
    f / (1 - f/s), which needs no special case).

    >>> float(image_distance(50.0, 100.0))
    100.0
    >>> float(image_distance(50.0, float("inf")))
    50.0
    """
    f = nx.positive("focal length", focal_length)
    s = nx.positive("object distance", object_distance, allow_inf=True)
    if nx.any_true(s <= f):
        raise OpticsError("the subject is at or inside the focal length: no real image forms on the film")
    return nx.out(f / (1.0 - f / s), what="the image distance")


def object_distance(focal_length, image_distance_):
    """s = s' f / (s' - f), the inverse of :func:`image_distance`."""
    return image_distance(focal_length, image_distance_)  # the law is symmetric in s and s'


def magnification(focal_length, object_distance):
    """|m| = s'/s = f / (s - f), the size on the film over the size of the subject (0 at infinity)."""
    f = nx.positive("focal length", focal_length)
    s = nx.positive("object distance", object_distance, allow_inf=True)
    if nx.any_true(s <= f):
        raise OpticsError("the subject is at or inside the focal length: no real image forms on the film")
    return nx.out(f / (s - f), what="the magnification")


def minimum_marked_distance(focal_length, hiatus=0.0):
    """Closest subject a lens of focal length f can image: object-to-image distance 4f (+ hiatus).

    At that distance s = s' = 2f and the magnification is 1 (Hecht §5.2.3).
    """
    f = nx.positive("focal length", focal_length)
    return nx.out(4.0 * f + nx.finite("hiatus", hiatus), what="the closest mark")


def object_distance_for_marked(focal_length, marked_distance, hiatus=0.0):
    """Object distance s (from H1) of a subject marked ``marked_distance`` from the film plane.

    On set the focus mark is measured from the film plane to the subject; that length is
    s + s' + hiatus, where the hiatus is the H1-to-H2 separation (0 for a thin lens,
    positive when H1 lies in front of H2). Solving s + s f/(s - f) = D - hiatus gives
    s = (L + sqrt(L^2 - 4 L f)) / 2 with L = D - hiatus (the larger root: the subject is
    in front of the lens). Needs L >= 4 f.

    >>> round(float(object_distance_for_marked(50.0, 200.0)), 6)  # 1:1 macro: s = s' = 2f
    100.0

    A mark at infinity is a subject at infinity (s = inf).
    """
    f = nx.positive("focal length", focal_length)
    D = nx.positive("focus mark", marked_distance, allow_inf=True)
    hiatus = nx.finite("hiatus", hiatus)
    if nx.is_scalar(D) and math.isinf(D):
        return math.inf
    L = D - hiatus
    disc = L * L - 4.0 * L * f
    if nx.any_true(disc < -1e-9 * L * L) or nx.any_true(L <= 0):
        fmax = f if nx.is_scalar(f) else float(f.max())
        dmin = D if nx.is_scalar(D) else float(D.min())
        raise OpticsError(
            f"focus mark {dmin:.6g} mm is closer than this lens can focus: "
            f"the closest mark for a {fmax:g} mm thin lens is {4.0 * fmax + hiatus:.6g} mm from the film plane (4f)"
        )
    return nx.out(0.5 * (L + nx.sqrt(nx.maximum(disc, 0.0))), allow_inf=True, what="the object distance")


def field_of_view(size, focal_length, object_distance=None):
    """Angular field of view (radians) across a film dimension ``size`` (mm).

    At infinity focus: 2 atan(size / 2f). Focused at ``object_distance`` s (from H1),
    the film sits s' behind H2 and the field seen from H1 narrows to 2 atan(size / 2s')
    (focus breathing of a unit-focusing lens). Source: Hecht §5.7 (field stop and
    angular field); thin lens, so the pupils sit at the principal planes.

    >>> import math; round(math.degrees(field_of_view(36.0, 50.0)), 4)
    39.5978
    """
    size = nx.positive("film size", size)
    d = nx.positive("focal length", focal_length) if object_distance is None else \
        image_distance(focal_length, object_distance)
    return nx.out(2.0 * nx.atan(size / (2.0 * d)), what="the field of view")
