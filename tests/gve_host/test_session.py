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
