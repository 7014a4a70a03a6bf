"""cffi (API mode) builder of the C stepper core: ``emulator.motion._stepper_c``.

Built by setup.py at install time (``cffi_modules``, which calls :func:`ffibuilder`):
``pip install -e .`` builds it in place. The build embeds the digest of the files it is
built from (:data:`SOURCES`); ``rebuild.py`` compares it with the files beside the
module before the core is imported and rebuilds a module older than its sources. Running
this file from the project root also builds it in place, provided the setuptools at hand
can read pyproject.toml (77 or later).

Importing this module is cheap (cffi is imported by :func:`ffibuilder` only).
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from cffi import FFI

HERE = Path(__file__).resolve().parent
MODULE = "emulator.motion._stepper_c"
#: the headers whose declarations the module exposes (cffi's cdef)
HEADERS = ("_stepper.h", "_kernel.h")
#: the C files compiled into the module (the core, the benchmark's plain kernel)
C_FILES = ("_stepper.c", "_kernel.c")
#: the most axes the core drives: ``ST_AXES`` of the header, the one place it is written
AXES = int(re.search(r"^#define ST_AXES (\d+)$", (HERE / "_stepper.h").read_text(),
                     re.MULTILINE)[1])
#: every file the module is built from: a change to any of them makes a build stale
SOURCES = (*HEADERS, "_stepper_math.h", *C_FILES, "build_stepper.py")
#: precedes the sources' digest in the compiled module
MARKER = b"gve-stepper-sources:"


def source_digest(directory: Path = HERE) -> str:
    """The SHA-256 of :data:`SOURCES` in ``directory`` (names, lengths and contents)."""
    digest = hashlib.sha256()
    for name in SOURCES:
        data = (directory / name).read_bytes()
        digest.update(name.encode() + b"\0" + len(data).to_bytes(8, "little") + data)
    return digest.hexdigest()


def _cdef(directory: Path) -> str:
    # cffi's cdef takes declarations without preprocessor lines
    text = "\n".join(line for name in HEADERS
                     for line in (directory / name).read_text().splitlines()
                     if not line.startswith("#"))
    return re.sub(r"\bST_AXES\b", str(AXES), text) + "\nconst char *st_sources(void);\n"


def ffibuilder(directory: Path | None = None) -> FFI:
    """The builder of the module from the sources in ``directory`` (default: beside this
    file, with the C files named relative to the working directory when they are inside
    it, as setuptools wants them; an explicit directory names them absolutely)."""
    from cffi import FFI

    root = directory or HERE
    if directory is None and HERE.is_relative_to(Path.cwd()):
        sources = [str((HERE / name).relative_to(Path.cwd())) for name in C_FILES]
    else:
        sources = [str(root / name) for name in C_FILES]
    builder = FFI()
    builder.cdef(_cdef(root))
    preamble = "".join(f'#include "{name}"\n' for name in HEADERS)
    marker = (MARKER + source_digest(root).encode()).decode()
    builder.set_source(
        MODULE,
        preamble + f'const char *st_sources(void) {{ return "{marker}"; }}\n',
        sources=sources,
        include_dirs=[str(root)],
        # exact integer arithmetic; the one float (a square root's first guess) must not
        # be contracted or fast-mathed
        extra_compile_args=["-O2", "-std=c11", "-ffp-contract=off", "-fno-fast-math"],
        libraries=["m"],
    )
    return builder


if __name__ == "__main__":
    ffibuilder().compile(tmpdir=str(HERE.parent.parent), verbose=False)
