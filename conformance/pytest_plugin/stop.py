"""SIGINT, SIGTERM and SIGHUP alike in a pytest run of the suite (plugin.py), alone or
under pytest-xdist.

A process that runs items (pytest alone, or an xdist worker) counts the three signals
for the whole session as a run does (link/interrupts.py): the item in flight halts its
unit (`H`, then `D`: the next frames on the line) and is COULD-NOT-TEST, no other item
starts, and the end of the session puts every unit back and writes the reports (JUnit
included). An xdist controller runs no item: each signal it gets is passed on at once,
from its handler, as SIGINT to every worker, and no item is handed out after it; the run
ends when the workers have halted, restored and reported, with pytest's exit status for
an interrupted run (2). The workers live in process groups of their own, as a fleet's
members do, so that a terminal's Ctrl-C reaches the controller alone and each worker
counts it once. A third signal ends the controller at once.
"""

from __future__ import annotations

import contextlib
import os
import signal
from contextlib import ExitStack
from typing import Any

import pytest

from conformance.link.signals import StopSignals
from conformance.verdicts.verdict import COULD_NOT_TEST

#: why the session stopped, as pytest says it ("Interrupted: ...")
STOPPED = "interrupted by a signal"
#: what a worker runs first (execnet): leave the controller's process group, say its pid
_OWN_GROUP = ("import os\ntry:\n    os.setpgid(0, 0)\nexcept OSError:\n    pass\n"
              "channel.send(os.getpid())")


class Controller(StopSignals):
    """An xdist controller's signals: counted, each passed on at once to every worker."""

    def __init__(self, config: pytest.Config) -> None:
        super().__init__()
        self.config = config
        self.workers: list[int] = []

    @pytest.hookimpl(optionalhook=True)
    def pytest_xdist_newgateway(self, gateway: Any) -> None:
        spec = gateway.spec
        if getattr(spec, "popen", False) and not getattr(spec, "via", None):
            # a worker on this machine (a remote one's pid is no process here)
            self.workers.append(gateway.remote_exec(_OWN_GROUP).receive(60))

    def signal(self, *_: object) -> None:
        for pid in self.workers:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGINT)
        dsession = self.config.pluginmanager.getplugin("dsession")
        if dsession is not None and not getattr(dsession, "shouldstop", None):
            dsession.shouldstop = STOPPED          # no item handed out after it
        if not self.workers:
            raise KeyboardInterrupt          # nothing runs an item yet: stop here
        super().signal()


def hold(config: pytest.Config, interrupts: StopSignals, *, controller: bool) -> None:
    """Take the stopping signals for the session (see the module's text): ``interrupts``
    counts them in a process that runs items; a controller passes them on."""
    stack = ExitStack()
    if controller:
        relay = Controller(config)
        config.pluginmanager.register(relay, "gve-conformance-stop")
        stack.enter_context(relay.catching())
    else:
        stack.enter_context(interrupts.catching())
    config.add_cleanup(stack.close)


def interrupted(session: pytest.Session) -> None:
    """The item a signal stopped (its unit halted, the case COULD-NOT-TEST, reported as
    any): no item after it; the session ends as pytest ends an interrupted one, its units
    put back."""
    session.shouldstop = STOPPED


def before_item(session: pytest.Session, interrupts: StopSignals) -> None:
    """No item starts after a signal (one counted between items)."""
    if interrupts.stopped:
        interrupted(session)
        pytest.skip(f"{COULD_NOT_TEST}: not run: interrupted by a signal")
