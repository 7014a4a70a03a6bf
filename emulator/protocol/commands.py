"""The commands of spec 10: one handler each, and the table that names them.

A handler takes the unit, the parameter text after the command's name and the instant,
and returns the response's values (a list of strings), or a :class:`Deferred` answer
(H and W answer when the motion has stopped). It raises :class:`CommandError` to refuse;
a refused command changes nothing (spec 4).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from emulator.motion.interface import SECOND
from emulator.protocol.params import RANGE, SYNTAX, CommandError, dec, decfloat, fields, hexbyte
from emulator.protocol.state import INTA, INTCOM, QUEUE_FULL, RUN, STOP

if TYPE_CHECKING:
    from emulator.protocol.unit import Unit

FULL = 1
WATCHDOG = 2
UNKNOWN = 3
NOTHING_TO_GO = 6
BUSY = 7


@dataclass
class Deferred:
    """An answer due at ``instant`` (code and values computed then by ``finish``)."""

    instant: int
    finish: Callable[[int], tuple[int, list[str]]]


Handler = Callable[["Unit", str, int], "list[str] | Deferred"]


def no_params(p: str) -> None:
    if p:
        raise CommandError(SYNTAX, "this command takes no parameters")


def _not_moving(u: Unit, t: int) -> None:
    if u.moving(t):
        raise CommandError(BUSY, "not possible while a vector runs")


def _not_running(u: Unit, t: int) -> None:
    if u.st6(t) & RUN:
        raise CommandError(BUSY, "not possible while RUN = 1")


# -- identification ------------------------------------------------------------------

def cmd_version(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    return [u.profile.version]


def cmd_processor(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    return [u.profile.processor_id]


# -- vectors ---------------------------------------------------------------------------

def _steps(u: Unit, p: str) -> tuple[int, ...]:
    axes = len(u.profile.axes)
    counts = (3, 4) if axes == 4 else (axes,)
    lim = u.profile.vector_range
    values = [dec(x) for x in fields(p, counts)]
    for v in values:
        if not -lim <= v <= lim:
            raise CommandError(RANGE, f"{v} outside ±{lim}")
    return tuple(values + [0] * (axes - len(values)))


def _vector_rules(u: Unit, t: int) -> None:
    if u.mpg_active():
        raise CommandError(BUSY, "the MPG holds the axes")


def cmd_line(u: Unit, p: str, t: int) -> list[str]:
    steps = _steps(u, p)
    _vector_rules(u, t)
    if u.state.reference_until > t:
        raise CommandError(FULL, "a reference run is in progress")
    if u.motion.queued(t) and not u.mutant.active("line-while-busy"):
        raise CommandError(FULL, "L waits until nothing is queued or running")
    u.push(steps, False, t)
    return []


def cmd_cont(u: Unit, p: str, t: int) -> list[str]:
    steps = _steps(u, p)
    if u.state.kept_single:
        raise CommandError(SYNTAX, "after K the queue takes one L only")
    _vector_rules(u, t)
    room = u.profile.buffer - (1 if u.mutant.active("queue-one-short") else 0)
    if u.motion.queued(t) >= room:
        raise CommandError(FULL, "the CONT buffer is full")
    u.push(steps, True, t)
    return []


# -- modal parameters ------------------------------------------------------------------

def _modal(key: str, attr: str) -> Handler:
    def handler(u: Unit, p: str, t: int) -> list[str]:
        r = u.profile.ranges[key]
        setattr(u.state.modal, attr, dec(p, r.lo, r.hi))
        return []
    handler.__name__ = f"cmd_{attr}"
    return handler


def cmd_velocity(u: Unit, p: str, t: int) -> list[str]:
    r = u.profile.ranges["V"]
    u.state.modal.V = dec(p, r.lo, r.hi)
    return []


def cmd_spindle(u: Unit, p: str, t: int) -> list[str]:
    sp = u.profile.spindle
    assert sp is not None
    value = dec(p, sp.range.lo, sp.range.hi)
    u.state.spindle = value
    u.state.outputs = u.state.outputs & 0xFE if value else u.state.outputs | 0x01
    return []


def cmd_axis_limits(u: Unit, p: str, t: int) -> list[str]:
    axes = len(u.profile.axes)
    counts = (3, 4) if axes == 4 else (axes,)
    r = u.profile.ranges["VL"]
    values = [min(dec(x, r.lo, r.hi), u.profile.max_rate) for x in fields(p, counts)]
    u.state.modal.VL[: len(values)] = values
    return []


def _set_vk(flag: bool) -> Handler:
    def handler(u: Unit, p: str, t: int) -> list[str]:
        no_params(p)
        u.state.modal.VK = flag
        return []
    return handler


def _scales_accel(u: Unit) -> bool:
    return u.profile.microstep is not None       # GVE54 also exchanges acceleration


def cmd_xa(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    f = u.factor()
    m = u.state.modal
    accel = m.A * 1000 * f if _scales_accel(u) else None
    u.motion.set_velocity(min(m.V, u.profile.max_rate) * f, t, accel)
    return []


def _scale(num: int, den: int) -> Handler:
    def handler(u: Unit, p: str, t: int) -> list[str]:
        no_params(p)
        u.motion.scale_velocity(num, den, t, accel=_scales_accel(u))
        return []
    return handler


def cmd_xm(u: Unit, p: str, t: int) -> list[str]:
    r = u.profile.ranges["XM"]
    u.state.xm = dec(p, r.lo, r.hi)
    u.motion.set_multiplier(u.state.xm, t)
    return []


# -- positions -------------------------------------------------------------------------

def _positions(count: int) -> Handler:
    def handler(u: Unit, p: str, t: int) -> list[str]:
        no_params(p)
        return [str(x) for x in u.positions(t)[:count]]
    return handler


def cmd_zero(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    _not_running(u, t)
    for i in range(len(u.profile.axes)):
        u.motion.set_position(i, 0, t)
    return []


def _set_axis(axis: int) -> Handler:
    def handler(u: Unit, p: str, t: int) -> list[str]:
        r = u.profile.ranges.get("position")
        value = dec(p, r.lo if r else None, r.hi if r else None)
        _not_running(u, t)
        u.motion.set_position(axis, value * u.factor(), t)
        return []
    return handler


def cmd_reference(u: Unit, p: str, t: int) -> list[str] | Deferred:
    """W<axis>[,]travel,speed,back,speed_back: run to the switch, back off until it
    releases, and zero the counter there (spec 10 W [D]). The run is timed at constant
    speeds; the axis moves (``jump``) when it ends."""
    if not p or p[0] not in u.profile.axes:
        raise CommandError(SYNTAX, "W needs an axis letter")
    axis = u.profile.axes.index(p[0])
    rest = p[2:] if p[1:2] == "," else p[1:]
    lim = u.profile.vector_range
    travel, speed, back, speed_back = (dec(x) for x in fields(rest, (4,)))
    vr = u.profile.ranges["V"]
    if not (0 < abs(travel) <= lim and 0 <= back <= lim):
        raise CommandError(RANGE, "travel out of range")
    for s in (speed, speed_back):
        if not vr.lo <= s <= vr.hi:
            raise CommandError(RANGE, "speed out of range")
    _vector_rules(u, t)
    _not_running(u, t)
    f = u.factor()
    here = u.motion.physical(t)[axis]
    direction = 1 if travel > 0 else -1
    switch = u.reference_switch(p[0], here)
    to_switch = None if switch is None else switch[0] - here
    if to_switch is None or not 0 <= to_switch * direction <= abs(travel) * f:
        # not found within the travel: the whole travel, then 5
        return _reference_run(u, t, abs(travel) * SECOND // speed,
                              [(axis, travel * f)], RANGE)
    releases = switch[1]
    time_to = abs(to_switch) // f * SECOND // speed
    if releases and back >= 1:
        # a virtual switch releases one step back; the counter is 0 there
        return _reference_run(u, t, time_to + SECOND // speed_back,
                              [(axis, to_switch), (axis, -direction * f)], 0, zero=axis)
    # the switch is still active after n4 steps back: 5, the axis stays there
    return _reference_run(u, t, time_to + back * SECOND // speed_back,
                          [(axis, to_switch), (axis, -direction * back * f)], RANGE)


def _reference_run(u: Unit, t: int, duration: int, moves: list[tuple[int, int]],
                   code: int, zero: int | None = None) -> Deferred:
    end = t + duration
    u.state.reference_until = end

    def finish(at: int) -> tuple[int, list[str]]:
        for axis, delta in moves:
            if delta:
                u.motion.jump(axis, delta, at)
        if zero is not None:
            u.motion.set_position(zero, 0, at)
        return code, []
    return Deferred(end, finish)


# -- HALT, GO, DELETE, KEEP, RESTORE ---------------------------------------------------

def cmd_halt(u: Unit, p: str, t: int) -> list[str] | Deferred:
    no_params(p)
    rest = u.motion.halt(t)
    u.state.status[6] |= INTA | INTCOM
    if rest > t and not u.mutant.active("halt-answers-early"):
        return Deferred(rest, lambda at: (0, []))
    return []


def cmd_go(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    s = u.state
    if not s.inta:
        if u.mutant.active("go-without-inta"):
            return []
        raise CommandError(NOTHING_TO_GO, "G with INTA = 0")
    s.status[6] &= ~(INTA | INTCOM)
    s.status[4] = s.status[5] = 0
    u.motion.resume(t)
    if u.mutant.active("go-loses-step") and u.motion.queued(t):
        here = u.motion.position(t)
        u.motion.set_position(0, here[0] + 1, t)
    u.check_inputs(t)
    return []


def cmd_delete(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    if not u.mutant.active("delete-while-moving"):
        _not_moving(u, t)
    u.motion.clear(t)
    s = u.state
    s.status[4] = s.status[5] = s.status[6] = 0
    return []


def cmd_keep(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    _not_moving(u, t)
    s = u.state
    st6 = 0 if u.mutant.active("keep-forgets-st6") else s.status[6]
    s.saved = (u.motion.keep(t), s.status[4], s.status[5], st6)
    s.status[4] = s.status[5] = s.status[6] = 0
    s.kept_single = u.profile.keep == "single-L"
    return []


def cmd_restore(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    _not_moving(u, t)
    s = u.state
    if s.saved is None:
        motion_save, st4, st5, st6 = EMPTY_SAVE, 0, 0, 0
    else:
        motion_save, st4, st5, st6 = s.saved
    if u.mutant.active("restore-drops-partial"):
        motion_save = _drop_partial(motion_save)
    u.motion.restore(motion_save, t)
    s.status[4], s.status[5], s.status[6] = st4, st5, st6
    s.kept_single = False
    return []


# a KEEP save with nothing in it (the save structure both stepper cores use)
EMPTY_SAVE: object = ((), False)


def _drop_partial(save: object) -> object:
    entries, halted = save  # type: ignore[misc]
    if entries and entries[0][1] > 0:
        entries = entries[1:]
    return (entries, halted)


# -- EEPROM ----------------------------------------------------------------------------

def cmd_eeprom_read(u: Unit, p: str, t: int) -> list[str]:
    address = hexbyte(p)
    return ["%02X" % u.eeprom.read(address)[0]]


def _eeprom_write(u: Unit, address: int, data: bytes, t: int) -> None:
    _not_moving(u, t)
    if not u.mutant.active("eeprom-write-lost"):
        u.eeprom.write(address, data)


def cmd_eeprom_write(u: Unit, p: str, t: int) -> list[str]:
    a, x = fields(p, (2,))
    address, value = hexbyte(a), hexbyte(x)
    _eeprom_write(u, address, bytes([value]), t)
    return []


def _word_address(text: str) -> int:
    address = hexbyte(text)
    if address + 3 > 0xFF:
        raise CommandError(RANGE, "the word runs past FF")
    return address


def cmd_float_read(u: Unit, p: str, t: int) -> list[str]:
    (value,) = struct.unpack("<f", u.eeprom.read(_word_address(p), 4))
    return ["%.7g" % value]


def cmd_float_write(u: Unit, p: str, t: int) -> list[str]:
    a, x = fields(p, (2,))
    address, value = _word_address(a), decfloat(x)
    try:
        data = struct.pack("<f", value)
    except OverflowError as err:
        raise CommandError(RANGE, "not a float32") from err
    if not math.isfinite(struct.unpack("<f", data)[0]):
        raise CommandError(RANGE, "not a finite float32")
    _eeprom_write(u, address, data, t)
    return []


def cmd_uint_read(u: Unit, p: str, t: int) -> list[str]:
    (value,) = struct.unpack("<I", u.eeprom.read(_word_address(p), 4))
    return [str(value)]


def cmd_uint_write(u: Unit, p: str, t: int) -> list[str]:
    a, x = fields(p, (2,))
    address, value = _word_address(a), dec(x, 0, 0xFFFFFFFF)
    _eeprom_write(u, address, struct.pack("<I", value), t)
    return []


# -- ports and status words ----------------------------------------------------------

def cmd_output(u: Unit, p: str, t: int) -> list[str]:
    if not p.startswith(","):
        raise CommandError(SYNTAX, "O0,x")
    u.state.outputs = hexbyte(p[1:])
    return []


def _input(port: int) -> Handler:
    def handler(u: Unit, p: str, t: int) -> list[str]:
        no_params(p)
        return ["%02X" % u.state.inputs[port]]
    return handler


def cmd_status_read(u: Unit, p: str, t: int) -> list[str]:
    n = dec(p, 0, 6)
    return ["%02X" % (u.st6(t) if n == 6 else u.state.status[n])]


def cmd_status_write(u: Unit, p: str, t: int) -> list[str]:
    a, x = fields(p, (2,))
    n = dec(a, 0, 6)
    value = hexbyte(x)
    if u.mutant.active("status-word-masked") and n < 6:
        value &= u.profile.low_mask if n % 2 == 0 else u.profile.high_mask
    if n == 6:
        value &= ~(RUN | STOP)
    u.state.status[n] = value
    u.check_inputs(t)
    return []


def cmd_flags(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    full = u.motion.queued(t) >= u.profile.buffer
    return ["%02X" % (u.st6(t) | (QUEUE_FULL if full else 0))]


# -- GVE54 motor mode, GVE114 MPG ---------------------------------------------------------

def cmd_motor(u: Unit, p: str, t: int) -> list[str]:
    ms = u.profile.microstep
    assert ms is not None
    if p in ms.currents:
        _not_moving(u, t)
        u.state.current = p
    elif p in ms.factors:
        _not_moving(u, t)
        u.state.microstep = p
    else:
        raise CommandError(SYNTAX, f"unknown motor mode {p!r}")
    return []


def cmd_mpg(u: Unit, p: str, t: int) -> list[str]:
    if p not in ("+", "&", "-"):
        raise CommandError(SYNTAX, "Y takes +, & or -")
    u.state.mpg = p
    return ["Y" + p]


def cmd_index(u: Unit, p: str, t: int) -> list[str]:
    no_params(p)
    return [str(u.state.index)]


# name -> handler. Names are matched longest first; a profile offers only its own set.
COMMANDS: dict[str, Handler] = {
    "?": cmd_version, "Q": cmd_processor,
    "L": cmd_line, "C": cmd_cont,
    "T": _modal("T", "T"), "$": _modal("$", "dollar"), "A": _modal("A", "A"),
    "V": cmd_velocity, "B": _modal("B", "B"), "VL": cmd_axis_limits,
    "VK": _set_vk(True), "VN": _set_vk(False),
    "XA": cmd_xa, "XU": _scale(17, 16), "XD": _scale(15, 16), "XM": cmd_xm,
    "P": _positions(2), "PF": _positions(3),
    "N": cmd_zero, "NX": _set_axis(0), "NY": _set_axis(1), "NZ": _set_axis(2),
    "NA": _set_axis(3), "W": cmd_reference,
    "K": cmd_keep, "R": cmd_restore, "H": cmd_halt, "D": cmd_delete, "G": cmd_go,
    "ER": cmd_eeprom_read, "EW": cmd_eeprom_write,
    "EFR": cmd_float_read, "EFW": cmd_float_write,
    "EUR": cmd_uint_read, "EUW": cmd_uint_write,
    "O0": cmd_output, "I0": _input(0), "I1": _input(1), "I2": _input(2),
    "SR": cmd_status_read, "SW": cmd_status_write, "F": cmd_flags,
    "M": cmd_motor, "Y": cmd_mpg, "@": cmd_index,
}
# Answered by the unit itself (they act on framing, history, packets or the restart).
SPECIAL = (">", "J", "%", "*S", "*E")
NAMES = frozenset([*COMMANDS, *SPECIAL])


def split(body: str) -> tuple[str | None, str]:
    """The command name at the start of ``body`` (the longest that matches) and its
    parameter text."""
    for n in (3, 2, 1):
        if body[:n] in NAMES and len(body) >= n:
            return body[:n], body[n:]
    return None, body
