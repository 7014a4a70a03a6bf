"""A fleet: ``gve-conformance --target A --target B ... --jobs N`` runs each target in a
process of its own, at most N at once, and writes one report per target under
``<report dir>/<run id>/<target>/`` and a summary across them: printed, ``summary.json``
and ``index.html`` beside the targets' folders, and with ``--junitxml PATH`` one JUnit
file with a testsuite per target.

Each process is ``python -m conformance.cli.fleet_member JOB`` and runs the one target
exactly as a single run would, with the fleet's seed and example database and the
profile the fleet chose for it; the fleet has asked before moving (the members have no
terminal: hand steps are COULD-NOT-TEST there). Its output comes back line by line
behind the target's name. The processes live in process
groups of their own: a stopping signal (Ctrl-C, SIGTERM, SIGHUP alike) reaches the fleet
alone, which passes each one on at once — from its handler, before anything else runs —
as a SIGINT to every running target, so that each halts its unit as a single run does
(`H` the next frame on its line); it starts no other, waits for them and still reports. A
target is started with the signals held, so that none falls between its start and its
being known. A target whose fleet is gone (killed outright) sees its standard input end
and stops as if signalled.
"""

from __future__ import annotations

import argparse
import contextlib
import html
import json
import os
import queue
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import xml.etree.ElementTree as ET
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

from conformance.cli.ending import recap, say_all, written
from conformance.cli.progress import HEARTBEAT, Progress
from conformance.cli.usage import INTERRUPTED, verdict_status
from conformance.link.signals import StopSignals
from conformance.reports.files import ReportNotWritten, write_text
from conformance.run.runner import CaseResult, RunResult
from conformance.targets import Target
from conformance.verdicts.verdict import FAILED, INCOMPLETE, ORDER, PASSED

SUMMARY_JSON = "summary.json"
INDEX_HTML = "index.html"


@dataclass
class Member:
    """One target of the fleet and the process that runs it."""

    spec: str
    label: str                      # its report folder's name
    process: subprocess.Popen | None = None
    status: int | None = None       # the process's exit status
    started: float = 0.0            # seconds since the fleet began, when it started
    ended: float | None = None      # ... and when it ended
    result: dict = field(default_factory=dict)   # its results.json, once written


def labels(specs: list[str]) -> list[str]:
    """A folder name for each target, from its spec (``tcp:127.0.0.1:5114`` ->
    ``tcp-127.0.0.1-5114``), unique within the fleet."""
    out: list[str] = []
    for spec in specs:
        base = re.sub(r"[^A-Za-z0-9._-]+", "-", spec).strip("-.") or "target"
        name, n = base, 1
        while name in out:
            n += 1
            name = f"{base}-{n}"
        out.append(name)
    return out


def run_fleet(args: argparse.Namespace, argv: list[str], targets: list[Target], run_id: str,
              seed: int | None, database: str | None) -> int:
    """Run ``targets`` (chosen, confirmed, their ports closed) as a fleet with the options
    of ``args``; the exit status."""
    folder = (Path(tempfile.mkdtemp(prefix="gve-fleet-")) if args.no_reports
              else Path(args.report_dir, run_id))
    folder.mkdir(parents=True, exist_ok=True)
    specs = [t.info.spec for t in targets]
    members = [Member(spec, label) for spec, label in zip(specs, labels(specs), strict=True)]
    # asked and answered here: the members neither ask nor identify again
    child = dict(vars(args), jobs=1, report_dir=str(folder), no_reports=False, junitxml=None,
                 seed=seed, hypothesis_db=database or "none", yes=True, operator=False,
                 variant=None)
    for m, target in zip(members, targets, strict=True):
        job = {"args": dict(child, target=[m.spec], profile=target.profile.name,
                            run_id=m.label), "argv": argv}
        try:
            write_text(folder / f"{m.label}.job.json", json.dumps(job))
        except ReportNotWritten as err:             # before any target started
            print(f"gve-conformance: {err}", file=sys.stderr)
            return 1
    jobs = min(args.jobs, len(members))
    quiet = bool(getattr(args, "quiet", False))          # -q: the fleet's end only
    if not quiet:
        print(f"fleet {run_id}: {len(members)} targets, {jobs} at a time", flush=True)
    start = time.perf_counter()
    with Progress(len(members), unit="target", quiet=quiet,
                  verbose=bool(getattr(args, "verbose", False)), every_step=True,
                  heartbeat=HEARTBEAT) as shown:
        interrupted = _run_members(members, folder, jobs, start, shown)
    seconds = time.perf_counter() - start
    for m in members:
        (folder / f"{m.label}.job.json").unlink(missing_ok=True)
        m.result = m.result or _results(folder, m)
    summary = _summary(members, run_id, seconds, interrupted)
    if not quiet:
        _print_summary(summary)
    say_all([line for m in members for line in _recap(m)])
    lost = False                        # a report that could not be written (a full disk)
    if args.junitxml:
        junit = written(lambda: merge_junit(folder, members, args.junitxml, seconds))
        lost = junit is None
        if junit is not None:
            print(f"JUnit XML: {junit}")
    if args.no_reports:
        shutil.rmtree(folder, ignore_errors=True)
    else:
        index = written(lambda: _write_summary(folder, summary))
        lost = lost or index is None
        if index is not None:
            print(f"reports: {index} (one folder per target), {SUMMARY_JSON}")
    print(f"{summary['verdict']} — {summary['reason']}")
    return verdict_status(summary["verdict"], lost=lost, interrupted=interrupted or any(
        row["interrupted"] for row in summary["targets"]),
        accept_incomplete=args.accept_incomplete)


