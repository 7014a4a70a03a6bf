"""The motion commands of spec 10: vectors, modal parameters, overrides, positions, the
reference run, HALT/GO/DELETE/KEEP/RESTORE, and the GVE54 motor and GVE114 MPG modes.

Every handler takes the device, the session, the parameter text and the instant, and
parses every field (syntax) before it checks any range or state (spec 3); a refusal
raises :class:`CommandError` and changes nothing (spec 4).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from emulator.motion.interface import EMPTY_SAVE, KeepSave
from emulator.protocol.device import MS, Device
from emulator.protocol.params import CommandError, dec, fields, plain, within
from emulator.protocol.reply import Answer, Deferred, Reply
from emulator.protocol.session import Session
from emulator.protocol.state import INTA, INTCOM, Saved
from gve_fixtures.protocol import SECOND, ErrorCode

#: the reading accel-byte-range: the largest A a unit taking it as one byte accepts
ACCEL_BYTE = 255

Handler = Callable[[Device, Session, str, int], Reply]


# -- vectors ---------------------------------------------------------------------------

def parse_steps(dev: Device, p: str) -> tuple[int, ...]:
    """The relative steps of L or C: one value per axis (the GVE114's A may be left out;
    the reading vector-fewer-components takes one value or more, the rest as 0)."""
    axes = len(dev.profile.axes)
    counts = tuple(range(1, axes + 1)) if dev.readings.active("vector-fewer-components") \
        else (3, 4) if axes == 4 else (axes,)
    values = [dec(x) for x in fields(p, counts)]
    lim = dev.profile.vector_range
    for v in values:
        within(v, -lim, lim)
    return tuple(values + [0] * (axes - len(values)))


def cmd_line(dev: Device, ses: Session, p: str, t: int) -> Reply:
    steps = parse_steps(dev, p)
    dev.refuse_vectors_to_mpg()
    if dev.state.reference_until > t:
        raise CommandError(ErrorCode.QUEUE_FULL, "a reference run is in progress")
    busy = dev.motion.queued(t) or dev.state.dwell_until > t
    if busy and not dev.mutant.active("line-while-busy"):
        if dev.mutant.active("refused-line-queued"):
            dev.push(steps, False, t)
        raise CommandError(ErrorCode.QUEUE_FULL, "L waits until nothing is queued or running")
    dev.push(steps, False, t)
    if not any(steps) and not dev.state.inta and (dev.readings.active("zero-vector-dwells")
                                                  or dev.readings.active("dwell-outlives-halt")):
        # a normal vector with no motion: the T dwell after it holds RUN (the next
        # vector from rest waits it out in the stepper core too)
        dev.state.dwell_until = t + dev.state.modal.T * MS
    return []


def cmd_cont(dev: Device, ses: Session, p: str, t: int) -> Reply:
    steps = parse_steps(dev, p)
    if dev.state.kept_single:
        # the manual's "jen typu L (C ne)": refused as syntax [D], or as no room (a reading)
        code = ErrorCode.QUEUE_FULL if dev.readings.active("keep-c-queue-full") \
            else ErrorCode.SYNTAX
        raise CommandError(code, "after K the queue takes one L only")
    dev.refuse_vectors_to_mpg()
    if dev.readings.active("cont-waits-for-line") and dev.motion.queued(t) \
            and not dev.last_continuous:
        # the L accepted alone is still held: the C waits until it has ended
        raise CommandError(ErrorCode.QUEUE_FULL, "a C waits until the L has ended")
    room = dev.profile.buffer - (1 if dev.mutant.active("queue-one-short") else 0)
    if dev.motion.queued(t) >= room:
        if dev.mutant.active("refused-vector-queued"):
            dev.push(steps, True, t)
        elif dev.mutant.active("refused-vector-overwrites") and dev.last_vector is not None:
            # the last queued vector's end moves to where the refused one would end
            last = dev.last_vector + (0,) * (len(steps) - len(dev.last_vector))
            dev.push(tuple(s - v for s, v in zip(steps, last, strict=True)), True, t)
            dev.last_vector = steps
        raise CommandError(ErrorCode.QUEUE_FULL, "the CONT buffer is full")
    dev.push(steps, True, t)
    return []


# -- modal parameters and overrides ---------------------------------------------------------

def _stores_refused(dev: Device, key: str) -> bool:
    """Whether the unit's mutant stores ``key`` refused for its range (clamped to it)."""
    act = dev.mutant.active
    return ((key == "V" and act("velocity-refused-stored"))
            or (key == "A" and act("accel-refused-stored"))
            or (key == "B" and act("brake-refused-stored"))
            or (key == "T" and act("dwell-refused-stored")))


