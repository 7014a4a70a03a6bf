"""A job: what the host is to make the unit do, one step a line.

    # comments and blank lines are ignored
    V10000              a command: the body of a frame (spec 10), without `!`, address
    L1000,0,0           and checksum
    wait                wait until the motion so far has ended (`L0,0,0`, spec 10.1)
    position 1000,0,0   wait, then read `PF` and stop the job unless the unit is there
    use checksums       how to talk (before the first step; `--checksums` and
    use packets 4       `--packets N` on the command line say the same): checksum
                        mode (spec 6); runs of `C`/`B` as packets of up to N (spec 7)
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

_BODY = re.compile(r"[A-Z?@>%*$][A-Za-z0-9,+&\-.]*\Z")


@dataclass(frozen=True)
class Step:
    kind: str                    # command, wait, position
    body: str = ""
    position: tuple[int, ...] = ()

    @property
    def continuous(self) -> bool:
        """A packet may hold it: `C` and `B` (spec 7)."""
        return self.kind == "command" and self.body[:1] in ("C", "B")


@dataclass
class Job:
    steps: list[Step]
    checksums: bool = False
    packets: int = 0


class JobError(ValueError):
    """A job file that cannot be run; the message names the line."""


def parse(text: str, name: str = "job") -> Job:
    job = Job([])
    steps = job.steps
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        word, _, rest = line.partition(" ")
        if word == "use" and not steps:
            what, _, n = rest.partition(" ")
            if what == "checksums" and not n:
                job.checksums = True
            elif what == "packets" and n.isdigit():
                job.packets = int(n)
            else:
                raise JobError(f"{name}:{number}: `use checksums` or `use packets N`")
        elif word == "wait" and not rest:
            steps.append(Step("wait"))
        elif word == "position":
            try:
                steps.append(Step("position", position=tuple(
                    int(v) for v in rest.replace(" ", "").split(","))))
            except ValueError:
                raise JobError(f"{name}:{number}: position X,Y,Z expects integers") from None
        elif _BODY.match(line):
            steps.append(Step("command", line))
        else:
            raise JobError(f"{name}:{number}: not a command body, `wait`, `position` or "
                           f"`use` (before the first step): {line!r}")
    return job


def load(path: str | Path) -> Job:
    p = Path(path)
    try:
        return parse(p.read_text(encoding="ascii"), p.name)
    except (OSError, UnicodeDecodeError) as err:
        raise JobError(f"cannot read the job {p}: {err}") from None
