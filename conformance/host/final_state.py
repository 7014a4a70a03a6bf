"""After the host is gone, the relay asks each unit itself where its motion ended, over the
same wire (spec 8 `@`, 10.3 `SR6`, 10 `PF`): the last part of the oracle. `@` comes first
because it closes a packet the host may have left open (spec 7)."""

from __future__ import annotations

import time
from dataclasses import dataclass

import serial

from conformance.host.recording import Recording, show
from conformance.host.unitview import UnitView
from conformance.link.framing import CR, Response, frame, parse_response
from conformance.link.virtual import line_of
from gve_fixtures.protocol import St6

#: how long the motion the host left queued may still run
MOTION_S = 10.0
POLL_S = 0.02
ANSWER_S = 0.25


@dataclass
class Final:
    """Where a unit's motion ended: its counters, ST6, and whether it stalled (vectors
    still held, interrupted and never resumed)."""

    position: tuple[int, ...] | None
    st6: int | None
    stalled: bool = False
    note: str = ""


def ask(unit: serial.SerialBase, rec: Recording, address: int, body: str,
        summed: bool) -> Response | None:
    data = frame(body, address, summed)
    unit.timeout = ANSWER_S
    unit.write(data)
    raw = unit.read_until(CR)
    rec.action(time.monotonic_ns(), f"probe {show(data)}", f"answer {show(raw)}")
    r = parse_response(raw, summed=summed)
    return r if r.well_formed else None


def final_state(unit: serial.SerialBase, view: UnitView, rec: Recording) -> Final:
    """Ask the unit; the host is gone, so the line's time may now run ahead of the wall
    clock: waiting for a restart or for the motion takes no real time."""
    line = line_of(unit)
    wait = (view.deaf_until - time.monotonic_ns()) / 1e9
    if wait > 0:
        line.advance(wait + 0.05)     # the unit is restarting: it would hear nothing
    unit.read(unit.in_waiting)        # an answer nobody took any more
    summed = view.checksums
    r = ask(unit, rec, view.address, "@", summed)
    if r is None:                     # the host left the mode other than we think
        summed = not summed
        r = ask(unit, rec, view.address, "@", summed)
    if r is None:
        return Final(None, None, note="the unit did not answer `@` after the host left")
    deadline = line.now + round(MOTION_S * 1e9)
    st6 = None
    while line.now < deadline:
        r = ask(unit, rec, view.address, "SR6", summed)
        st6 = int(r.values[0], 16) if r is not None and r.values else None
        if st6 is not None and (not st6 & St6.RUN or st6 & St6.INTA):
            break
        line.advance(POLL_S)
    r = ask(unit, rec, view.address, "PF", summed)
    position = tuple(int(v) for v in r.values) if r is not None and r.values else None
    stalled = st6 is not None and bool(st6 & St6.RUN) and bool(st6 & St6.INTA)
    note = "" if st6 is not None and not st6 & St6.RUN else (
        "vectors held, interrupted and never resumed" if stalled else
        f"still moving {MOTION_S:g} s after the host left")
    return Final(position, st6, stalled, note)
