"""Whatever a co-simulator or a rig replies — digits of other scripts (``²``, ``٣``),
numbers of thousands of digits, JSON nested a hundred thousand deep, escape sequences —
the suite reads it with bounds: the co-simulator has broken the protocol (the target not
responding, saying what it sent, escaped) or the rig cannot be used (COULD-NOT-TEST),
never another exception (an ERROR of the suite, a traceback, a usage error)."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.case.context import CouldNotTest
from conformance.link.liveness import TargetNotResponding
from conformance.targets.cosim import CosimLine, announced
from conformance.targets.process import port_url
from conformance.targets.rig import ControlRig

#: pieces a hostile reply is made of: protocol words, numbers in every form, controls
WORDS = st.sampled_from(["now", "rx", "next", "none", "ok", "error:", "cosim", "30", "0D",
                         "310D", "\x1b]0;title\x07", "\x00", "\r", "\x9b"])
NUMBERS = st.one_of(
    st.integers(min_value=-10, max_value=10**6).map(str),
    st.integers(min_value=30, max_value=6000).map(lambda n: "9" * n),     # huge
    st.sampled_from(["²", "٣", "1_000", " 7", "+5", "0x10", "1e3", "NaN", "-", "", "①"]),
    st.text(alphabet=st.characters(categories=["Nd", "No"]), min_size=1, max_size=8))
DEEP = st.integers(min_value=17, max_value=100_000).map(lambda n: "[" * n + "]" * n)
JSONISH = st.one_of(
    DEEP, st.integers(min_value=17, max_value=100_000).map(lambda n: '{"a":' * n),
    st.sampled_from(['{"position": [1e999]}', '{"outputs": NaN}', '{"outputs": true}',
                     '{"spindle": "²"}', '{"outputs": "%s"}' % ("F" * 5000),
                     '{"spindle": %s}' % ("9" * 5000), "{}", '{"inputs": {"1": "²"}}']))
REPLY = st.one_of(st.lists(st.one_of(WORDS, NUMBERS), max_size=4).map(" ".join), JSONISH,
                  st.text(max_size=40))


class Replies:
    """A co-simulator's channel that answers with ``replies`` in turn, then nothing."""

    alive = True

    def __init__(self, replies: list[str]) -> None:
        self.replies = list(replies)

    def send(self, text: str) -> bool:
        return True

    def line(self, timeout: float) -> str | None:
        return self.replies.pop(0) if self.replies else None

    def wait(self, seconds: float) -> bool:
        return True            # "ended": no wait for a reply that never comes

    def ended(self) -> str:
        return "it ended"


@settings(max_examples=300, deadline=None)
@given(st.lists(REPLY, min_size=1, max_size=6))
def test_a_co_simulator_s_replies_are_read_with_bounds(replies):
    line = CosimLine(Replies(replies), 115200)
    try:
        line.write(b"!0?\r")
        line.read(64, 0.01, b"\r")
        line.next_event()
        line.advance(0.001)
    except (TargetNotResponding, LookupError) as err:      # ProtocolBroken is one
        assert not any(ch in str(err) for ch in "\x00\x1b\x07\r\n\x9b"), str(err)


@settings(max_examples=300, deadline=None)
@given(first=REPLY, replies=st.lists(REPLY, max_size=6))
def test_a_rig_s_replies_are_read_with_bounds(first, replies):
    asked = iter([*replies, *['{"outputs": "zz"}'] * 8])
    rig = ControlRig.found_in(first, lambda command: next(asked), 0)
    if rig is None:
        return
    for use in (rig.state, rig.outputs, rig.spindle, lambda: rig.set_input(1, 0xFE),
                rig.hands_off):
        try:
            use()
        except CouldNotTest as err:
            assert not any(ch in str(err) for ch in "\x00\x1b\x07\r\n\x9b"), str(err)


@given(NUMBERS)
def test_a_first_line_announces_a_version_only_in_ascii_digits(number):
    version = announced(f"cosim {number}")
    word = number.strip()               # the line is read word by word
    assert version is None or (word.isascii() and word.isdigit() and len(word) <= 20)
    assert port_url(f"localhost:{number}") is None or (number.isascii() and number.isdigit())


def test_nesting_a_hundred_thousand_deep_is_no_rig():
    assert ControlRig.found_in("[" * 100_000 + "]" * 100_000, lambda c: "ok", 0) is None
    assert ControlRig.found_in('{"a":' * 100_000, lambda c: "ok", 0) is None
