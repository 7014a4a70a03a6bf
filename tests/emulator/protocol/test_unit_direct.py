"""The Unit driven directly, without the line: bytes in at the baud rate, advance()
to next_deadline(), answers collected from emit (architecture "The unit" contract).

Invariants checked on random byte streams shared by several units: time only moves
forward, every answer belongs to one of the unit's own addresses' frames, and the unit
always comes to rest (next_deadline() becomes None), so nothing can hang (spec 2, 3).
"""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from emulator.protocol.unit import Unit

BAUD = 115200
BYTE_NS = round(1e10 / BAUD)        # 10 bits per byte (8N1)
REST_LIMIT = 10_000                 # advance() steps before we call it a hang


class Harness:
    """Several units on one virtual line; collects (address, answer, instant)."""

    def __init__(self, units: list[Unit]) -> None:
        self.units = units
        self.now = 0
        self.answers: list[tuple[int, bytes, int]] = []
        for u in units:
            u.emit = lambda data, t, u=u: self.answers.append((u.address, data, t))

    def send(self, data: bytes) -> None:
        for u in self.units:
            u.receive(data, self.now, BYTE_NS)
        self.now += len(data) * BYTE_NS

    def settle(self) -> int:
        """Advance every unit to its deadlines until none is left; returns the steps."""
        for steps in range(REST_LIMIT):
            deadlines = [d for u in self.units if (d := u.next_deadline()) is not None]
            if not deadlines:
                return steps
            t = min(deadlines)
            assert t > self.now or all(t > u.now for u in self.units), "deadline in the past"
            self.now = max(self.now, t)
            for u in self.units:
                u.advance(t)
        raise AssertionError("the units never came to rest")


FRAMES = [b"V1000", b"L5,0,0", b"L-3,2,1", b"C1,1,1", b"P", b"H", b"G", b"D", b"K", b"R",
          b"F", b"?", b"@", b">", b"SR6", b"SW8,F1", b"Q", b"%-", b"J", b"XA", b"v1"]

piece = st.one_of(
    st.binary(max_size=10),                                           # noise, may hold '!'
    st.tuples(st.integers(0, 7), st.sampled_from(FRAMES)).map(
        lambda af: b"!" + str(af[0]).encode() + af[1] + b"\r"),       # a frame, any address
)


@given(st.sampled_from(["GVE84-100", "GVE114-500", "GVE54"]),
       st.lists(st.tuples(piece, st.booleans()), max_size=15))
@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
def test_shared_stream_units_answer_only_their_frames_and_come_to_rest(model, pieces):
    units = [Unit(model, 1), Unit(model, 2)]
    h = Harness(units)
    stream = b""
    for data, wait in pieces:
        stream += data
        h.send(data)
        if wait:
            h.settle()
    h.settle()
    for address in (1, 2):
        mine = [(d, t) for a, d, t in h.answers if a == address]
        # each answer needs a frame that started with "!" and this address (spec 2, 3)
        assert len(mine) <= stream.count(b"!" + str(address).encode()), (mine, stream)
        assert [t for _, t in mine] == sorted(t for _, t in mine), "time goes forward"
        for answer, _ in mine:
            # a response line; only `>` adds a first line: the echoed frame (spec 4, 8)
            *echo, last = answer[:-1].split(b"\r")
            assert answer.endswith(b"\r") and last[:1] in b"0123456789ABCDEF", answer
            assert len(echo) <= 1, answer
            assert all(e.startswith(b"!" + str(address).encode()) for e in echo), answer
    assert all(u.next_deadline() is None for u in units)
    # a final known frame to each: exactly one answer each, from the addressed unit only
    for address in (1, 2):
        h.answers.clear()
        h.send(b"\r")                          # end any unfinished frame first
        h.settle()
        h.answers.clear()
        h.send(b"!" + str(address).encode() + b"?\r")
        h.settle()
        assert [a for a, _, _ in h.answers] == [address], h.answers


