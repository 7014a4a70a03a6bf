"""The pytest plugin (entry point ``gve_conformance``): run the suite's cases as pytest
items with ``pytest --gve-target emu:GVE84-100`` (any target of the command line).

Inert unless ``--gve-target`` is given (or ``pytest --pyargs conformance``, which runs
against the default emulator target), so it never changes other pytest runs. Given, it
is the collector: the session collects the suite's cases and nothing else (no test
file of the directory pytest runs in), one collector per target and per spec section,
one item per case; ``--collect-only``, ``-k``, ``-m`` and ``--gve-cases`` choose among
them. A mistake in the options is a usage error before anything is sent; one session
per target lasts the whole pytest run and puts the unit back at its end (also after
Ctrl-C).

Verdicts as pytest shows them (docs/ci.md): PASS passed, FAIL and ERROR failed (the
deciding check, its rule, tag and the rule's sentence in the report); NON-STRICT and
INFO outcomes of their own (``N`` and ``I``, counted in the last line, listed with why in
the short summary); COULD-NOT-TEST and MISSING skipped, naming the case and why. In
``--junitxml`` a case's classname is the suite's (``gve.<profile>.section<N_M>``), its
properties say its verdict, tag and section, and NON-STRICT and INFO are skipped
testcases whose message begins with the verdict, as in the suite's own JUnit file.
Markers choose by tag and need: ``-m "not destructive"``, ``-m "tag_M"`` (see
``pytest --markers`` with ``--gve-target``).

Fleets (pytest-xdist, ``-n N``): the items of a target that holds a port (serial, TCP)
form one xdist group (``--dist loadgroup``, which the plugin sets), so that one worker has
the port for the whole run; items of an ``emu:`` target (a fresh unit in process for
every link) spread over the workers. The controller only checks that each port opens;
a worker opens a target's port at its first item of that target.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Generator, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path

import pytest

from conformance.case import settings as settings_profiles
from conformance.case.context import Case
from conformance.case.settings import PROFILES
from conformance.link.signals import StopSignals
from conformance.operator.consent import Consent, NoConsent
from conformance.operator.console import Console
from conformance.pytest_plugin.stop import before_item, hold, interrupted
from conformance.run.runner import CaseResult, run_case
from conformance.targets import DEFAULT_MAX_TRAVEL, Target, parse_target
from conformance.verdicts.explain import plain, reason
from conformance.verdicts.quoting import quoted
from conformance.verdicts.verdict import (
    COULD_NOT_TEST,
    ERROR,
    FAIL,
    INCOMPLETE,
    INFO,
    MISSING,
    NON_STRICT,
    PASSED,
    UNTESTED,
    overall,
)

_TARGETS = pytest.StashKey[list[Target]]()
_INTERRUPTS = pytest.StashKey[StopSignals]()
_MOTION = pytest.StashKey[bool]()
#: the controller's answer to "Move this machine?", given to an xdist worker
MOTION_ALLOWED = "gve_motion_allowed"


def pytest_addoption(parser: pytest.Parser) -> None:
    g = parser.getgroup("gve-conformance", "GVE protocol conformance suite")
    g.addoption("--gve-target", action="append", default=[],
                help="run the suite's cases against this target (emu:PROFILE, serial:..., "
                     "tcp:..., exec:COMMAND)")
    g.addoption("--gve-profile", default=None,
                help="the profile a serial/tcp/exec target behaves as")
    g.addoption("--gve-cases", action="append", default=[], metavar="GLOB",
                help="run only cases whose ID matches (repeatable)")
    g.addoption("--gve-exclude", action="append", default=[], metavar="GLOB",
                help="leave out cases whose ID matches (repeatable; after --gve-cases)")
    g.addoption("--gve-mutant", default=None, metavar="NAME",
                help="emulator targets: plant this deliberate bug")
    g.addoption("--gve-seed", type=int, default=None, metavar="N",
                help="the Hypothesis machines' seed: the same N replays the same examples "
                     "(default: the settings' own, derandomized in ci)")
    g.addoption("--gve-settings", default=None,
                help="Hypothesis settings profile (default: ci in virtual time, the "
                     "emulator's or a co-simulator's; hardware on serial/tcp/exec targets)")
    g.addoption("--gve-yes", action="store_true",
                help="real units: move without asking first (unattended benches); without "
                     "it a unit that can move is asked about on the terminal, and with no "
                     "terminal the run is refused before anything is sent")
    g.addoption("--gve-max-travel", type=int, default=DEFAULT_MAX_TRAVEL, metavar="N",
                help="real units: the motion envelope in full steps per axis either side "
                     f"of where the run began (default {DEFAULT_MAX_TRAVEL})")
    g.addoption("--gve-allow-destructive", action="store_true",
                help="real units: allow J, W and EEPROM writes (EEPROM backed up and "
                     "restored)")
    g.addoption("--gve-accept-incomplete", action="store_true",
                help="pass a run that FAILed nothing yet did not test what it was asked to "
                     "(INCOMPLETE: motion declined, no rig...); otherwise it fails")
    g.addoption("--gve-strict", action="store_true",
                help="grade a serial/tcp/exec target by the project's decisions too: a "
                "[D] difference FAILs instead of NON-STRICT (the embedded emulator "
                "always is)")
    g.addoption("--gve-hypothesis-db", default=None, metavar="DIR|redis://HOST:PORT/N|none",
                help="where the machines keep failing examples, tried first on the next run "
                     f"(default: {settings_profiles.DEFAULT_DATABASE}/ in the rootdir)")


#: an item's markers by its case's tag (-m "tag_M") and by what it needs
TAG_MARKERS = {"M": "tag_M", "M-ex": "tag_M_ex", "D": "tag_D", "D-info": "tag_D_info"}
NEEDS = {"rig": "needs the test rig or a technician's hands",
         "destructive": "restarts the unit, runs to a switch or writes EEPROM "
                        "(--gve-allow-destructive)",
         "timing": "judges when the unit answers or where it is in time",
         "hands": "needs a hand on the machine: the rig or an operator"}
#: the verdicts pytest shows as outcomes of their own: (category, letter, word)
OWN_OUTCOMES = {NON_STRICT: ("non-strict", "N", "NON-STRICT"), INFO: ("info", "I", "INFO")}
#: the verdicts reported as skipped, with the verdict and why as the reason
SKIPPED = (NON_STRICT, INFO, COULD_NOT_TEST, MISSING)


class CaseFailed(Exception):
    def __init__(self, result: CaseResult) -> None:
        super().__init__(result.verdict)
        self.result = result


@dataclass(frozen=True)
class _Crash:
    """Where a failed case is and its one line (pytest's short summary and JUnit
    message read ``message``)."""

    path: str
    lineno: int
    message: str


class CaseReport:
    """A FAIL or ERROR as pytest shows it: its one line (the verdict, the case and why),
    the rule's sentence, every failed check, the notes and the wire log."""

    def __init__(self, lines: list[str], crash: _Crash) -> None:
        self.lines = lines
        self.reprcrash = crash

    def toterminal(self, tw) -> None:
        for line in self.lines:
            tw.line(line)

    def __str__(self) -> str:
        return "\n".join(self.lines)