class _Fleet(StopSignals):
    """The fleet's signals: counted as a run counts them, each passed on at once, from
    the handler, as SIGINT to every running target (the third ends them at once too)."""

    def __init__(self, running: list[Member]) -> None:
        super().__init__()
        self.running = running

    def signal(self, *_: object) -> None:
        for m in self.running:
            _interrupt(m)
        super().signal()


def _interrupt(m: Member) -> None:
    if m.process is not None and m.process.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            os.kill(m.process.pid, signal.SIGINT)


def _results(folder: Path, m: Member) -> dict:
    """The member's results.json ({} when it wrote none)."""
    path = folder / m.label / "results.json"
    return json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}


def _recap(m: Member) -> list[str]:
    """What failed on the member's target, as a single run's recap says it."""
    data = m.result
    results = [CaseResult(d["id"], d["section"], data["cases"][d["id"]]["rule"], d["tag"],
                          data["cases"][d["id"]]["source"], d["profile"], d["target"],
                          d["verdict"], checks=d["checks"], notes=d["notes"])
               for d in data.get("results", [])]
    lines = recap(RunResult(data.get("run_id", m.label), results))
    return [f"[{m.label}] {line}" for line in lines]


def _run_members(members: list[Member], folder: Path, jobs: int, start: float,
                 shown: Progress) -> bool:
    """Run the members' processes, at most ``jobs`` at once; True when interrupted."""
    pending, running = deque(members), []
    wake: queue.Queue[Member] = queue.Queue()     # a member's process has ended
    out_lock = threading.Lock()
    interrupts = _Fleet(running)
    said = False
    try:
        with interrupts.catching():
            while pending or running:
                if interrupts.stopped and not said:
                    said = True
                    pending.clear()
                    print("fleet: interrupted; every running target halts its unit and "
                          "reports", file=sys.stderr, flush=True)
                while pending and len(running) < jobs and not interrupts.stopped:
                    m = pending.popleft()
                    # a signal now waits until the member is running and known to the
                    # handler, which passes it on: none is started and then forgotten
                    with StopSignals.held():
                        _start(m, folder, start, wake, out_lock, shown)
                        running.append(m)
                with contextlib.suppress(queue.Empty):
                    wake.get(timeout=0.5)
                running[:] = [m for m in running if m.status is None]
    except KeyboardInterrupt:           # the third signal: passed on, no more waiting
        print("fleet: stopped at once (third signal)", file=sys.stderr, flush=True)
        for m in running:
            with contextlib.suppress(subprocess.TimeoutExpired):
                if m.process is not None:
                    m.process.wait(5)
    return interrupts.stopped


def _start(m: Member, folder: Path, start: float, wake: queue.Queue,
           out_lock: threading.Lock, shown: Progress) -> None:
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    m.started = time.perf_counter() - start
    # its standard input is a pipe the fleet holds: its end tells the member the fleet
    # is gone (fleet_member.py)
    m.process = subprocess.Popen(
        [sys.executable, "-m", "conformance.cli.fleet_member",
         str(folder / f"{m.label}.job.json")],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        text=True, errors="replace", env=env, process_group=0)

    def relay() -> None:
        assert m.process is not None and m.process.stdout is not None
        for line in m.process.stdout:
            if shown.quiet:
                continue                # read all the same, so that the member never blocks
            with out_lock:
                shown.print(f"[{m.label}] {line}".rstrip())
        status = m.process.wait()
        with contextlib.suppress(OSError):
            m.process.stdin.close()
        m.ended = time.perf_counter() - start
        m.result = _results(folder, m)
        with out_lock:
            shown.step(f"{m.spec}: {m.result.get('verdict', FAILED)} — "
                       f"{m.result.get('reason', 'the target wrote no results')}")
        m.status = status               # last: the member counts as done from here
        wake.put(m)

    threading.Thread(target=relay, name=f"fleet-{m.label}", daemon=True).start()


