"""The optional compiled tracing kernel (physcam.trace.kernels._ckernel; docs/install.md, "The fast path"), with the
Blender extension's rim pass in the same module (_rimpass.c).

Everything else about the package is in pyproject.toml. The extension is ``optional``: where it cannot be
built (no C compiler) setuptools warns and installs physcam without it, and the numpy kernel traces the same
rays. It needs no numpy headers (arrays come through the buffer protocol), so the build requires only
setuptools. The flags keep IEEE arithmetic in the reference's order: no fast-math, no contraction to fused
multiply-adds (they change the last bits; docs/ray-tracing.md); -fno-math-errno lets sqrt be one instruction.
"""

import os
import shutil

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

#: GCC and clang; MSVC's /fp:precise does not contract (its /fp:contract is off unless asked for)
UNIX_FLAGS = ["-O3", "-g0", "-ffp-contract=off", "-fno-fast-math", "-fno-math-errno", "-fno-trapping-math", "-std=c99"]
MSVC_FLAGS = ["/O2", "/fp:precise"]


class BuildExt(build_ext):
    """build_ext with the compiler's flags for IEEE arithmetic (module notes), whose copy into the source tree
    (an editable install, ``--inplace``) replaces the module file instead of writing over it: the test
    environments install the same tree editable one after another while another's suite may have the old
    module loaded (a shared library written over in place can crash the process that mapped it)."""

    def build_extensions(self):
        flags = MSVC_FLAGS if self.compiler.compiler_type == "msvc" else UNIX_FLAGS
        for ext in self.extensions:
            ext.extra_compile_args = list(flags)
        super().build_extensions()

    def copy_file(self, infile, outfile, *args, **kwargs):
        if not str(outfile).endswith((".so", ".pyd")) or not os.path.isfile(infile):
            return super().copy_file(infile, outfile, *args, **kwargs)
        tmp = f"{outfile}.{os.getpid()}.tmp"
        shutil.copy2(infile, tmp)
        os.replace(tmp, outfile)
        return outfile, 1


setup(
    ext_modules=[Extension("physcam.trace.kernels._ckernel", ["src/physcam/trace/kernels/_ckernel.c",
                                                              "src/physcam/trace/kernels/_rimpass.c"], optional=True)],
    cmdclass={"build_ext": BuildExt},
)