class Terminal(Console):
    """The terminal behind pytest's capture: each line shown and each question asked
    with the capture suspended, so that a person sees the question and answers it."""

    def __init__(self, config: pytest.Config) -> None:   # no look at the terminal yet
        self._capture = config.pluginmanager.getplugin("capturemanager")
        self.stdin, self.stdout = sys.__stdin__, sys.__stdout__
        self._interactive: bool | None = None

    @property
    def interactive(self) -> bool:
        """Whether a person can answer: the terminal behind the capture, looked at only
        when a question may be needed."""
        if self._interactive is None:
            with self._uncaptured():
                self._interactive = self.stdin is not None and self.stdin.isatty()
        return self._interactive

    @contextmanager
    def _uncaptured(self) -> Iterator[None]:
        if self._capture is None:
            yield
            return
        self._capture.suspend(in_=True)     # standard input too: the answer is typed there
        try:
            yield
        finally:
            self._capture.resume()

    def say(self, text: str) -> None:
        with self._uncaptured():
            super().say(text)

    def _answer(self, prompt: str) -> str | None:
        with self._uncaptured():
            return super()._answer(prompt)


def verdict_line(r: CaseResult) -> str:
    """``NON-STRICT 8.repeat.answer [emu:GVE84-100]: 8.repeat.answer [D] ...``."""
    return f"{r.verdict} {r.id} [{r.target}]: {reason(r).line()}"


