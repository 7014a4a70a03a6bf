"""A host certification: the clean run first (the baseline), then every fault scenario,
each a separate run of the host's job against fresh units.

Launched: the host program is started once per scenario with ``{port}`` replaced by the
port it should open; scenarios after the clean one run side by side where each can have
its own port (pseudo-terminals, TCP port 0). Attended: one port for the whole session;
the operator starts the host for each scenario and says when its job has ended.
"""

from __future__ import annotations

import contextlib
import os
import select
import signal
import subprocess
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import TextIO

from conformance.host import oracle
from conformance.host.checks import LineFacts, judge
from conformance.host.final_state import final_state
from conformance.host.line_faults import Fault
from conformance.host.oracle import HostResult, HostRun
from conformance.host.played_units import open_line
from conformance.host.ports import HostPort, open_port
from conformance.host.relay import Relay
from conformance.host.scenarios import Baseline, Scenario
from conformance.host.unitview import line_views, profiles_by_address
from conformance.link.signals import STOPPING, StopSignals
from conformance.run.metadata import now_iso
from conformance.run.runner import RunResult
from conformance.verdicts.verdict import COULD_NOT_TEST, MISSING
from gve_fixtures.profile import Profile

#: the longest a clean run may take unless the user says otherwise (--clean-limit)
CLEAN_LIMIT_S = 120.0
#: operator answers in attended mode -> the exit status they stand for
OPERATOR = {"": 0, "done": 0, "ok": 0, "failed": 1, "fail": 1, "gave up": 1}


@dataclass
class Plan:
    units: list[tuple[Profile, int]]
    baud: int
    scenarios: list[Scenario]
    command: list[str] | None = None      # None: attended
    port: str = "pty"
    host_timeout: float = 5.0
    strict: bool = False
    jobs: int = 4
    #: address -> the full steps per axis the clean run must travel (--expect-motion)
    expect_motion: dict[int, tuple[int, ...]] | None = None
    #: the longest the clean run may take (a fault run's limit follows from its length)
    clean_limit: float = CLEAN_LIMIT_S
    #: the emulator readings the played units take (none: the project's decisions)
    readings: tuple[str, ...] = ()
    stop: threading.Event = field(default_factory=threading.Event)   # Ctrl-C
    baseline: Baseline | None = None      # what the clean run showed, once it has run
    started: set[str] = field(default_factory=set)   # scenarios whose host run has begun

    @property
    def profile(self) -> str:
        return " ".join(f"{p.name}@{a}" for p, a in self.units)

    @property
    def target(self) -> str:
        return "host: " + (" ".join(self.command) if self.command else "attended")

    @property
    def parallel(self) -> bool:
        return self.port == "pty" or self.port.endswith(":0")


class HostStartError(OSError):
    """The host program could not be started at all."""


#: how long a host program has to end after SIGTERM before its process group is killed
TERM_GRACE_S = 2.0


def _stop(proc: subprocess.Popen) -> None:
    """End the host program and everything it started (its process group): SIGTERM, then
    SIGKILL for what is still there after a grace period. A signal to the suite meanwhile
    waits until the host is gone, so that nothing is left behind."""
    with StopSignals.held():
        for sig, grace in ((signal.SIGTERM, TERM_GRACE_S), (signal.SIGKILL, None)):
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, sig)
            try:
                proc.wait(grace)
                break
            except subprocess.TimeoutExpired:
                continue
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)     # what the host left in its group
        _wait_group_gone(proc.pid, time.monotonic() + TERM_GRACE_S)


def _alive_in_group(pgid: int) -> list[int]:
    """The processes of group ``pgid`` still running (zombies waiting to be reaped are not);
    empty where ``/proc`` cannot tell."""
    alive = []
    with contextlib.suppress(OSError):
        for entry in os.scandir("/proc"):
            if not entry.name.isdigit():
                continue
            try:
                stat = Path(f"/proc/{entry.name}/stat").read_text()
            except OSError:
                continue
            fields = stat.rsplit(")", 1)[1].split()
            if fields[0] != "Z" and int(fields[2]) == pgid:
                alive.append(int(entry.name))
    return alive


def _wait_group_gone(pgid: int, deadline: float) -> None:
    """SIGKILL is delivered asynchronously: on a loaded machine a killed child can still be
    running when killpg returns, so poll until the group is gone (or the deadline)."""
    while _alive_in_group(pgid) and time.monotonic() < deadline:
        time.sleep(0.01)


