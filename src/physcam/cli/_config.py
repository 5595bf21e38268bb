"""The user config: defaults a person sets once (``physcam config show`` prints them).

The file is TOML, read from ``$PHYSCAM_CONFIG`` when that variable is set (an empty value means
no config file), else ``$XDG_CONFIG_HOME/physcam/config.toml``, else
``~/.config/physcam/config.toml``. Every key is optional; an option given on the command line
always wins::

    sensor = "ALEXA 35"      # the sensor when no --sensor is given (default Super 35)
    coc = "d/1500"           # circle of confusion: d/1500, d/1000, d/1730, cine, or a value (25um)
    units = "ft"             # distances printed in ft (feet and inches) or m (default m)
    output_dir = "~/shots"   # relative output files (-o, --plot, --stmap, usd files) go here
    blender_python = "/opt/blender/4.2/python/bin/python3.11"   # or a blender executable
    glass_catalogs = ["~/zemax/glasscat/CORNING.AGF"]   # Zemax .agf catalogues searched for glasses

An unknown key, a value of the wrong kind, a file that is not TOML or one nested too deeply to
read is refused with the file's name, so a typo never silently falls back to a default; so are a
``PHYSCAM_CONFIG`` naming a file that is not there and a config path that is a folder.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from .._record import field, record
from ..errors import InputError

__all__ = ["Config", "config_path", "load_config", "KEYS"]

#: The keys a config may set, with what each means (``physcam config show`` lists them).
KEYS = {
    "sensor": "the sensor when no --sensor is given (a name from `physcam sensors`)",
    "coc": "the circle of confusion when no --coc is given: d/1500, d/1000, d/1730, cine or a value (0.025, 25um)",
    "units": "the unit system distances are printed in: m or ft",
    "output_dir": "the folder relative output files are written into",
    "blender_python": "Blender for `compare blender` and the Blender tests: a Python with bpy, or a blender "
                      "executable (run with --background --python)",
    "glass_catalogs": "Zemax .agf glass catalogues (a list of paths, or one) searched after a lens file's own "
                      "catalogues, as --glass-catalog does",
}


@record
class Config:
    """The user's defaults; None where the file does not set them."""

    path: Path | None = None
    exists: bool = False
    sensor: str | None = None
    coc: str | float | None = None
    units: str | None = None
    output_dir: Path | None = None
    blender_python: str | None = None
    glass_catalogs: tuple | None = None
    source: dict = field(default_factory=dict)  # key -> where its value came from

    def to_dict(self) -> dict:
        return {"path": None if self.path is None else str(self.path), "exists": self.exists,
                "sensor": self.sensor, "coc": self.coc, "units": self.units,
                "output_dir": None if self.output_dir is None else str(self.output_dir),
                "blender_python": self.blender_python,
                "glass_catalogs": None if self.glass_catalogs is None else list(self.glass_catalogs)}


def config_path() -> Path | None:
    """Where the config is read from (see the module notes); None when ``PHYSCAM_CONFIG`` is empty."""
    key = (os.environ.get("PHYSCAM_CONFIG"), os.environ.get("XDG_CONFIG_HOME"), os.environ.get("HOME"))
    if key not in _PATHS:  # (the server asks per request: issue 47)
        _PATHS.clear()
        _PATHS[key] = _config_path()
    return _PATHS[key]


_PATHS: dict = {}


def _config_path() -> Path | None:
    env = os.environ.get("PHYSCAM_CONFIG")
    if env is not None:
        return Path(env).expanduser() if env.strip() else None
    base = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"), ".config")
    return Path(base) / "physcam" / "config.toml"


_CACHE: dict = {}


def load_config() -> Config:
    """The user config (cached per file and modification time, and while there is none). The file named by
    ``PHYSCAM_CONFIG`` must be there, and whichever file is read must be a regular file: a config that is a
    folder, or a variable naming a file that is not there (a typo, a path of another machine), is refused in
    one line, not passed over for physcam's defaults."""
    path = config_path()
    try:
        st = None if path is None else os.stat(path)
    except (OSError, ValueError):
        st = None
    if path is not None and st is None and os.environ.get("PHYSCAM_CONFIG", "").strip():
        raise InputError(f"PHYSCAM_CONFIG names {path}, which is not there: make it, or unset PHYSCAM_CONFIG "
                         f"(or set it empty) for no config")
    if st is not None and not stat.S_ISREG(st.st_mode):
        kind = "a folder" if stat.S_ISDIR(st.st_mode) else "not a regular file"
        raise InputError(f"the physcam config {path} is {kind}: a config is a TOML file (physcam config show)")
    key = (path, None if st is None else st.st_mtime_ns)
    if key not in _CACHE:
        _CACHE.clear()
        _CACHE[key] = Config(path=path, exists=False) if key[1] is None else _read(path)
    return _CACHE[key]