def _where(case: Case) -> tuple[str, int]:
    """The case's file and the line its @case starts on (1-based)."""
    code = case.func.__code__
    return code.co_filename, code.co_firstlineno


class GveTarget(pytest.Collector):
    """The suite's cases on one target, a collector per spec section."""

    def __init__(self, *, target: Target, **kw) -> None:
        super().__init__(**kw)
        self.target = target

    def collect(self) -> list[GveSection]:
        from conformance.run.selection import select
        sections: dict[str, list[Case]] = {}
        for case in select(self.config.getoption("--gve-cases") or None,
                           self.config.getoption("--gve-exclude") or None):
            sections.setdefault(case.section, []).append(case)
        return [GveSection.from_parent(self, name=f"section{s.replace('.', '_')}",
                                       nodeid=f"{self.nodeid}::{s}", cases=cases)
                for s, cases in sections.items()]


class GveSection(pytest.Collector):
    """The cases of one spec section on the parent's target."""

    def __init__(self, *, cases: list[Case], **kw) -> None:
        super().__init__(**kw)
        self.cases = cases

    def collect(self) -> list[GveItem]:
        from conformance.reports.junit import classname
        target = self.parent.target
        # on an xdist worker the node ID names the group, as xdist_group marks do
        group = worker_group(target) if _on_xdist_worker(self.config) else None
        settings_name = self.config.getoption("--gve-settings")
        items = []
        for case in self.cases:
            # the node ID is the suite's JUnit classname as a path: pytest's JUnit file
            # then gives the case the classname the suite's own gives it
            where = classname(target.profile.name, case.section).replace(".", "/")
            name = f"{case.id}[{target.info.spec}]"
            item = GveItem.from_parent(self, name=name,
                                       nodeid=f"{where}::{name}" + (f"@{group}" if group
                                                                    else ""),
                                       case=case, target=target, settings_name=settings_name)
            item.add_marker(TAG_MARKERS[case.tag])
            for need in NEEDS:
                if getattr(case, need):
                    item.add_marker(need)
            items.append(item)
        return items


class GveItem(pytest.Item):
    def __init__(self, *, case: Case, target: Target, settings_name: str | None,
                 **kw) -> None:
        super().__init__(**kw)
        self.case, self.target, self.settings_name = case, target, settings_name
        self.result: CaseResult | None = None

    def runtest(self) -> None:
        interrupts = self.config.stash[_INTERRUPTS]
        before_item(self.session, interrupts)
        try:
            # a worker starts its targets here, at its first item of each (an exec:
            # target's program: whether it has a rig decides the rig cases)
            self.target.preflight()
        except (ValueError, LookupError) as err:
            pytest.fail(str(err), pytrace=False)
        with interrupts.catching():
            result = run_case(self.case, self.target, self.settings_name,
                              seed=self.config.getoption("--gve-seed"))
        self.result = result
        self.user_properties += [("verdict", result.verdict), ("tag", self.case.tag),
                                 ("section", self.case.section)]
        if result.verdict in UNTESTED:          # why, for the run's verdict (verdict.py)
            self.user_properties.append((NOT_TESTED, "\n".join(result.notes)))
        if result.interrupted:
            interrupted(self.session)       # its verdict reported, no item after it
        if result.verdict in (FAIL, ERROR):
            raise CaseFailed(result)

    def repr_failure(self, excinfo, style=None):
        if isinstance(excinfo.value, CaseFailed):
            r = excinfo.value.result
            why = reason(r)
            lines = [verdict_line(r)]
            lines += [f"the rule: {why.cites()}"] if why.rule else []
            lines += [f"the case: {plain(r.rule)} ({plain(r.source)})"]
            lines += [f"  [{c['tag']}] {c['what']}: observed {quoted(c['observed'])}, "
                      f"expected {quoted(c['expected'])}" for c in r.failed_checks]
            path, line = _where(self.case)
            from conformance.reports.junit import message
            return CaseReport(lines + r.notes + ["wire log:", *r.wire_log],
                              _Crash(path, line, message(r)))
        return super().repr_failure(excinfo, style)

    def reportinfo(self):
        path, line = _where(self.case)
        return path, line - 1, f"{self.case.id} on {self.target.info.spec}"


