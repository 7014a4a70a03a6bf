"""Bad input never crashes or hangs the unit, never gets two answers to one frame,
never an answer for another address, and never changes state when refused (spec 3-5, 8).

Random noise (no '!', so it cannot form a frame), unfinished frames and waits are
interleaved with valid frames; after every valid frame the invariants are checked.
"""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from emulator.mutants import MUTANTS
from tests.emulator.replay import open_line

FRAMES = ["V1000", "V5", "L5,0,0", "L-3,2,1", "C7,0,0", "C1,1,1", "T99", "SW8,F1", "SR6",
          "P", "PF", "H", "G", "D", "K", "R", "F", "?", "Q", "@", "N", "XA", "A100", "B50",
          "*S", "*E1", "*E0", "%+", "%-", "ER01", "EW40,12", "Q5", "v1", "Z", "SR", "O0,FE",
          "O1,FE", "O"]

noise = st.binary(max_size=12).map(lambda b: b.replace(b"!", b"?"))
item = st.one_of(
    st.tuples(st.just("noise"), noise),
    st.tuples(st.just("partial"), st.sampled_from(FRAMES).map(lambda f: f[:-1])),
    st.tuples(st.just("wait"), st.floats(0.0, 0.5)),
    st.tuples(st.just("frame"), st.sampled_from(FRAMES)),
)


def _drain(port) -> bytes:
    port.line.advance(0.3)                      # let a pending H, watchdog, restart finish
    return port.read(port.in_waiting)


@given(st.sampled_from(["GVE54", "GVE84-100", "GVE114-500"]), st.lists(item, max_size=25))
@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
def test_bad_input_never_breaks_the_unit(model, items):
    address = 1 if model == "GVE54" else 0
    port = open_line(model, address)
    line = port.line
    unit = line.unit(address)
    accepted = [0] * len(unit.profile.axes)
    for kind, value in items:
        if kind == "noise":
            port.write(value)
        elif kind == "partial":
            port.write(f"!{address}{value}".encode())
        elif kind == "wait":
            line.advance(value)
        else:
            _drain(port)
            if unit.session.checksums or unit.session.packet is not None:
                continue                        # the model below speaks plain frames only
            port.write(f"!{address}@\r".encode())
            before = int(port.read_until(b"\r").split(b",")[1])
            port.write(f"!{address}{value}\r".encode())
            answer = port.read_until(b"\r")
            extra = _drain(port)
            if unit.session.packet is not None:
                assert answer == b"", "*S and members are not answered"
                continue
            if value != "H":
                assert extra == b"", f"{value}: a second answer {extra!r}"
            assert answer.endswith(b"\r") and answer[:1] in b"0123456789ABCDEF", answer
            if unit.session.checksums:
                continue                        # %+ just switched checksums on
            port.write(f"!{address}@\r".encode())
            after = port.read_until(b"\r")
            counted = 0 if value in ("@", ">") else 1         # spec 8
            if after:
                assert int(after.split(b",")[1]) == (before + counted) % 256, "index"
            code = int(answer[:1], 16) & 7
            if value[0] in "LC" and code == 0:
                steps = [int(x) for x in value[1:].split(",")]
                for i, s in enumerate(steps):
                    accepted[i] += s * unit.device.factor()
            assert unit.device.motion.queued(line.now) <= unit.profile.buffer
    _drain(port)
    # the position is the sum of executed steps: let everything run out and compare
    port.write(f"!{address}%-,CF\r".encode() if unit.session.checksums else b"")
    _drain(port)
    unit.session.packet = None
    port.write(f"!{address}G\r".encode())
    line.run_until_idle(600)
    _drain(port)
    if not unit.device.motion.flags(line.now).busy and not _had_reset(items):
        assert list(unit.device.motion.position(line.now)) == accepted, "position = executed steps"


def _had_reset(items) -> bool:
    """Frames that legitimately move the counters apart from the vectors."""
    return any(kind == "frame" and value in ("N", "D", "K", "R") for kind, value in items)


#: fields with digits that are not ASCII (``str.isdigit`` takes them, ``int`` does not),
#: in every place a field stands: a lone modal value, one before a comma, a packet member
UNREADABLE_DIGITS = [b"!0V\xb2\r", b"!0V\xb2,5\r", b"!0V1\xb9,5\r", b"!0L\xb2,0,0\r",
                     b"!0T\xb3\r", b"!0SW\xb2,00\r", b"!0*S\r", b"!0V\xb2\r", b"!0C\xb2,0,0\r",
                     b"!0*E1\r"]


@pytest.mark.parametrize("mutant", [None, *sorted(MUTANTS)])
def test_digits_outside_ascii_are_a_syntax_error_for_every_mutant_too(mutant):
    """A frame is bytes from the line, read as Latin-1: '²' is a digit to Python's
    isdigit; the unit (and each planted bug, whose branches read the fields before they
    look at the mutant) answers it as a field it cannot read, never with a crash."""
    port = open_line("GVE114-500", 0, **({} if mutant is None else {"mutant": mutant}))
    answers = []
    for frame in UNREADABLE_DIGITS:
        port.write(frame)
        port.line.advance(0.05)
        answers.append(port.read(port.in_waiting))
    assert all(a == b"" or a.endswith(b"\r") for a in answers), answers
    assert answers[0] == b"4\r" or mutant is not None