def _write_summary(folder: Path, summary: dict) -> Path:
    """summary.json and index.html beside the targets' folders; the page's path."""
    write_text(folder / SUMMARY_JSON, json.dumps(summary, indent=1))
    return write_text(folder / INDEX_HTML, _index_html(summary))


def _summary(members: list[Member], run_id: str, seconds: float, interrupted: bool) -> dict:
    rows, counts = [], {}
    for m in members:
        r = m.result
        for verdict, n in r.get("counts", {}).items():
            counts[verdict] = counts.get(verdict, 0) + n
        rows.append({"target": m.spec, "folder": m.label, "exit_status": m.status,
                     "verdict": r.get("verdict", FAILED),
                     "reason": r.get("reason", "the target's process wrote no results"),
                     "counts": r.get("counts", {}), "seconds": r.get("seconds"),
                     "frames": r.get("frames", 0),
                     # a member stopped before its run began wrote no results
                     "interrupted": r.get("interrupted", m.status == INTERRUPTED),
                     "started": round(m.started, 3),
                     "ended": None if m.ended is None else round(m.ended, 3)})
    failed = [row for row in rows if row["verdict"] not in (PASSED, INCOMPLETE)
              and not row["interrupted"]]
    incomplete = [row for row in rows if row["verdict"] == INCOMPLETE]
    why = ([f"{len(failed)} of {len(rows)} targets failed"] if failed else []) + (
        ["interrupted before every target had run"] if interrupted else [])
    verdict, reason = (FAILED, "; ".join(why)) if why else (
        INCOMPLETE, f"{len(incomplete)} of {len(rows)} targets not tested whole") \
        if incomplete else (PASSED, f"all {len(rows)} targets passed")
    return {"run_id": run_id, "verdict": verdict, "reason": reason,
            "seconds": round(seconds, 3), "interrupted": interrupted, "counts": counts,
            "targets": rows}


def _print_summary(summary: dict) -> None:
    def text(counts: dict) -> str:
        return ", ".join(f"{v} {counts[v]}" for v in ORDER if v in counts) or "nothing run"

    width = max(len(row["target"]) for row in summary["targets"])
    print(f"\nfleet of {len(summary['targets'])} targets in {summary['seconds']:.1f} s:")
    for row in summary["targets"]:
        print(f"  {row['target']:{width}}  {row['verdict']:6}  {text(row['counts'])}")
    print(f"  {'all':{width}}  {summary['verdict']:6}  {text(summary['counts'])}")


def merge_junit(folder: Path, members: list[Member], path: str, seconds: float) -> Path:
    """One JUnit file: the testsuites of every target's junit.xml under one root."""
    root = ET.Element("testsuites", name="gve-conformance", time=f"{seconds:.3f}")
    tests = 0
    for m in members:
        source = folder / m.label / "junit.xml"
        if not source.is_file():
            continue
        for suite in ET.parse(source).getroot().iter("testsuite"):
            suite.set("id", str(len(root)))          # numbered from 0 across the fleet
            root.append(suite)
            tests += int(suite.get("tests", "0"))
    root.set("tests", str(tests))
    return write_text(path, ET.tostring(root, encoding="unicode", xml_declaration=True))


def _index_html(summary: dict) -> str:
    e = html.escape
    rows = "".join(
        f"<tr><td><a href=\"{e(row['folder'])}/report.html\">{e(row['target'])}</a></td>"
        f"<td>{e(row['verdict'])}</td><td>{e(row['reason'])}</td>"
        f"<td>{e(', '.join(f'{k} {v}' for k, v in row['counts'].items()))}</td></tr>"
        for row in summary["targets"])
    return (f"<!doctype html><meta charset=\"utf-8\"><title>gve-conformance fleet "
            f"{e(summary['run_id'])}</title><h1>{e(summary['verdict'])}: "
            f"{e(summary['reason'])}</h1><p>fleet {e(summary['run_id'])}, "
            f"{summary['seconds']:.1f} s</p><table border=\"1\" cellpadding=\"4\">"
            "<tr><th>target</th><th>verdict</th><th>why</th><th>cases</th></tr>"
            f"{rows}</table>\n")