def _specs(config: pytest.Config) -> list[str]:
    specs = config.getoption("--gve-target")
    if not specs and config.getoption("pyargs") and "conformance" in config.args:
        specs = ["emu:GVE84-100"]      # `pytest --pyargs conformance`: the default target
    # emu:all, as on the command line: the embedded emulator on every profile, with the
    # settings given
    every = [spec for given in specs for spec in (_every_profile(given) or [given])]
    return list(dict.fromkeys(every))       # a target named twice runs once


def _every_profile(spec: str) -> list[str]:
    """``emu:all[?settings]`` as one target per profile; [] for any other target."""
    name, _, query = spec.partition("?")
    if name != "emu:all":
        return []
    from gve_fixtures.profile import available_profiles
    return [f"emu:{p}" + (f"?{query}" if query else "") for p in available_profiles()]


def _on_xdist_worker(config: pytest.Config) -> bool:
    return hasattr(config, "workerinput")


def _xdist_controller(config: pytest.Config) -> bool:
    return (getattr(config.option, "dist", "no") != "no" and bool(getattr(config.option, "tx",
                                                                          None))
            and not _on_xdist_worker(config))


def worker_group(target: Target) -> str | None:
    """The xdist group of a target's items: its port, or None (emu: nothing shared)."""
    if not target.info.real:
        return None
    # loadgroup reads the group after a node ID's last '@', past its last ']'
    return "gve-port:" + re.sub(r"[@\[\]]", "_", target.url)


def _example_database(config: pytest.Config) -> None:
    where = config.getoption("--gve-hypothesis-db")
    if where is None:
        where = str(Path(config.rootpath, settings_profiles.DEFAULT_DATABASE))
    run = ExitStack()
    try:
        run.enter_context(settings_profiles.example_database(where))
    except ValueError as err:
        raise pytest.UsageError(f"--gve-hypothesis-db: {err}") from None
    config.add_cleanup(run.close)


def pytest_configure(config: pytest.Config) -> None:
    """Check every option before anything is collected or sent (a usage error, not an
    INTERNALERROR or a failed test per case)."""
    specs = _specs(config)
    if not specs:
        return
    settings = config.getoption("--gve-settings")
    if settings is not None and settings not in PROFILES:
        raise pytest.UsageError(f"--gve-settings {settings!r}: one of {', '.join(PROFILES)}")
    from conformance.run.selection import select
    globs, exclude = config.getoption("--gve-cases"), config.getoption("--gve-exclude")
    if (globs or exclude) and not select(globs or None, exclude or None):
        raise pytest.UsageError(" ".join([f"--gve-cases {g}" for g in globs]
                                         + [f"--gve-exclude {g}" for g in exclude])
                                + ": no case matches")
    _example_database(config)
    for marker in TAG_MARKERS.values():
        config.addinivalue_line("markers", f"{marker}: a case of the suite whose tag is "
                                           f"{marker[4:].replace('_', '-')}")
    for marker, what in NEEDS.items():
        config.addinivalue_line("markers", f"{marker}: a case of the suite that {what}")
    controller, worker = _xdist_controller(config), _on_xdist_worker(config)
    if controller and config.option.dist != "loadgroup":
        config.option.dist = "loadgroup"    # only groups keep a port on one worker
    interrupts = StopSignals()
    targets, opened = [], []
    consent = _consent(config, worker)
    try:
        for spec in specs:
            target = parse_target(spec, profile=config.getoption("--gve-profile"),
                                  allow_destructive=config.getoption("--gve-allow-destructive"),
                                  max_travel=config.getoption("--gve-max-travel"),
                                  mutant=config.getoption("--gve-mutant"),
                                  strict=config.getoption("--gve-strict"))
            opened.append(target)
            if not worker:
                target.preflight()
        if not worker:
            consent.check(opened)        # no yes and nobody to ask: refused, nothing sent
        if controller:      # asked once here: the workers have no terminal
            config.stash[_MOTION] = consent.ask_once(opened, lambda t: ("", ""))
        for target in opened:
            if controller:
                target.close()      # it runs nothing; the worker of the port opens it
                continue
            target.begin(interrupts)
            consent.arm(target)
            targets.append(target)
    except NoConsent as err:
        for t in opened:
            t.close()
        raise pytest.UsageError(str(err)) from None
    except (ValueError, LookupError) as err:
        for t in opened:
            t.close()
        raise pytest.UsageError(str(err)) from None
    config.stash[_TARGETS] = targets
    config.stash[_INTERRUPTS] = interrupts
    config.stash[_VERDICT] = verdict = RunVerdict()
    config.pluginmanager.register(verdict, "gve-conformance-verdict")
    config.pluginmanager.register(WholeReasons(), WholeReasons.NAME)
    hold(config, interrupts, controller=controller)