def _regular_files_only(path: Path, catalogues) -> None:
    """Refuse a glass catalogue that exists and is not a regular file (``/dev/zero`` grows without
    bound, a FIFO blocks): ``stat`` only, nothing is opened. A missing one is said when it is read."""
    import stat

    for c in catalogues:
        try:
            mode = os.stat(c).st_mode
        except OSError:
            continue
        if not stat.S_ISREG(mode):
            kind = "a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode) else "a device" \
                if (stat.S_ISCHR(mode) or stat.S_ISBLK(mode)) else "not a regular file"
            raise InputError(f"the physcam config {path}: glass_catalogs: {c} is {kind}, not a regular file "
                             "(a Zemax .agf text file)")


def _read(path: Path) -> Config:
    import tomllib

    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise InputError(f"cannot read the physcam config {path}: {exc.strerror or exc}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"the physcam config {path} is not valid TOML: {exc}") from None
    except RecursionError:  # tomllib recurses once per level of nested arrays or tables
        raise InputError(f"the physcam config {path} nests arrays or tables too deeply to read; "
                         f"it is a flat list of keys (physcam config show)") from None
    unknown = sorted(set(data) - set(KEYS))
    if unknown:
        raise InputError(f"the physcam config {path} has unknown key(s) {', '.join(unknown)}; "
                         f"it may set {', '.join(KEYS)}")
    values: dict = {}
    for k, v in data.items():
        if k == "coc" and isinstance(v, (int, float)) and not isinstance(v, bool):
            from ..optics.coc import require_coc

            try:
                values[k] = require_coc(float(v))
            except InputError as exc:  # out of the one range (0.001 to 1 mm)
                raise InputError(f"the physcam config {path}: coc: {exc}") from None
            continue
        if k == "glass_catalogs":
            v = [v] if isinstance(v, str) else v
            if not isinstance(v, list) or not all(isinstance(x, str) and x.strip() for x in v):
                raise InputError(f"the physcam config {path}: glass_catalogs must be a list of .agf paths, "
                                 f"e.g. glass_catalogs = [\"~/CORNING.AGF\"], got {v!r}")
            values[k] = tuple(str(Path(x.strip()).expanduser()) for x in v)
            _regular_files_only(path, values[k])
            continue
        if not isinstance(v, str) or not v.strip():
            raise InputError(f"the physcam config {path}: {k} must be text, e.g. {k} = \"...\", got {v!r}")
        values[k] = v.strip()
    if "sensor" in values:
        from ..optics.sensors import find_sensor

        try:
            find_sensor(values["sensor"])
        except InputError as exc:
            raise InputError(f"the physcam config {path}: sensor: {exc}") from None
    if "coc" in values and isinstance(values["coc"], str):
        from ..optics.coc import parse_coc

        try:
            values["coc"] = parse_coc(values["coc"])
        except InputError as exc:  # a bad number with a unit
            raise InputError(f"the physcam config {path}: coc: {exc}") from None
        if isinstance(values["coc"], str):
            from ..optics.coc import circle_of_confusion

            try:
                circle_of_confusion(36.0, 24.0, values["coc"])
            except InputError as exc:
                raise InputError(f"the physcam config {path}: coc: {exc}") from None
    if "units" in values:
        from ..units import UNIT_SYSTEMS, unit_system

        values["units"] = unit_system(values["units"])  # "feet" is ft, "metres" m, as on the command line
        if values["units"] not in UNIT_SYSTEMS:
            raise InputError(f"the physcam config {path}: units must be one of {', '.join(UNIT_SYSTEMS)}, "
                             f"got {values['units']!r}")
    out = values.get("output_dir")
    return Config(path=path, exists=True, sensor=values.get("sensor"), coc=values.get("coc"),
                  units=values.get("units"), output_dir=None if out is None else Path(out).expanduser(),
                  blender_python=None if "blender_python" not in values
                  else str(Path(values["blender_python"]).expanduser()),
                  glass_catalogs=values.get("glass_catalogs"), source={k: str(path) for k in values})
