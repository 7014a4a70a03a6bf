"""cffi (API mode) builder of the C stepper core: ``emulator.motion._stepper_c``.

Built by setup.py at install time (``cffi_modules``): ``pip install -e .`` rebuilds it in
place after a change to _stepper.c. Running this file from the project root also builds it
in place, provided the setuptools at hand can read pyproject.toml (77 or later).
"""

from __future__ import annotations

import re
from pathlib import Path

from cffi import FFI

HERE = Path(__file__).resolve().parent
HEADER = (HERE / "_stepper.h").read_text()
# cffi's cdef takes declarations without preprocessor lines
CDEF = "\n".join(line for line in HEADER.splitlines() if not line.startswith("#"))
CDEF = re.sub(r"\bST_AXES\b", "4", CDEF)

ffibuilder = FFI()
ffibuilder.cdef(CDEF)
ffibuilder.set_source(
    "emulator.motion._stepper_c",
    '#include "_stepper.h"',
    sources=[str((HERE / "_stepper.c").relative_to(Path.cwd()))
             if HERE.is_relative_to(Path.cwd()) else str(HERE / "_stepper.c")],
    include_dirs=[str(HERE)],
    # exact integer arithmetic; the one float (a square root's first guess) must not be
    # contracted or fast-mathed
    extra_compile_args=["-O2", "-std=c11", "-ffp-contract=off", "-fno-fast-math"],
    libraries=["m"],
)

if __name__ == "__main__":
    ffibuilder.compile(tmpdir=str(HERE.parent.parent), verbose=False)