def _consent(config: pytest.Config, worker: bool) -> Consent:
    """The run's consent to motion (conformance/operator/consent.py): --gve-yes, else the question
    on the terminal; an xdist worker takes its controller's answer."""
    if worker:
        return Consent(bool(config.workerinput.get(MOTION_ALLOWED)),
                       Console(interactive=False), flag="--gve-yes")
    return Consent(config.getoption("--gve-yes"), Terminal(config), flag="--gve-yes")


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node) -> None:
    """pytest-xdist: a worker starts with its controller's answer about motion."""
    node.workerinput[MOTION_ALLOWED] = node.config.stash.get(_MOTION, False)


@pytest.hookimpl(tryfirst=True)
def pytest_make_collect_report(collector: pytest.Collector) -> pytest.CollectReport | None:
    """With --gve-target the session collects the suite's cases, one collector per
    target, and nothing else (the test files of where pytest runs are not the suite)."""
    if not isinstance(collector, pytest.Session) or _TARGETS not in collector.config.stash:
        return None
    found = [GveTarget.from_parent(collector, name=t.info.spec, nodeid=f"gve[{t.info.spec}]",
                                   target=t)
             for t in collector.config.stash[_TARGETS]]
    return pytest.CollectReport(collector.nodeid, "passed", None, found)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo
                              ) -> Generator[None, pytest.TestReport, pytest.TestReport]:
    """A case's verdict on its report; the verdicts pytest knows as skipped (NON-STRICT,
    INFO, COULD-NOT-TEST, MISSING) skipped with the case and why as the reason."""
    report = yield
    r = getattr(item, "result", None)
    if call.when == "call" and r is not None:
        report.gve_verdict = r.verdict
        report.gve_why = reason(r).line()
        if r.verdict in SKIPPED and report.passed:
            path, line = _where(item.case)
            report.outcome = "skipped"
            report.longrepr = (path, line, verdict_line(r))
    return report


def pytest_report_teststatus(report: pytest.TestReport, config: pytest.Config
                             ) -> tuple[str, str, str] | None:
    """NON-STRICT and INFO as outcomes of their own: a letter while running, a word with
    -v, their own count in the last line."""
    if report.when != "call":
        return None
    return OWN_OUTCOMES.get(getattr(report, "gve_verdict", ""))


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_terminal_summary(terminalreporter, exitstatus: int, config: pytest.Config
                            ) -> Generator[None, None, None]:
    """After pytest's short summary (whose FAILED lines carry why, whole:
    :class:`WholeReasons`): the NON-STRICT and INFO cases, which it does not list, each
    with why, wherever the summary lists what did not pass (``-r`` with f, s or p: the
    default, -ra, -rA)."""
    yield
    whole = config.pluginmanager.get_plugin(WholeReasons.NAME)
    if whole is not None:
        whole.restore(config)
    chars = getattr(terminalreporter, "reportchars", "")
    if not any(c in chars for c in "fsp"):
        return
    reports = [rep for word in ("non-strict", "info") for rep in
               terminalreporter.stats.get(word, [])
               if getattr(rep, "gve_why", None) and rep.when == "call"]
    if reports:
        terminalreporter.write_sep("=", "gve-conformance: NON-STRICT and INFO", yellow=True)
        for rep in reports:
            terminalreporter.write_line(f"{rep.gve_verdict} {rep.nodeid} - {rep.gve_why}")


