"""Build hooks that pyproject.toml cannot express: the package list (with `fixtures/`
installed as `gve_fixtures`), the optional C stepper core built through cffi and the
wheel's tag.

The C core is built against CPython's limited API (cffi's default, `.abi3.so`), so one
wheel serves every CPython from the oldest that ``requires-python`` admits: the wheel is
tagged ``cp311-abi3-<platform>`` rather than for the interpreter that built it.

If the C core cannot be compiled (no compiler, no headers), installation goes on and
the emulator uses its pure-Python twin, saying so once on stderr.
"""

import sys

from setuptools import find_namespace_packages, find_packages, setup
from setuptools.command.build_ext import build_ext

# fixtures/ installs as gve_fixtures; its data folders (profiles/, transcripts/) and the
# reference host's jobs/ and the report's templates/ are named as packages too, as
# setuptools asks of every folder that carries package data
packages = [*find_packages(include=["emulator*", "conformance*", "gve_host*"]), "gve_host.jobs",
            "conformance.reports.templates",
            "gve_fixtures", *(f"gve_fixtures.{name}" for name in
                              find_namespace_packages(where="fixtures",
                                                      exclude=["*__pycache__*"]))]


class OptionalBuildExt(build_ext):
    """Build the C stepper if possible; never fail the installation over it."""

    def run(self):
        try:
            super().run()
        except Exception as err:  # any build failure means "no C core"
            self._skip(err)

    def build_extension(self, ext):
        try:
            super().build_extension(ext)
        except Exception as err:
            self._skip(err)

    @staticmethod
    def _skip(err):
        print(f"warning: the C stepper core was not built ({err}); "
              "the emulator will use the Python twin", file=sys.stderr)


#: the oldest CPython the wheel's limited-API extension serves (``requires-python``)
LIMITED_API = "cp311"

setup(
    packages=packages,
    cffi_modules=["emulator/motion/build_stepper.py:ffibuilder"],
    cmdclass={"build_ext": OptionalBuildExt},
    options={"bdist_wheel": {"py_limited_api": LIMITED_API}},
)
