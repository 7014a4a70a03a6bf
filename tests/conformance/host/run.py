"""Running a certification from a test: `gve-conformance host` in process, the host
program as its own process, the reports read back."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import gve_host
from conformance.cli.host import main
from conformance.verdicts.verdict import FAIL, grade

JOB = Path(gve_host.__file__).parent / "jobs" / "square.job"


#: a host silent this long hangs: long enough for the reference host on a machine loaded
#: by the other tests (it stalled 2 s there once), short for a host that does hang
HOST_TIMEOUT = 4.0


def certify(tmp_path: Path, profile: str, *host: str, scenarios: tuple[str, ...] = (),
            options: tuple[str, ...] = (), command: list[str] | None = None
            ) -> tuple[int, list[dict]]:
    """The exit status and the results of certifying ``command`` (default: the reference
    host on the sample job, with ``host`` options)."""
    command = command or [sys.executable, "-m", "gve_host", "{port}", "--job", str(JOB), *host]
    argv = ["--profile", profile, "--report-dir", str(tmp_path), "--host-timeout",
            str(HOST_TIMEOUT),
            *[a for s in scenarios for a in ("--scenarios", s)], *options, "--", *command]
    status = main(argv)
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir()]
    return status, json.loads((folder / "results.json").read_text())["results"]


def verdicts(results: list[dict]) -> dict[str, str]:
    return {r["scenario"]: r["verdict"] for r in results}


def failing_rules(result: dict) -> set[str]:
    """The rules whose failed checks made this scenario FAIL."""
    return {c["rule"] for c in result["checks"] if not c["ok"] and grade(c["tag"], False) == FAIL}
