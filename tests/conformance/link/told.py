"""Telling a guard's followers one exchange as a link does, for tests that drive a guard
without a link."""

from __future__ import annotations

from conformance.link.liveness import Booked, Observed, tell_followers
from conformance.link.safety import Guard
from conformance.protocol.view import observe
from conformance.protocol.wire import Response


def told(g: Guard, body: str | None, r: Response | None, at: int | None = None, *,
         address: int | None = None) -> None:
    """``body`` (None: no frame, only the answer counted) booked with the view it leaves
    and its answer ``r`` (None: none read) heard, ``at`` the instant it went out."""
    bookkeeping, liveness = g.followers()
    frames: tuple[Booked, ...] = ()
    view = bookkeeping.view
    if body is not None:
        where = g.address if address is None else address
        view = observe(view, body, r, where)
        frames = (Booked(body, r, where, view),)
    tell_followers(Observed(frames, view, r, at, heard=True, own=bool(g.own_frames()),
                  urgent=bool(g.emergency())), bookkeeping, liveness)