def modal(key: str, attr: str) -> Handler:
    """T, $, A, V, B: one decimal within the profile's range, kept for later vectors."""
    def handler(dev: Device, ses: Session, p: str, t: int) -> Reply:
        r = dev.profile.ranges[key]
        if key == "A" and dev.readings.active("accel-byte-range"):
            r = replace(r, hi=min(r.hi, ACCEL_BYTE))
        head = plain(p.split(",")[0])
        if key == "V" and "," in p and head is not None and r.lo <= head <= r.hi \
                and dev.mutant.active("velocity-syntax-refused-stored"):
            dev.state.modal.V = head
        value = dec(p)
        if not r.lo <= value <= r.hi and _stores_refused(dev, key):
            setattr(dev.state.modal, attr, min(max(value, r.lo), r.hi))
        setattr(dev.state.modal, attr, within(value, r.lo, r.hi))
        return []
    handler.__name__ = f"cmd_{attr}"
    return handler


def cmd_axis_limits(dev: Device, ses: Session, p: str, t: int) -> Reply:
    axes = len(dev.profile.axes)
    values = [dec(x) for x in fields(p, (3, 4) if axes == 4 else (axes,))]
    r = dev.profile.ranges["VL"]
    limits = [min(within(v, r.lo, r.hi), dev.profile.max_rate) for v in values]
    if dev.mutant.active("axis-limit-x-for-all"):
        limits = limits[:1] * len(limits)
    dev.state.modal.VL[: len(limits)] = limits
    return []


def path_speed(flag: bool) -> Handler:
    def handler(dev: Device, ses: Session, p: str, t: int) -> Reply:
        dev.state.modal.VK = flag
        return []
    handler.__name__ = "cmd_vk" if flag else "cmd_vn"
    return handler


def cmd_xa(dev: Device, ses: Session, p: str, t: int) -> Reply:
    dev.exchange_velocity(t)
    return []


def scale(num: int, den: int) -> Handler:
    def handler(dev: Device, ses: Session, p: str, t: int) -> Reply:
        dev.scale_velocity(num, den, t)
        return []
    handler.__name__ = f"cmd_scale_{num}_{den}"
    return handler


def cmd_xm(dev: Device, ses: Session, p: str, t: int) -> Reply:
    r = dev.profile.ranges["XM"]
    dev.override(within(dec(p), r.lo, r.hi), t)
    return []


# -- positions ----------------------------------------------------------------------------

def positions(count: int) -> Handler:
    def handler(dev: Device, ses: Session, p: str, t: int) -> Reply:
        here = dev.positions(t)
        if count < 3 and dev.mutant.active("short-read-ignores-microstep"):
            here = tuple(int(x / dev.factor()) for x in here)
        return [str(x) for x in here[:count]]
    handler.__name__ = f"cmd_positions_{count}"
    return handler


def cmd_zero(dev: Device, ses: Session, p: str, t: int) -> Reply:
    dev.refuse_while_running(t)
    for axis in range(len(dev.profile.axes)):
        dev.motion.set_position(axis, 0, t)
    return []


def set_axis(axis: int) -> Handler:
    def handler(dev: Device, ses: Session, p: str, t: int) -> Reply:
        value = dec(p)
        r = dev.profile.ranges.get("position")
        if r is not None:
            within(value, r.lo, r.hi)
        dev.refuse_while_running(t)
        dev.motion.set_position(axis, value * dev.factor(), t)
        return []
    handler.__name__ = f"cmd_set_axis_{axis}"
    return handler


