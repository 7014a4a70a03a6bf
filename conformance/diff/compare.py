"""Two answers to one frame compared: alike, or the kind of their difference.

Kinds: ``silence`` (one side answered, the other did not), ``code`` (the error codes
differ), ``inta`` (only the INTA bit differs), ``checksum`` (only the response's checksum
differs), ``position`` (`P`/`PF` readings differ), ``data`` (other values), ``bytes``
(anything else: unreadable bytes, a line more), ``timing`` (the same bytes at different
instants: virtual time only, where both sides are exact).

In virtual time on both sides everything is exact against the reference's own kind (a
target graded by the project's decisions: the emulator, --strict); a target of somebody
else's in virtual time places its steps its own way, so its positions may differ by a step
of placement on each axis, and an answer given when the motion has come to rest (`H`) by
two step periods (conformance/motion/tolerance.py): its steps placed a period later stop a
period later, and the stop's last step, the ramp's longest, falls where its own steps put
it. With a target in real time, positions
read while moving may differ by the band of ``conformance/motion/tolerance.py`` (the
fastest rate the reference can have stepped at, times the width of the windows in which
the two frames were processed, the target's widened by the line's band of
``conformance/link/line_band.py``, plus a step of placement); at rest they must be equal
unless a frame changed the motion's course, which the target may have acted on up to its
latency and the line's band later.
The index (`@`) is compared from where each side's example began (the index of a real
unit or a co-simulator is not reset by the known state), in virtual time too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from conformance.diff.sides import RoundTrip
from conformance.link.line_band import EXACT, LineBand
from conformance.motion.tolerance import PLACEMENT_STEPS, Window, reading_band
from conformance.protocol.catalogue import classes
from gve_fixtures.protocol import SECOND

POSITION_COMMANDS = classes(position=True)
#: the kind of a difference in when the same bytes came
TIMING = "timing"
#: answered when the motion has stopped (spec 2)
DEFERRED = classes(deferred=True)


@dataclass(frozen=True)
class Judge:
    """How exactly two exchanges are compared."""

    exact: bool = True              # both sides in virtual time
    rate: int = 0                   # the fastest an axis may step (counter units/s)
    index_offset: int = 0           # target's index minus the reference's at the start
    #: real time: how much later the target may have acted than the reference on the
    #: frames that changed a running motion's course (H, G, XM, an input...), summed:
    #: positions even at rest may differ by the rate times this
    slack_ns: int = 0
    #: real time: the target's line band (its measured round trip and the example's own)
    line: LineBand = EXACT
    #: virtual time: the steps of placement either side a target of somebody else's may
    #: read (0: the reference's own placement), and how much later or earlier it may
    #: answer what answers once the motion is at rest (two of this step period, ns)
    placement: int = 0
    period_ns: int = 0
    #: the bits of an input port its manual calls unused (port, mask): what they read
    #: is silent, the rest is compared
    unused_inputs: tuple[tuple[int, int], ...] = ()


def difference(command: str, target: RoundTrip, reference: RoundTrip, judge: Judge,
               *, moving: bool = False) -> str | None:
    """The kind of difference between the two answers (None: alike)."""
    a, b = target.answer, reference.answer
    if a == b:
        if not a:
            # nothing came on either side: where each stopped listening is the suite's
            return None
        late = (target.received_at - target.sent_at) - (reference.received_at
                                                         - reference.sent_at)
        if judge.exact and late and not (command in DEFERRED
                                         and abs(late) <= 2 * judge.period_ns):
            return TIMING
        return None
    if not a or not b:
        return "silence"
    ra, rb = target.response, reference.response
    if ra is None or rb is None or ra.code is None or rb.code is None:
        return "bytes"
    if ra.code & 7 != rb.code & 7:
        return "code"
    if ra.inta != rb.inta:
        return "inta"
    if len(ra.lines) != len(rb.lines):
        return "bytes"
    if list(ra.values) == list(rb.values):
        return "checksum" if ra.checksum != rb.checksum else "bytes"
    if command in POSITION_COMMANDS or (command == ">" and _repeats_position(ra, rb)):
        if (not judge.exact or judge.placement) \
                and _positions_close(target, reference, judge, moving):
            return None
        return "position"
    if command == "@" and _same_index(ra.values, rb.values, judge):
        return None
    if _same_pins(command, ra.values, rb.values, judge):
        return None
    return "data"


def _same_pins(command: str, a: list[str], b: list[str], judge: Judge) -> bool:
    """Whether two reads of an input port differ only in bits its manual calls unused."""
    unused = dict(judge.unused_inputs).get(int(command[1:]), 0) \
        if command[:1] == "I" and command[1:].isdigit() else 0
    if not unused or len(a) != 1 or len(b) != 1:
        return False
    try:
        return (int(a[0], 16) ^ int(b[0], 16)) & ~unused & 0xFF == 0
    except ValueError:
        return False


def alike_because(command: str, target: RoundTrip, reference: RoundTrip, judge: Judge,
                  *, moving: bool = False) -> str:
    """Why two answers :func:`difference` found alike are alike ("" when their bytes are
    the same): what a replay prints beside two answers that differ in their bytes."""
    if target.answer == reference.answer:
        return ""
    if command == "@":
        return (f"the same index, counted from where each side began (offset "
                f"{judge.index_offset})")
    if command[:1] == "I" and target.response is not None and reference.response is not None \
            and _same_pins(command, target.response.values, reference.response.values, judge):
        return "the same in every bit with a pin (the others unused by the manual)"
    limit = band(target, reference, judge, moving)
    when = "read while the axes may have moved" if moving else \
        "read after a frame that changed the motion's course"
    line = "" if judge.line.exact else f" ({judge.line})"
    return f"within ±{limit} step(s){line}, {when}"


def delays(target: RoundTrip, reference: RoundTrip) -> tuple[str, str]:
    """How long after its frame each side answered, as a timing difference shows them
    (``41.250 ms``): with as many decimals as make two different instants read
    differently (to the nanosecond)."""
    a = target.received_at - target.sent_at
    b = reference.received_at - reference.sent_at
    for decimals in range(3, 7):
        shown = tuple(f"{ns / 1e6:.{decimals}f} ms" for ns in (a, b))
        if shown[0] != shown[1] or a == b:
            return shown
    return shown


def _repeats_position(ra, rb) -> bool:
    """Both `>` answers repeat the same position read: its values were taken while the
    axes may have moved, and are compared as that read was (the first line is the frame
    repeated, `!0PF`)."""
    if len(ra.lines) != 2 or ra.lines[0] != rb.lines[0]:
        return False
    frame = ra.lines[0].decode("latin-1")
    return frame[2:].upper() in POSITION_COMMANDS


def _numbers(values: list[str]) -> list[int] | None:
    try:
        return [int(v) for v in values]
    except ValueError:
        return None


def band(target: RoundTrip, reference: RoundTrip, judge: Judge, moving: bool) -> int:
    """Steps two readings may differ by: exact at rest; while moving the rate times how
    far apart the two instants can be, plus placement; and the rate times how late the
    target may have acted on what changed the motion's course."""
    if judge.exact:
        return judge.placement
    slack = judge.slack_ns + judge.line.ns if judge.slack_ns else 0
    late = math.ceil(judge.rate * slack / SECOND)
    if not moving:
        return late + PLACEMENT_STEPS if late else 0
    a = Window(*judge.line.widen(target.sent_at, target.received_at))
    b = Window(reference.sent_at, reference.received_at)
    return reading_band(a, b, judge.rate, placement=PLACEMENT_STEPS) + late


def _positions_close(target: RoundTrip, reference: RoundTrip, judge: Judge,
                     moving: bool) -> bool:
    xs, ys = _numbers(target.response.values), _numbers(reference.response.values)
    if xs is None or ys is None or len(xs) != len(ys):
        return False
    limit = band(target, reference, judge, moving)
    return all(abs(x - y) <= limit for x, y in zip(xs, ys, strict=True))


def _same_index(xs: list[str], ys: list[str], judge: Judge) -> bool:
    a, b = _numbers(xs), _numbers(ys)
    return (a is not None and b is not None and len(a) == len(b) == 1
            and (a[0] - judge.index_offset) % 256 == b[0] % 256)
