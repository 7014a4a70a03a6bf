"""The reports of a gate (`mutation`, `fairness`, `corpus`), which judges items one at a
time (a mutant hunted, a reading tried, an implementation judged) rather than cases: its
``results.json`` and JUnit XML in ``<folder>/<run id>/`` (and at ``--junitxml``). One
testsuite named after the gate, one testcase per item: a ``failure`` where the item failed
the gate, ``skipped`` where the job ended before it (its time limit, a signal), and the
lines the console showed for it as its ``system-out``; the gate's last line is the
suite's ``system-out`` and its ``verdict`` property, as a run's is. The same gate
cli/gate.py ends (one meaning under one name)."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from dataclasses import asdict, dataclass, field
from pathlib import Path

from conformance.reports.files import write_text
from conformance.reports.text import element


@dataclass
class GateItem:
    """One item a gate judged (``passed``), or did not reach (``passed`` None)."""

    name: str
    passed: bool | None
    seconds: float = 0.0
    lines: list[str] = field(default_factory=list)


@dataclass
class GateRun:
    """A gate's run: its items in order, its verdict and last line's reason."""

    job: str
    run_id: str
    verdict: str
    reason: str
    items: list[GateItem]
    seconds: float = 0.0
    command: list[str] = field(default_factory=list)
    started: str = ""

    def to_json(self) -> dict:
        return {**asdict(self), "seconds": round(self.seconds, 3),
                "items": [{**asdict(i), "seconds": round(i.seconds, 3)} for i in self.items]}


def render_gate_junit(run: GateRun) -> str:
    root = ET.Element("testsuites", name=f"gve-conformance {run.job}")
    suite = element(
        root, "testsuite", name=run.job, tests=len(run.items),
        failures=sum(i.passed is False for i in run.items), errors=0,
        skipped=sum(i.passed is None for i in run.items), time=f"{run.seconds:.3f}")
    props = element(suite, "properties")
    for name, value in (("verdict", f"{run.verdict} — {run.reason}"),
                        ("started", run.started), ("command", " ".join(run.command))):
        element(props, "property", name=name, value=value)
    for item in run.items:
        tc = element(suite, "testcase", name=item.name, classname=f"gve.{run.job}",
                      time=f"{item.seconds:.3f}")
        said = "\n".join(item.lines)
        if item.passed is False:
            element(tc, "failure", said, message=item.lines[0] if item.lines else item.name,
                     type="FAILED")
        elif item.passed is None:
            element(tc, "skipped", message=item.lines[0] if item.lines else "not run")
        else:
            element(tc, "system-out", said)
    element(suite, "system-out", f"{run.verdict} — {run.reason}\n")
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def write_gate_junit(run: GateRun, path: str | Path) -> Path:
    path = Path(path)
    write_text(path, render_gate_junit(run))
    return path


def write_gate_reports(run: GateRun, folder: str | Path) -> Path:
    """``results.json`` and ``junit.xml`` in ``folder/<run id>/``."""
    out = Path(folder) / run.run_id
    write_gate_junit(run, out / "junit.xml")
    write_text(out / "results.json", json.dumps(run.to_json(), indent=1))
    return out
