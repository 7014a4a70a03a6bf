"""What a run report says about the run itself: when and where it ran,
who ran it, which suite, every flag that shaped it, and per target the unit's identity,
the profile it was judged as and the motion envelope.

The CLI (or any other producer of a RunResult, such as host certification) fills it;
the reports only print it. Plain data, JSON-serializable through :func:`asdict`.
"""

from __future__ import annotations

import datetime
import platform as _platform
import shlex
import socket
from dataclasses import asdict, dataclass, field
from importlib import metadata as _dist

__all__ = ["RunMeta", "TargetMeta", "host_name", "now_iso", "suite_version"]


@dataclass
class TargetMeta:
    spec: str                               # as given on the command line
    kind: str = ""                          # emu, serial, tcp
    profile: str = ""                       # the profile the target was judged as
    profile_chosen: str = ""                # how: "--profile", "auto: <why>", "emu"
    version: str = ""                       # the unit's answer to `?`
    processor_id: str = ""                  # the unit's answer to `Q`
    envelope: int | None = None             # steps per axis from the start (real units)
    excursion: list[int] | None = None      # the largest |travel| per axis seen in the run
    graded: str = ""                        # "strict" or "by the tags" (docs/suite.md)
    #: real time: the line's `?` round trip measured at the start (ms min, median, max)
    #: and one byte's time at the baud rate
    line: dict[str, float] = field(default_factory=dict)


@dataclass
class RunMeta:
    started: str = ""                       # ISO 8601 with the zone
    finished: str = ""
    operator: str = ""                      # --operator-name
    suite_version: str = field(default_factory=lambda: suite_version())
    host: str = field(default_factory=lambda: host_name())
    platform: str = field(default_factory=_platform.platform)
    python: str = field(default_factory=_platform.python_version)
    command: list[str] = field(default_factory=list)   # the arguments as given
    settings: str = ""                      # Hypothesis settings profile
    seed: int | None = None                 # None: derandomized settings
    mutant: str | None = None
    destructive: bool = False
    max_travel: int | None = None
    cases: list[str] = field(default_factory=list)      # --cases globs (empty: all)
    exclude: list[str] = field(default_factory=list)
    full_logs: bool = False
    strict: bool = False                    # --strict: third-party targets graded strictly
    operator_steps: bool = False            # a technician was asked for hand steps
    confirmed: str = ""                     # how motion was allowed: "asked", "--yes", ""
    targets: list[TargetMeta] = field(default_factory=list)
    # a host certification: the host program as given after `--` (empty: attended) and
    # the certification's own options in force (they replace the suite's flags)
    host_command: list[str] = field(default_factory=list)
    host_flags: dict[str, object] = field(default_factory=dict)
    #: another job's own options in force (diff's), which replace the suite's flags too
    job_flags: dict[str, object] = field(default_factory=dict)
    # the spec's rules the selected cases can fail, per profile: {profile, covered, total,
    # sections: [{section, covered (a count), uncovered (rule IDs)}]}
    coverage: list[dict] = field(default_factory=list)

    def target(self, spec: str) -> TargetMeta:
        """The entry for ``spec`` (made when missing)."""
        for t in self.targets:
            if t.spec == spec:
                return t
        self.targets.append(TargetMeta(spec))
        return self.targets[-1]

    def flags(self) -> dict[str, object]:
        """The flags that shaped the run, by their command-line names (a host
        certification's: the host command and the certification's options)."""
        if self.host_flags:
            return {"host command": shlex.join(self.host_command) or "attended",
                    **self.host_flags}
        if self.job_flags:
            return dict(self.job_flags)
        return {"--settings": self.settings,
                "--seed": "derandomized" if self.seed is None else self.seed,
                "--mutant": self.mutant or "none",
                "--allow-destructive": self.destructive,
                "--max-travel": self.max_travel,
                "--cases": " ".join(self.cases) or "all",
                "--exclude": " ".join(self.exclude) or "none",
                "--full-logs": self.full_logs,
                "--strict": self.strict,
                "--operator": self.operator_steps,
                "motion confirmed": self.confirmed or "not asked"}

    def to_dict(self) -> dict:
        return asdict(self)


def now_iso() -> str:
    """The local date and time, ISO 8601 with the zone offset, to the second."""
    return datetime.datetime.now().astimezone().isoformat(timespec="seconds")


def suite_version() -> str:
    try:
        return _dist.version("gve-conformance")
    except _dist.PackageNotFoundError:
        return "unknown (not installed)"


def host_name() -> str:
    return socket.gethostname()