def test_unit_answers_after_the_frame_and_only_once():
    h = Harness([Unit("GVE84-100", 0)])
    h.send(b"!0V1000\r")
    end = h.now
    h.settle()
    # spec 4: V within range answers 0 (INTA = 0 after reset, spec 9)
    assert [(a, d) for a, d, _ in h.answers] == [(0, b"0\r")]
    assert h.answers[0][2] >= end - BYTE_NS


def test_watchdog_answers_2_after_the_silence_and_then_rests():
    unit = Unit("GVE84-100", 0, watchdog_ms=100)
    h = Harness([unit])
    h.send(b"!0V10")
    h.settle()
    # spec 3: an unfinished frame is dropped after 100 ms and answered 2
    assert [d for _, d, _ in h.answers] == [b"2\r"]
    assert h.answers[0][2] >= 100_000_000
    assert unit.next_deadline() is None


def test_only_bang_arrived_no_answer():
    h = Harness([Unit("GVE84-100", 0, watchdog_ms=100)])
    h.send(b"!")
    h.settle()
    assert h.answers == []                     # spec 3: only '!' arrived → nothing


def test_bytes_during_restart_after_j_are_lost():
    unit = Unit("GVE84-100", 0)
    h = Harness([unit])
    h.send(b"!0J\r")
    h.send(b"!0?\r")                           # arrives while the unit restarts (spec 2)
    h.settle()
    assert [d for _, d, _ in h.answers] == [b"0\r"]
    h.answers.clear()
    h.send(b"!0@\r")
    h.settle()
    # spec 8/9: after the restart the index starts again; one answer, code 0
    assert len(h.answers) == 1 and h.answers[0][1].startswith(b"0,")


def _codes(h: Harness) -> list[bytes]:
    return [d for _, d, _ in h.answers]


def test_gve114_addresses_0_and_7_share_index_and_checksum_mode():
    unit = Unit("GVE114-500", 0)
    h = Harness([unit])
    for frame in (b"!0?\r", b"!7?\r", b"!7@\r"):
        h.send(frame)
        h.settle()
    # spec 8 + 12: two counted frames, one on each address, one index
    assert _codes(h)[-1] == b"0,2\r"
    h.answers.clear()
    h.send(b"!7%+\r")                          # checksums on via address 7
    h.settle()
    assert _codes(h) == [b"0,5C\r"]            # spec 6: already with its checksum
    h.answers.clear()
    h.send(b"!0?\r")                           # no checksum: address 0 refuses it too
    h.settle()
    # spec 6: error 4 with a checksum; "4," sums to 0x34 + 0x2C = 0x60
    assert _codes(h) == [b"4,60\r"]


def test_address_7_refuses_motion_commands():
    h = Harness([Unit("GVE114-500", 0)])
    h.send(b"!7L1,0,0,0\r")
    h.settle()
    assert _codes(h) == [b"3\r"]               # spec 12: anything else there → 3


def test_frames_during_a_pending_halt_are_dropped():
    unit = Unit("GVE84-100", 0)
    h = Harness([unit])
    h.send(b"!0V1000\r!0L20000,0,0\r")
    h.now += 50_000_000                        # let the vector run for 50 ms
    unit.advance(h.now)
    assert unit.device.motion.flags(h.now).moving
    h.answers.clear()
    h.send(b"!0H\r")
    h.send(b"!0?\r")                           # arrives while H waits for the stop
    h.settle()
    # spec 2/10.4 + project decision: only H's answer, 8 (INTA set by HALT), no '?' answer
    assert _codes(h) == [b"8\r"]
    assert not unit.device.motion.flags(h.now).moving


def test_reference_run_without_a_switch_is_5():
    unit = Unit("GVE84-100", 0)
    h = Harness([unit])
    h.send(b"!0WX,-200,1000,200,500\r")
    h.settle()
    # spec 10 W: the switch is never found → 5, answered after the move
    assert len(h.answers) == 1 and h.answers[0][1] == b"5\r"
    assert h.answers[0][2] >= 200_000_000        # 200 steps at no more than 1000/s