def cmd_reference(dev: Device, ses: Session, p: str, t: int) -> Reply:
    """W<axis>[,]travel,speed,back,speed_back: run to the switch, back off until it
    releases, and zero the counter there (spec 10 W [D]). The run is timed at constant
    speeds; the axis moves (``jump``) when it ends."""
    if not p or p[0] not in dev.profile.axes:
        raise CommandError(ErrorCode.SYNTAX, "W needs an axis letter")
    name, axis = p[0], dev.profile.axes.index(p[0])
    travel, speed, back, speed_back = (
        dec(x) for x in fields(p[2:] if p[1:2] == "," else p[1:], (4,)))
    lim, vr = dev.profile.vector_range, dev.profile.ranges["V"]
    if travel == 0:
        raise CommandError(ErrorCode.RANGE, "no travel")
    within(travel, -lim, lim)
    within(speed, vr.lo, vr.hi)
    within(back, 0, lim)
    within(speed_back, vr.lo, vr.hi)
    dev.refuse_vectors_to_mpg()
    dev.refuse_while_running(t)
    f = dev.factor()
    here = dev.motion.physical(t)[axis]
    direction = 1 if travel > 0 else -1
    switch = dev.reference_switch(name, here)
    to_switch = None if switch is None else switch[0] - here
    if to_switch is None or not 0 <= to_switch * direction <= abs(travel) * f:
        # not found within the travel: the whole travel, then 5
        return _reference_run(dev, t, abs(travel) * SECOND // speed,
                              [(axis, travel * f)], ErrorCode.RANGE)
    time_to = abs(to_switch) // f * SECOND // speed
    if switch[1] and back >= 1:               # a virtual switch releases one step back
        return _reference_run(dev, t, time_to + SECOND // speed_back,
                              [(axis, to_switch), (axis, -direction * f)], ErrorCode.OK,
                              zero=axis)
    # still active after n4 steps back: 5, the axis stays there
    return _reference_run(dev, t, time_to + back * SECOND // speed_back,
                          [(axis, to_switch), (axis, -direction * back * f)], ErrorCode.RANGE)


def _reference_run(dev: Device, t: int, duration: int, moves: list[tuple[int, int]],
                   code: ErrorCode, zero: int | None = None) -> Deferred | Answer:
    end = t + duration
    dev.state.reference_until = end

    def finish(at: int) -> tuple[int, list[str]]:
        for axis, delta in moves:
            if delta:
                dev.motion.jump(axis, delta, at)
        if zero is not None:
            dev.motion.set_position(zero, 0, at)
        return code, []
    if dev.mutant.active("reference-answers-early"):
        dev.later(end, finish)                 # the run goes on, answered already
        return Answer(code, [])
    return Deferred(end, finish)


# -- HALT, GO, DELETE, KEEP, RESTORE (spec 10.4, 10.5) -------------------------------------

def cmd_halt(dev: Device, ses: Session, p: str, t: int) -> Reply:
    rest = dev.motion.halt(t)
    if not dev.readings.active("dwell-outlives-halt"):
        dev.state.dwell_until = min(dev.state.dwell_until, t)     # a dwell ends at once
    dev.state.status[6] |= INTA | INTCOM
    if rest > t and not dev.mutant.active("halt-answers-early"):
        return Deferred(dev.seen_at_rest(rest), lambda at: (ErrorCode.OK, []))
    return []


def cmd_go(dev: Device, ses: Session, p: str, t: int) -> Reply:
    s = dev.state
    if not s.inta:
        if dev.mutant.active("go-without-inta"):
            return []
        raise CommandError(ErrorCode.NOTHING_TO_GO, "G with INTA = 0")
    if dev.readings.active("go-nothing-queued") and not dev.motion.queued(t):
        raise CommandError(ErrorCode.NOTHING_TO_GO, "G with nothing queued")
    held = dev.motion.queued(t)
    s.status[6] &= ~(INTA | INTCOM)
    if held and dev.mutant.active("go-keeps-intcom"):
        s.status[6] |= INTCOM
    s.status[4] = s.status[5] = 0
    dev.motion.resume(t)
    if dev.mutant.active("go-loses-step") and dev.motion.queued(t):
        dev.motion.set_position(0, dev.motion.position(t)[0] + 1, t)
    dev.check_inputs(t)
    if not held and dev.readings.active("go-clears-then-nothing"):
        raise CommandError(ErrorCode.NOTHING_TO_GO, "G with nothing queued, flags cleared")
    return []


