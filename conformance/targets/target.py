"""A target: the profile expected of it and how to reach it. Each scheme's module
(emu.py, port.py) makes one; the run-wide :class:`~conformance.targets.session.Session`
opens its links and keeps what must hold for the whole run (docs/suite.md)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from dataclasses import dataclass

import serial

from conformance.link.link import Link
from conformance.link.signals import StopSignals
from conformance.targets.info import TargetInfo
from conformance.targets.session import Session, open_session
from gve_fixtures.profile import Profile

DEFAULT_MAX_TRAVEL = 2000


class TargetError(ValueError):
    """A target that cannot be used as given (one line for the user, before any frame)."""


def known_settings(spec: str, given: Iterable[str], valid: Iterable[str]) -> None:
    """Refuse a setting the target's scheme does not know (a misspelling would otherwise
    be ignored: a run at the wrong address, a mutant not planted): TargetError naming the
    first unknown key, the nearest valid one and every valid one."""
    valid = sorted(set(valid))
    unknown = [key for key in given if key not in valid]
    if not unknown:
        return
    key = unknown[0]
    nearest = difflib.get_close_matches(key, valid, n=1)
    raise TargetError(f"{spec}: unknown setting {key!r}"
                      + (f" (did you mean {nearest[0]!r}?)" if nearest else "")
                      + f"; valid: {', '.join(valid) or 'none'}")


@dataclass
class Target:
    info: TargetInfo
    profile: Profile
    address: int
    baud: int
    url: str
    mutant: str | None = None
    readings: str = ""              # emu: the emulator's other readings, "A,B"

    def __post_init__(self) -> None:
        self._session: Session | None = None

    @property
    def session(self) -> Session:
        """The run's session on this target (a new one until :meth:`begin` names one)."""
        if self._session is None:
            self._session = open_session(self)
        return self._session

    def begin(self, interrupts: StopSignals | None = None) -> Session:
        """The session for a run, Ctrl-C shared through ``interrupts``: the one prepared
        before the run (an operator's prompt set, the identity read), else a new one."""
        if self._session is None or self._session.finished:
            self._session = open_session(self, interrupts)
        elif interrupts is not None:
            self._session.share(interrupts)
        return self._session

    def open_link(self, address: int | None = None) -> Link:
        """A link in the known state, through the session."""
        return self.session.open_link(address)

    def preflight(self) -> None:
        """Raise TargetError if the target cannot be used (checked before anything is
        sent: the port opens, the options make sense)."""

    def connect(self, address: int | None) -> tuple[serial.SerialBase, int, bool, object]:
        """(port, baud, virtual time, rig or None) for a new link."""
        raise NotImplementedError

    def close(self) -> None:
        """Release what the target holds (a port)."""