def run_once(plan: Plan, fault: Fault, port: HostPort, *,
             done: Callable[[], int | None] | None = None,
             limit: float = CLEAN_LIMIT_S) -> HostRun:
    """One run of the host's job under ``fault``: launched (``plan.command``), or until
    ``done()`` returns the exit status the operator reported."""
    line = open_line(plan.units, plan.baud, plan.readings)
    views = line_views(plan.units)
    relay = Relay(port, line, views, fault, plan.baud)
    start = time.monotonic()
    try:
        if plan.command is None:
            assert done is not None
            ended, code, output = _attended_run(relay, done)
        else:
            ended, code, output = _launched_run(relay, plan, port, limit)
        seconds = time.monotonic() - start
        relay.finish()
        finals = {v.address: final_state(line, v, relay.rec) for v in views}
    finally:
        line.close()
    return HostRun(relay.rec, views, finals, code, ended, seconds, fault, output)


def _attended_run(relay: Relay, done: Callable[[], int | None]) -> tuple[str, int | None, str]:
    said: list[int] = []

    def answered() -> bool:
        code = done()
        if code is not None:
            said.append(code)
        return code is not None

    relay.serve(answered, None, None)
    return ("silent", None, "") if said[-1] < 0 else ("operator", said[-1], "")


def _launched_run(relay: Relay, plan: Plan, port: HostPort,
                  limit: float) -> tuple[str, int | None, str]:
    """Start the host, relay until it exits (or hangs, or Ctrl-C), stop it if need be."""
    argv = [a.replace("{port}", port.name) for a in plan.command or []]
    proc: subprocess.Popen | None = None
    with tempfile.TemporaryFile() as log:
        try:
            # a signal waits until the host is known, so that it is stopped, never orphaned
            with StopSignals.held():
                try:
                    proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=log,
                                            stderr=subprocess.STDOUT, start_new_session=True)
                except OSError as err:
                    raise HostStartError(f"cannot start {argv[0]!r}: {err}") from err
            ended = relay.serve(lambda: proc.poll() is not None or plan.stop.is_set(),
                                plan.host_timeout, limit)
        finally:
            if proc is not None and proc.poll() is None:
                _stop(proc)
        if plan.stop.is_set() and ended == "done":
            ended = "interrupted"
        ended = "exited" if ended == "done" else ended
        log.seek(0)
        output = log.read()[-4000:].decode("utf-8", "replace")
    return ended, proc.returncode if ended == "exited" else None, output


def baseline_of(out: HostRun) -> Baseline | None:
    if out.ended not in ("exited", "operator") or out.exit_code != 0:
        return None
    b = Baseline(oracle.executed(out.views), out.finals, out.recording.exchanges,
                 out.seconds)
    for view in out.views:
        found = view.interrupt_input()
        if found is not None:
            b.interrupt = (view.address, *found)
            break
    return b


def grade(plan: Plan, sc: Scenario, out: HostRun) -> HostResult:
    """The scenario's result, against the plan's baseline (the clean run's)."""
    units = profiles_by_address(out.views)
    line = LineFacts(out.views, units, plan.baud, out.recording.origin, out.exit_code)
    g = oracle.Grader(sc, plan.strict)
    oracle.wire_checks(g, judge(out.recording, line))
    oracle.motion_checks(g, out, plan.baseline, plan.expect_motion)
    if sc.name == "interrupt":
        oracle.interrupt_checks(g, out.recording)
    return oracle.result(g, out, plan.profile, plan.target)


def _fault_limit(plan: Plan) -> float:
    """How long a fault run may take: twice the clean one, and time to give up."""
    restart = max(p.restart_ms for p, _ in plan.units) / 1000
    seconds = plan.baseline.seconds if plan.baseline is not None else plan.clean_limit
    return 2 * seconds + 2 * plan.host_timeout + restart


def launched(plan: Plan, on_result: Callable[[HostResult], None]) -> None:
    """Every scenario of ``plan`` with its host program started for each: the clean run,
    then the others side by side; ``on_result`` gets them in scenario order."""
    def run(sc: Scenario, fault: Fault, limit: float) -> HostRun:
        plan.started.add(sc.id)
        port = open_port(plan.port, plan.baud)
        try:
            return run_once(plan, fault, port, limit=limit)
        finally:
            port.close()

    clean, rest = plan.scenarios[0], plan.scenarios[1:]
    out = run(clean, Fault(), plan.clean_limit)
    plan.baseline = baseline_of(out)
    on_result(grade(plan, clean, out))
    made = [_build(sc, plan) for sc in rest]
    workers = plan.jobs if plan.parallel else 1
    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        futures = [m if isinstance(m, HostResult) else
                   pool.submit(lambda sc, m: grade(plan, sc, run(sc, m, _fault_limit(plan))),
                               sc, m)
                   for sc, m in zip(rest, made, strict=True)]
        try:
            for f in futures:
                on_result(f if isinstance(f, HostResult) else f.result())
        except KeyboardInterrupt:
            plan.stop.set()                     # every relay stops, every host is killed
            for f in futures:
                if not isinstance(f, HostResult):
                    f.cancel()
            raise


