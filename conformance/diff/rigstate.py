"""What the test rig sees of a unit, compared on the two sides of `diff`: the outputs it
drives, the spindle setting and where the axes physically are (docs/rig.md, `state`).

The serial line shows none of these: an output written but deferred, a spindle command
refused at its address, an axis moved by a wrong amount while its counter reads right.
Each is rendered as an answer of its own (`0,FE`, `0,500`, `0,x,y,z`) so that it is
compared, labelled and graded as an answer is: the axes as a position read (within the
same band), the rest exactly. A key either side's rig does not give is not compared.
"""

from __future__ import annotations

from collections.abc import Iterator

from conformance.link.framing import parse_response
from conformance.protocol.bounded import decimal, hexadecimal

#: what is compared, in this order: (the state's key, the command a difference is
#: labelled with, the command it is compared as)
OBSERVED = (
    ("outputs", "state:outputs", "state"),
    ("spindle", "state:spindle", "state"),
    ("physical", "state:physical", "PF"),
)


def _rendered(key: str, value: object) -> bytes | None:
    """The rig's ``value`` of ``key`` as an answer's bytes (None: not readable)."""
    if key == "outputs":
        number = None if isinstance(value, bool) else hexadecimal(str(value))
        return None if number is None or number > 0xFF else b"0,%02X\r" % number
    if key == "spindle":
        number = None if isinstance(value, bool) else decimal(str(value))
        return None if number is None else b"0,%d\r" % number
    if isinstance(value, list) and value and all(
            isinstance(v, int) and not isinstance(v, bool) and abs(v) < 2**63 for v in value):
        return ("0," + ",".join(str(v) for v in value) + "\r").encode()
    return None


def observed(target: dict, reference: dict) -> Iterator[tuple[str, str, bytes, bytes]]:
    """(labelled as, compared as, the target's answer, the reference's) for every key both
    rigs give readably."""
    for key, label, compared in OBSERVED:
        a = _rendered(key, target.get(key))
        b = _rendered(key, reference.get(key))
        if a is not None and b is not None:
            yield label, compared, a, b


def response(answer: bytes):
    return parse_response(answer, summed=False)
