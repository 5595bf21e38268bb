from . import _program

_program.start()  # before the command line's imports (the collector's threshold: physcam._program)

from .cli import run  # noqa: E402

run()