def _build(sc: Scenario, plan: Plan) -> Fault | HostResult:
    """The scenario's fault, or its result when it cannot run."""
    if plan.baseline is None:
        return oracle.skipped(sc, COULD_NOT_TEST, "no baseline: the host did not finish "
                              "its job on the clean line", plan.profile, plan.target)
    made = sc.build(plan.baseline)
    if isinstance(made, str):
        return oracle.skipped(sc, MISSING, made, plan.profile, plan.target)
    return made


def attended(plan: Plan, on_result: Callable[[HostResult], None], console: TextIO,
             operator: TextIO) -> None:
    """Every scenario in turn on one port; the operator runs the host and reports."""
    port = open_port(plan.port, plan.baud)
    gone: dict[str, bool] = {}
    print(f"port: {port.name}", file=console, flush=True)
    try:
        for n, sc in enumerate(plan.scenarios, 1):
            made = Fault() if sc.name == "clean" else _build(sc, plan)
            if gone:
                made = oracle.skipped(sc, COULD_NOT_TEST, "the operator ended the session",
                                      plan.profile, plan.target)
            if isinstance(made, HostResult):
                on_result(made)
                continue
            port.read()                          # what an earlier run left unread
            print(f"[{n}/{len(plan.scenarios)}] {sc.id}: {sc.title}.\n"
                  f"  Start the host's job on {port.name} now. When it has ended, type "
                  "`done` (it finished), `failed` (it reported an error or gave up) or "
                  "`hung` (it stopped answering), then Enter.", file=console, flush=True)
            plan.started.add(sc.id)
            out = run_once(plan, made, port, done=lambda: _operator(operator, gone))
            if sc.name == "clean":
                plan.baseline = baseline_of(out)
            on_result(oracle.skipped(sc, COULD_NOT_TEST, "the operator ended the session "
                                     "before saying how the job ended", plan.profile,
                                     plan.target) if gone else grade(plan, sc, out))
    finally:
        port.close()


def _operator(stream: TextIO, state: dict[str, bool]) -> int | None:
    """The exit status the operator reports (-1: the host hung), None: not yet."""
    if not select.select([stream], [], [], 0)[0]:
        return None
    text = stream.readline()
    if not text:
        state["gone"] = True
        return -1
    word = text.strip().lower()
    if word in ("hung", "hang", "hangs"):
        return -1
    return OPERATOR.get(word, 1)


@contextlib.contextmanager
def stopping_signals() -> Iterator[None]:
    """SIGTERM and SIGHUP (a CI job's timeout, a closed terminal) stop a certification as
    Ctrl-C does: every host program is stopped and the reports are written."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, signal.default_int_handler) for sig in STOPPING}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def certify(plan: Plan, run_id: str, on_result: Callable[[HostResult], None],
            console: TextIO | None = None, operator: TextIO | None = None) -> RunResult:
    run = RunResult(run_id, targets=[plan.target], settings="host")
    # a certification's evidence is its wire log both ways with the faults marked on it:
    # every scenario keeps it whole, passing or not
    run.meta.started, run.meta.full_logs = now_iso(), True
    run.meta.strict = plan.strict
    start = time.monotonic()
    results: list[HostResult] = []

    def keep(r: HostResult) -> None:
        results.append(r)
        on_result(r)

    try:
        with stopping_signals():
            if plan.command is None:
                assert console is not None and operator is not None
                attended(plan, keep, console, operator)
            else:
                launched(plan, keep)
    except KeyboardInterrupt:
        plan.stop.set()
        run.interrupted = True
        done = {r.id for r in results}
        for sc in plan.scenarios:
            if sc.id in done:
                continue
            running = sc.id in plan.started
            r = oracle.skipped(sc, COULD_NOT_TEST, "interrupted by a signal: the host "
                               "program was stopped, the scenario not judged" if running else
                               "not run: the certification was interrupted by a signal",
                               plan.profile, plan.target)
            r.interrupted = running
            results.append(r)
    run.results = list(results)
    run.seconds = time.monotonic() - start
    run.frames = sum(r.frames for r in results)
    run.meta.finished = now_iso()
    return run
