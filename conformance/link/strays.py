"""Bytes no frame asked for, as the link judges them: a watchdog's answer to what the
suite left unfinished on purpose (a lone `!`, a frame without its CR, an open packet),
judged by the watchdog's rule; else a second answer to the last frame, or one after its
timeout, each a :class:`Stray` naming the rule it breaks."""

from __future__ import annotations

from typing import NamedTuple

from conformance.protocol.wire import CR, parse_response, readable
from gve_fixtures.protocol import ErrorCode

# what the last frame left on the line
ANSWERED, TIMED_OUT, UNASKED = "answered", "timed out", "unasked"

# what the suite's bytes left unfinished for a watchdog to end
LONE_BANG, OPEN_FRAME, OPEN_PACKET = "a lone '!'", "a frame without its CR", "an open packet"
#: the rule an answer of each one's watchdog is judged by (our reading: a lone `!` is
#: dropped without an answer, a frame answered 2, a packet never closed by time)
WATCHDOG_RULES = {LONE_BANG: "3.frame.watchdog-lone-bang", OPEN_FRAME: "3.frame.watchdog",
                  OPEN_PACKET: "7.packet.open-until-end"}
#: the rule a second answer breaks (the unit answers every complete frame once), and one
#: after its frame's timeout (it answers as soon as possible)
TWICE, LATE_RULE = "2.link.simplex", "2.link.answer-promptly"


class Stray(NamedTuple):
    """Bytes that did not belong to the frame just sent: what they were, the rule they
    break, and whether they FAIL whatever that rule's tag (a second answer no watchdog
    explains; a watchdog's answer is graded by its rule's tag)."""

    text: str
    rule: str
    always: bool = True

    def __str__(self) -> str:
        return f"{self.text} [{self.rule}]"


def left_open(partial: bytes, packet_open: bool) -> str:
    """What the suite's bytes so far leave for a watchdog to end (``partial``: the bytes
    of a frame begun; LONE_BANG, OPEN_FRAME, OPEN_PACKET), "" when nothing."""
    if partial == b"!":
        return LONE_BANG
    if partial:
        return OPEN_FRAME
    return OPEN_PACKET if packet_open else ""


def judge(data: bytes, when: str, kind: str, summed: bool,
          last: tuple[str, bytes, bytes], *, judged: bool = False) -> tuple[bool, Stray | None]:
    """Whether ``data``, which no frame asked for, is a watchdog's answer to ``kind``
    (what was left unfinished), and the violation it is, if any: a lone `!` answered or
    a packet closed by time is a reading of its rule (not when the case reads the bytes
    itself, ``judged``; a frame answered so is our reading); else a second answer to the
    ``last`` frame (state, frame, answer) or a late one."""
    if kind and _watchdog_answer(data, kind, summed):
        if kind == OPEN_FRAME or judged:
            return True, None
        return True, Stray(f"{kind} was ended by a watchdog answering {readable(data)}",
                           WATCHDOG_RULES[kind], always=False)
    state, sent, answer = last
    frame_text = readable(sent) or "the last frame"
    if state == ANSWERED:
        return False, Stray(f"answered twice: {frame_text} got {readable(answer)}, then "
                            f"{readable(data)} {when}", TWICE)
    if state == TIMED_OUT:
        return False, Stray(f"answered after its timeout: {frame_text} got "
                            f"{readable(data)} late", LATE_RULE)
    return False, None


def _watchdog_answer(data: bytes, kind: str, summed: bool) -> bool:
    """Whether ``data`` is nothing but answers a watchdog gives (code 2, with INTA as it
    stands; after a packet its count of members too, spec 7's `2,k`)."""
    lines = [line for line in data.split(CR) if line]
    if not lines or not data.endswith(CR):
        return False
    for line in lines:
        r = parse_response(line + CR, summed=summed)
        if r is None or r.code is None or r.code & 7 != ErrorCode.WATCHDOG:
            return False
        if len(r.values) > (1 if kind == OPEN_PACKET else 0):
            return False
    return True
