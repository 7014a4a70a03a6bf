"""One member of a fleet (cli/fleet.py): ``python -m conformance.cli.fleet_member JOB``
runs the one target of JOB (the fleet's parsed options as JSON) as a single run would."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from conformance.cli.usage import INTERRUPTED


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        job = json.loads(Path(argv[0]).read_text(encoding="utf-8"))
        from conformance.cli.run import execute
        return execute(argparse.Namespace(**job["args"]), job["argv"])
    except KeyboardInterrupt:
        # only before the run began: a run interrupted halts its unit, reports, returns
        print("interrupted before the run began", file=sys.stderr)
        return INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
