"""The reference host's recovery (spec 8) against a scripted unit: a lost answer is asked
for with `@` and `>`, never resent; a lost frame is resent once; a restart is noticed."""

from __future__ import annotations

import pytest

from gve_host.session import Session, UnitLost


class ScriptedUnit:
    """Just enough of a unit for spec 8: an index, the last frame and its answer. It
    answers every frame `0`; ``lose_answer``/``lose_frame`` drop the answer to, or the
    whole of, the frame with that body the first time it comes."""

    def __init__(self, lose_answer: str = "", lose_frame: str = "", index: int = 0) -> None:
        self.index, self.last = index, None
        self.lose_answer, self.lose_frame = lose_answer, lose_frame
        self.received: list[bytes] = []
        self.out = bytearray()
        self.timeout = None

    def write(self, data: bytes) -> int:
        body = data[2:-1].decode()
        if body == self.lose_frame:
            self.lose_frame = ""
            return len(data)
        self.received.append(data)
        if body == "@":
            self.out += b"0,%d\r" % self.index
        elif body == ">":
            self.out += self.last[0] + b"\r" + self.last[1] if self.last else b"0\r"
        else:
            self.index = (self.index + 1) % 256
            self.last = (data[:-1], b"0\r")
            if body == self.lose_answer:
                self.lose_answer = ""
            else:
                self.out += b"0\r"
        return len(data)

    def read_until(self, end: bytes = b"\r") -> bytes:
        k = self.out.find(end)
        if k < 0:
            return b""                  # the "timeout" passes at once
        line = bytes(self.out[: k + 1])
        del self.out[: k + 1]
        return line

    def reset_input_buffer(self) -> None:
        self.out.clear()

    def flush(self) -> None:
        pass


def bodies(unit: ScriptedUnit) -> list[str]:
    return [d[2:-1].decode() for d in unit.received]


def test_a_lost_answer_is_asked_for_not_resent():
    unit = ScriptedUnit(lose_answer="L100,0,0")
    s = Session(unit, 0, timeout=0.05)
    s.sync()
    answer = s.transact("L100,0,0")
    assert answer is not None and answer.code == 0
    assert bodies(unit) == ["@", "L100,0,0", "@", ">"]         # once, then asked


def test_a_lost_frame_is_sent_again():
    unit = ScriptedUnit(lose_frame="L100,0,0")
    s = Session(unit, 0, timeout=0.05)
    s.sync()
    s.transact("L100,0,0")
    assert bodies(unit) == ["@", "@", "L100,0,0"]              # it never arrived


def test_an_index_that_jumped_means_the_unit_is_lost():
    unit = ScriptedUnit(lose_answer="V100")
    s = Session(unit, 0, timeout=0.05)
    s.sync()
    unit.index = 0 if s.index else 7                          # as after a restart
    with pytest.raises(UnitLost, match="restarted"):
        s.transact("V100")


class Clock:
    """The session's time, moved only by the port below (no real waiting)."""

    def __init__(self) -> None:
        self.t = 0.0

    def monotonic(self) -> float:
        return self.t

    def sleep(self, seconds: float) -> None:
        self.t += seconds


class LateLine:
    """A unit in checksum mode whose answer to a vector (`1`: queue full) comes so late
    that the session gives it up for lost: it arrives just before the answer to the `@`
    that follows, which itself comes ``at_gap`` seconds later (the line's other end was
    busy). Lines are (instant, bytes); an empty read lets 10 ms pass."""

    def __init__(self, clock: Clock, at_gap: float) -> None:
        self.clock, self.at_gap = clock, at_gap
        self.lines: list[tuple[float, bytes]] = []
        self.received: list[bytes] = []
        self.timeout = None

    def write(self, data: bytes) -> int:
        self.received.append(data)
        now, body = self.clock.t, data[2:].split(b",")[0].rstrip(b"\r")
        if body == b"@":
            self.lines += [(now, b"1,5D\r"),
                           (now + self.at_gap, b"0,1,B9\r")]
        elif body == b">":
            self.lines.append((now, self.received[-3].rstrip(b"\r") + b"\r1,5D\r"))
        return len(data)

    def read_until(self, end: bytes = b"\r") -> bytes:
        if self.lines and self.lines[0][0] <= self.clock.t:
            t, data = self.lines[0]
            k = data.find(end)
            line, rest = data[: k + 1], data[k + 1:]
            self.lines[0:1] = [(t, rest)] if rest else []
            return line
        self.clock.t += 0.01
        return b""

    def reset_input_buffer(self) -> None:
        self.lines = [x for x in self.lines if x[0] > self.clock.t]

    def flush(self) -> None:
        pass


def test_a_late_answer_before_the_index_is_passed_over(monkeypatch):
    clock = Clock()
    monkeypatch.setattr("gve_host.session.time", clock)
    unit = LateLine(clock, at_gap=0.05)          # longer than SETTLE_S
    s = Session(unit, 0, timeout=0.25)
    s.summed, s.index = True, 0
    answer = s.transact("L1000,1000,0")
    # the late `1,5D` is a valid answer in checksum mode, not a unit without checksums:
    # the index comes after it, `>` shows the refusal, and the driver will try again
    assert answer is not None and answer.code == 1
    assert bodies(unit) == ["L1000,1000,0,D3", "@,BD", ">,BB"]