def cmd_delete(dev: Device, ses: Session, p: str, t: int) -> Reply:
    if dev.mutant.active("delete-refused"):
        raise CommandError(ErrorCode.BUSY, "D refused at rest")
    if not dev.mutant.active("delete-while-moving"):
        dev.refuse_while_moving(t)
    if dev.mutant.active("delete-ignored"):
        return []
    dev.motion.clear(t)
    s = dev.state
    s.status[4] = s.status[5] = s.status[6] = 0
    dev.after_clearing(t)
    return []


def cmd_keep(dev: Device, ses: Session, p: str, t: int) -> Reply:
    dev.refuse_while_moving(t)
    s = dev.state
    if s.saved is not None and dev.profile.keep == "single-L" \
            and dev.readings.active("second-keep-refused"):
        raise CommandError(ErrorCode.SYNTAX, "K while an earlier K's save is held")
    st6 = 0 if dev.mutant.active("keep-forgets-st6") else s.status[6]
    s.saved = Saved(dev.motion.keep(t), s.status[4], s.status[5], st6)
    s.status[4] = s.status[5] = s.status[6] = 0
    s.kept_single = dev.profile.keep == "single-L"
    dev.after_clearing(t)
    return []


def cmd_restore(dev: Device, ses: Session, p: str, t: int) -> Reply:
    dev.refuse_restore(t)
    s = dev.state
    if s.saved is None and dev.readings.active("restore-nothing-kept-refused"):
        raise CommandError(ErrorCode.SYNTAX, "nothing kept to restore")
    if s.saved is None and dev.readings.active("restore-nothing-kept-range"):
        raise CommandError(ErrorCode.RANGE, "nothing kept to restore")
    saved = s.saved or Saved(EMPTY_SAVE, 0, 0, 0)
    if not dev.mutant.active("restore-keeps-save"):
        s.saved = None                         # a stack of one level: R pops it
    motion = saved.motion
    if dev.mutant.active("restore-drops-partial") and motion.entries \
            and motion.entries[0][1] > 0:
        motion = KeepSave(motion.entries[1:], motion.halted)
    dev.motion.restore(motion, t)
    s.status[4], s.status[5], s.status[6] = saved.st4, saved.st5, saved.st6
    s.kept_single = False
    dev.after_clearing(t)
    return []


# -- GVE54 motor mode, GVE114 MPG ---------------------------------------------------------

def cmd_motor(dev: Device, ses: Session, p: str, t: int) -> Reply:
    ms = dev.profile.microstep
    assert ms is not None
    if p not in ms.currents and p not in ms.factors:
        if p[:1] in ms.factors and dev.mutant.active("microstep-refused-stored"):
            dev.state.microstep = p[:1]
        raise CommandError(ErrorCode.SYNTAX, f"unknown motor mode {p!r}")
    if dev.readings.active("motor-mode-refused-while-run"):
        dev.refuse_while_running(t)
    dev.refuse_while_moving(t)
    if p in ms.currents:
        dev.state.current = p
        if dev.mutant.active("current-resets-mode"):
            dev.state.microstep = ms.reset_mode
    else:
        dev.state.microstep = p
    return []


def cmd_mpg(dev: Device, ses: Session, p: str, t: int) -> Reply:
    if p not in ("+", "&", "-"):
        raise CommandError(ErrorCode.SYNTAX, "Y takes +, & or -")
    if p != "-" and not dev.mpg_parameters_in_range():
        raise CommandError(ErrorCode.RANGE, "an MPG parameter is out of range")
    if p != "-" and dev.readings.active("mpg-refused-while-moving") \
            and dev.motion.flags(t).moving:
        raise CommandError(ErrorCode.BUSY, "the hand wheel is not turned on while vectors run")
    dev.state.mpg = p
    return ["Y" + p]
