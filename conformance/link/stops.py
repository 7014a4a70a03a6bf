"""What stops a case on a real unit before its frames go out: a frame the suite refused
(:class:`SafetyStop`), a restart of the unit's seen (:class:`UnitRestarted`)."""

from __future__ import annotations


class SafetyStop(BaseException):
    """A frame the suite refused to send to a real unit: the case ends COULD-NOT-TEST.

    A BaseException, so that no case and no Hypothesis machine takes it for a failure
    and tries the frame again."""


class UnitRestarted(SafetyStop):
    """The unit restarted by itself (or its counters no longer tell where its axes are):
    the case in which it was seen ends COULD-NOT-TEST with what was seen."""