class WholeReasons:
    """pytest's short summary (``FAILED <node ID> - <why>``) with why whole: pytest trims
    it to the terminal's width, and drops it where the node ID (a case, its profile's
    section and its target) fills the width alone, except at ``-vv``. The summary is
    written at ``-vv`` and the verbosity given back right after it (registered with the
    suite's targets only: no other pytest run is changed)."""

    NAME = "gve-conformance-whole-reasons"

    def __init__(self) -> None:
        self.given: int | None = None

    @pytest.hookimpl(wrapper=True, trylast=True)
    def pytest_terminal_summary(self, config: pytest.Config) -> Generator[None, None, None]:
        # inside pytest's own wrapper, whose short summary follows this one's end
        yield
        self.given = config.option.verbose
        config.option.verbose = max(self.given, 2)

    def restore(self, config: pytest.Config) -> None:
        if self.given is not None:
            config.option.verbose, self.given = self.given, None


@dataclass
class _Seen:
    """A case's verdict as the run's verdict reads it: the verdict and its notes (why
    it was not tested)."""

    verdict: str
    notes: list[str]


class RunVerdict:
    """The suite's verdict for the whole pytest run, from every case's report (on an
    xdist controller too: the reports carry their verdicts): PASSED, INCOMPLETE or
    FAILED, as the command line's last line says it."""

    def __init__(self) -> None:
        self.seen: list[_Seen] = []

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        props = dict(report.user_properties)
        if report.when == "call" and "verdict" in props:
            self.seen.append(_Seen(props["verdict"], props.get(NOT_TESTED, "").split("\n")))

    def line(self, interrupted: bool, problems: list[str]) -> tuple[str, str]:
        return overall(self.seen, interrupted, problems)


_VERDICT = pytest.StashKey[RunVerdict]()
#: the user property of a case not tested: its notes, a line each
NOT_TESTED = "not tested because"


@pytest.hookimpl(tryfirst=True)
def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """The end of the pytest run (also after Ctrl-C): every session puts its unit back;
    what could not be put back is printed and fails the run. Then the suite's verdict:
    one that is not PASSED fails the pytest run (one that FAILed nothing yet did not
    test what it was asked to, INCOMPLETE, passes with --gve-accept-incomplete)."""
    problems, broken = [], []
    for target in session.config.stash.get(_TARGETS, []):
        report = target.session.finish()
        target.close()
        problems += [f"{target.info.spec}: {p}" for p in report.problems]
        # a known-state step the unit broke: a FAIL of its rule, whichever item met it
        broken += [f"{target.info.spec}: {f.rule}: the known state: {f.what}: {f.observed}"
                   for f in target.session.failures]
    for problem in problems:
        print(f"\ngve-conformance: PROBLEM on {problem}")
    for failure in broken:
        print(f"\ngve-conformance: FAIL on {failure}")
    if (problems or broken) and session.exitstatus == pytest.ExitCode.OK:
        session.exitstatus = pytest.ExitCode.TESTS_FAILED
    verdict = session.config.stash.get(_VERDICT, None)
    if verdict is None or _on_xdist_worker(session.config) or not verdict.seen:
        return
    word, tail = verdict.line(session.exitstatus == pytest.ExitCode.INTERRUPTED,
                              problems + broken)
    print(f"\ngve-conformance: {word} — {tail}")
    accepted = word == PASSED or (word == INCOMPLETE and session.config.getoption(
        "--gve-accept-incomplete"))
    if not accepted and session.exitstatus == pytest.ExitCode.OK:
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_unconfigure(config: pytest.Config) -> None:
    """A run that ended before its session finished (a usage error later on): the
    sessions still put their units back."""
    for target in config.stash.get(_TARGETS, []):
        target.session.finish()
        target.close()
