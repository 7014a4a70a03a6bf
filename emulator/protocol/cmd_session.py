"""The commands that act on the session (spec 6, 7, 8) and the restart `J`: the index
`@`, the repeat `>`, the checksum mode `%`, packets `*S` / `*E` and their members."""

from __future__ import annotations

from emulator.protocol.cmd_motion import parse_steps
from emulator.protocol.device import Device
from emulator.protocol.params import CommandError, dec, plain, within
from emulator.protocol.reply import Answer, Plain, Reply
from emulator.protocol.session import Member, Session
from gve_fixtures.protocol import ErrorCode


def cmd_index(dev: Device, ses: Session, p: str, t: int) -> Reply:
    if dev.readings.active("index-hex"):
        return ["%02X" % ses.index]
    return [str(ses.index)]


def cmd_repeat(dev: Device, ses: Session, p: str, t: int) -> Reply:
    """The last answered frame as received, then its answer; a plain 0 with no history."""
    if ses.history is None:
        return []
    last, answer = ses.history
    return Plain(last + b"\r" + answer)


def cmd_restart(dev: Device, ses: Session, p: str, t: int) -> Reply:
    """J: answers a plain 0 (formatted as after the reset [D]) and restarts."""
    dev.reset(t)
    ses.reset(dev.profile.reset.checksums)
    return Plain(b"0\r")


def cmd_checksum_mode(dev: Device, ses: Session, p: str, t: int) -> Reply:
    if p not in ("+", "-"):
        raise CommandError(ErrorCode.SYNTAX, "% takes + or -")
    ses.checksums = p == "+"
    return []


def cmd_packet_start(dev: Device, ses: Session, p: str, t: int) -> Reply:
    ses.packet = []                            # no answer; a second *S restarts it
    return None


def member(dev: Device, name: str | None, params: str) -> Member:
    """A frame inside an open packet (spec 7): only C and B may be members."""
    if name is None:
        return Member(None, None, ErrorCode.UNKNOWN)
    if name not in ("C", "B"):
        r = dev.profile.ranges["V"]
        value = plain(params)
        if name == "V" and dev.mutant.active("failed-packet-applies-v") \
                and value is not None and r.lo <= value <= r.hi:
            dev.state.modal.V = value
        # the reading packet-failed-count-zero: a command a packet cannot hold is unknown there
        unknown = dev.readings.active("packet-failed-count-zero")
        return Member(name, None, ErrorCode.UNKNOWN if unknown else ErrorCode.SYNTAX)
    try:
        if name == "C":
            return Member(name, parse_steps(dev, params), ErrorCode.OK)
        r = dev.profile.ranges["B"]
        return Member(name, within(dec(params), r.lo, r.hi), ErrorCode.OK)
    except CommandError as err:
        return Member(name, None, err.code)


def commit_on_arrival(dev: Device, m: Member, t: int) -> Member:
    """The reading packet-committed-on-arrival: a valid member takes effect as it
    arrives (B sets the modal B, C is queued); a C the queue cannot take, or takes only
    alone (after K) or not at all (the MPG), fails with the code `*E` would give."""
    if m.code:
        return m
    if m.name == "B":
        dev.state.modal.B = m.value  # type: ignore[assignment]
        return m
    code = ErrorCode.SYNTAX if dev.state.kept_single else ErrorCode.BUSY if dev.mpg_active() \
        else ErrorCode.QUEUE_FULL if dev.motion.queued(t) >= dev.profile.buffer else None
    if code is not None:
        return Member(m.name, None, code)
    dev.push(m.value, True, t)  # type: ignore[arg-type]
    return m


def cmd_packet_end(dev: Device, ses: Session, p: str, t: int) -> Reply:
    """*E n: commit every member only if all k are valid, k = n and the queue has room
    for the C members; the answer is always ``code,k`` (spec 7)."""
    members, ses.packet = ses.packet, None
    if members is None:
        return Answer(ErrorCode.SYNTAX, ["0"])
    k = len(members)
    try:
        n = dec(p)
    except CommandError as err:
        return Answer(err.code, [str(k)])
    mismatch = k != n and not dev.mutant.active("packet-count-ignored")
    failing = next((m.code for m in members if m.code), ErrorCode.OK)
    reads = dev.readings.active
    counted = _failed_count(dev, members)
    if counted is not None:                   # a failing member's code before the count
        code = failing or (ErrorCode.COUNT_MISMATCH if mismatch else ErrorCode.OK)
    else:
        code = ErrorCode.COUNT_MISMATCH if mismatch else failing
    if reads("packet-committed-on-arrival"):
        return Answer(code, [str(k)])            # each member took effect as it arrived
    vectors = sum(1 for m in members if m.name == "C" and not m.code)
    if not code and vectors:
        if dev.state.kept_single:
            code = ErrorCode.SYNTAX
        elif dev.mpg_active():
            code = ErrorCode.BUSY
        elif dev.motion.queued(t) + vectors > dev.profile.buffer:
            code = ErrorCode.QUEUE_FULL
    if code and dev.mutant.active("failed-packet-keeps-b"):
        for m in members:
            if m.name == "B" and not m.code:
                dev.state.modal.B = m.value  # type: ignore[assignment]
    if code == ErrorCode.OK or dev.mutant.active("packet-partial-commit"):
        room = dev.profile.buffer - dev.motion.queued(t)
        for m in members:
            if m.code:
                continue
            if m.name == "B":
                dev.state.modal.B = m.value  # type: ignore[assignment]
            elif room > 0:
                dev.push(m.value, True, t)  # type: ignore[arg-type]
                room -= 1
    return Answer(code, [str(k if not code or counted is None else counted)])


def _failed_count(dev: Device, members: list[Member]) -> int | None:
    """The count a failed packet's `*E` answers under the readings that count otherwise
    than every member received (spec 7 [D]): the valid members, or none; None: k."""
    if dev.readings.active("packet-failed-count-zero"):
        return 0
    if dev.readings.active("packet-failed-count-valid"):
        return sum(1 for m in members if not m.code)
    return None
