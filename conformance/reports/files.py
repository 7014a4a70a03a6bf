"""How reports reach the disk: every run in a folder of its own, taken before the run
begins (a run never writes into another run's folder, at the same time or later), and
every file whole or not at all — written beside itself under a temporary name, then
renamed over its own name, so that a full disk, a Ctrl-C or a second run leaves no
truncated ``results.json`` behind: the file as it was, or none."""

from __future__ import annotations

import contextlib
import os
import time
import uuid
from pathlib import Path


class ReportNotWritten(Exception):
    """A report could not be written (a full disk, a folder taken away): one line
    naming the file and why."""


class RunFolderTaken(Exception):
    """The run's folder exists already: another run's, whose reports stay as they are."""


def new_run_id() -> str:
    """A fresh run id: the date, the time and a random tag."""
    return time.strftime("%Y%m%d-%H%M%S") + "-" + uuid.uuid4().hex[:6]


def claim(report_dir: str | Path, run_id: str | None = None) -> Path:
    """The run's folder ``report_dir/run_id``, created now and the run's alone (the
    folder is created exclusively: of two runs with one id, one gets it); ``run_id``
    None: a fresh id. RunFolderTaken when the folder named exists already,
    ReportNotWritten when it cannot be created."""
    for _ in range(100):
        folder = Path(report_dir, run_id or new_run_id())
        try:
            folder.mkdir(parents=True)
            return folder
        except FileExistsError:
            if run_id is not None:
                raise RunFolderTaken(
                    f"--run-id {run_id}: {folder} exists: a run never writes over another "
                    "run's reports (give another --run-id, or move that folder)") from None
        except OSError as err:
            raise ReportNotWritten(f"cannot create {folder}: {err.strerror or err}") from None
    raise ReportNotWritten(f"no fresh run id under {report_dir}")


def release(folder: Path) -> None:
    """Give back a run's folder that nothing was written to (the run stopped before its
    reports): the id may be used again."""
    with contextlib.suppress(OSError):
        folder.rmdir()


def write_text(path: str | Path, text: str, encoding: str = "utf-8") -> Path:
    """``text`` at ``path`` whole or not at all (see the module's docstring);
    ReportNotWritten when it cannot be, the file as it was."""
    path = Path(path)
    # created as any file the run writes (the umask's permissions, not mkstemp's 0600)
    temporary = path.with_name(f".{path.name}.{uuid.uuid4().hex[:8]}.partial")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(temporary, "x", encoding=encoding) as out:
            out.write(text)
            out.flush()
            os.fsync(out.fileno())
        os.replace(temporary, path)
    except OSError as err:
        with contextlib.suppress(OSError):
            temporary.unlink()
        raise ReportNotWritten(f"cannot write {path}: {err.strerror or err}") from None
    return path
