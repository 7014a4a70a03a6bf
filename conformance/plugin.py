"""The pytest plugin (entry point ``gve_conformance``): run the suite's cases as pytest
items with ``pytest --gve-target emu:GVE84-100`` (any target of the command line).

Inert unless ``--gve-target`` is given (or ``pytest --pyargs conformance``, which runs
against the default emulator target), so it never changes other pytest runs. A mistake
in the options is a usage error before anything is sent; one session per target lasts
the whole pytest run and puts the unit back at its end (also after Ctrl-C).

Fleets (pytest-xdist, ``-n N``): the items of a target that holds a port (serial, TCP)
form one xdist group (``--dist loadgroup``, which the plugin sets), so that one worker has
the port for the whole run; items of an ``emu:`` target (a fresh unit in process for
every link) spread over the workers. The controller only checks that each port opens;
a worker opens a target's port at its first item of that target.
"""

from __future__ import annotations

import re
from contextlib import ExitStack
from pathlib import Path

import pytest

from conformance import settings as settings_profiles
from conformance.link.interrupts import Interrupts
from conformance.runner import CaseResult, run_case
from conformance.settings import PROFILES
from conformance.targets import DEFAULT_MAX_TRAVEL, Target, parse_target
from conformance.verdict import COULD_NOT_TEST, ERROR, FAIL, MISSING

_TARGETS = pytest.StashKey[list[Target]]()
_INTERRUPTS = pytest.StashKey[Interrupts]()


def pytest_addoption(parser: pytest.Parser) -> None:
    g = parser.getgroup("gve-conformance", "GVE protocol conformance suite")
    g.addoption("--gve-target", action="append", default=[],
                help="run the suite's cases against this target (emu:PROFILE, serial:..., "
                     "tcp:..., exec:COMMAND)")
    g.addoption("--gve-profile", default=None,
                help="the profile a serial/tcp/exec target behaves as")
    g.addoption("--gve-cases", action="append", default=[], help="case ID glob (repeatable)")
    g.addoption("--gve-settings", default=None,
                help="Hypothesis settings profile (default: ci in virtual time, the "
                     "emulator's or a co-simulator's; hardware on serial/tcp/exec targets)")
    g.addoption("--gve-max-travel", type=int, default=DEFAULT_MAX_TRAVEL)
    g.addoption("--gve-allow-destructive", action="store_true")
    g.addoption("--gve-strict", action="store_true",
                help="grade a serial/tcp/exec target by the project's decisions too: a "
                "[D] difference FAILs instead of NON-STRICT (the embedded emulator "
                "always is)")
    g.addoption("--gve-hypothesis-db", default=None, metavar="DIR|redis://HOST:PORT/N|none",
                help="where the machines keep failing examples, tried first on the next run "
                     f"(default: {settings_profiles.DEFAULT_DATABASE}/ in the rootdir)")


class CaseFailed(Exception):
    def __init__(self, result: CaseResult) -> None:
        super().__init__(result.verdict)
        self.result = result


class GveItem(pytest.Item):
    def __init__(self, *, case, target, settings_name: str | None, **kw) -> None:
        super().__init__(**kw)
        self.case, self.target, self.settings_name = case, target, settings_name

    def runtest(self) -> None:
        interrupts = self.config.stash[_INTERRUPTS]
        try:
            # a worker starts its targets here, at its first item of each (an exec:
            # target's program: whether it has a rig decides the rig cases)
            self.target.preflight()
        except (ValueError, LookupError) as err:
            pytest.fail(str(err), pytrace=False)
        with interrupts.catching():
            result = run_case(self.case, self.target, self.settings_name)
        if result.interrupted:
            raise KeyboardInterrupt
        if result.verdict in (MISSING, COULD_NOT_TEST):
            pytest.skip(f"{result.verdict}: {'; '.join(result.notes)[:200]}")
        if result.verdict in (FAIL, ERROR):
            raise CaseFailed(result)

    def repr_failure(self, excinfo, style=None) -> str:
        if isinstance(excinfo.value, CaseFailed):
            r = excinfo.value.result
            lines = [f"{r.verdict} {r.id} [{r.profile}]: {r.rule} ({r.source})"]
            lines += [f"  [{c['tag']}] {c['what']}: observed {c['observed']!r}, "
                      f"expected {c['expected']!r}" for c in r.failed_checks]
            return "\n".join(lines + r.notes + ["wire log:", *r.wire_log])
        return super().repr_failure(excinfo, style)

    def reportinfo(self):
        return "gve-conformance", None, f"{self.case.id} [{self.target.profile.name}]"


def _specs(config: pytest.Config) -> list[str]:
    specs = config.getoption("--gve-target")
    if not specs and config.getoption("pyargs") and "conformance" in config.args:
        specs = ["emu:GVE84-100"]      # `pytest --pyargs conformance`: the default target
    return list(dict.fromkeys(specs))       # a target named twice runs once


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
    from conformance.catalogue import select
    globs = config.getoption("--gve-cases")
    if globs and not select(globs):
        raise pytest.UsageError(f"--gve-cases {' '.join(globs)}: no case matches")
    _example_database(config)
    controller, worker = _xdist_controller(config), _on_xdist_worker(config)
    if controller and config.option.dist != "loadgroup":
        config.option.dist = "loadgroup"    # only groups keep a port on one worker
    interrupts = Interrupts()
    targets = []
    try:
        for spec in specs:
            target = parse_target(spec, profile=config.getoption("--gve-profile"),
                                  allow_destructive=config.getoption("--gve-allow-destructive"),
                                  max_travel=config.getoption("--gve-max-travel"),
                                  strict=config.getoption("--gve-strict"))
            if not worker:
                target.preflight()
            if controller:
                target.close()      # it runs nothing; the worker of the port opens it
                continue
            target.begin(interrupts)
            targets.append(target)
    except (ValueError, LookupError) as err:
        for t in targets:
            t.close()
        raise pytest.UsageError(str(err)) from None
    config.stash[_TARGETS] = targets
    config.stash[_INTERRUPTS] = interrupts


def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config,
                                  items: list[pytest.Item]) -> None:
    targets = config.stash.get(_TARGETS, [])
    if not targets:
        return
    from conformance.catalogue import select
    globs = config.getoption("--gve-cases") or None
    for target in targets:
        # on an xdist worker the node ID names the group, as xdist_group marks do
        group = worker_group(target) if _on_xdist_worker(config) else None
        for case in select(globs):
            name = f"{case.id}[{target.info.spec}]"
            items.append(GveItem.from_parent(
                session, name=name, nodeid=f"::{name}@{group}" if group else None, case=case,
                target=target, settings_name=config.getoption("--gve-settings")))


@pytest.hookimpl(tryfirst=True)
def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """The end of the pytest run (also after Ctrl-C): every session puts its unit back;
    what could not be put back is printed and fails the run."""
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


def pytest_unconfigure(config: pytest.Config) -> None:
    """A run that ended before its session finished (a usage error later on): the
    sessions still put their units back."""
    for target in config.stash.get(_TARGETS, []):
        target.session.finish()
        target.close()
