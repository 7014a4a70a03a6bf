"""One unit, one command at a time (spec 2), and what to do when an answer goes missing
(spec 8).

The unit counts every complete frame it receives whose checksum verifies (except `@` and
`>` themselves) in an index modulo 256. The session keeps its own count of that index.
When an answer does not come, or comes damaged, it asks `@`:

- the index has not moved: the command never arrived; send it again;
- it moved by one: the command arrived and ran (or was refused); `>` shows the frame the
  unit got and the answer it gave, which the session takes as the answer;
- anything else: the unit restarted, or another host talks to it; the session stops.

A vector is therefore never sent twice unless the unit says it never got it. With
``resend_repeatable`` a setting or a read (V, A, SW, PF…) whose answer went missing is
sent again at once instead: "Většina příkazů se dá zopakovat (A,V,PF atd..)" (M84
12.5.12); its index is asked before the next command.
"""

from __future__ import annotations

import re
import sys
import time
from collections.abc import Callable

import serial

from gve_fixtures.protocol import ErrorCode
from gve_host import wire
from gve_host.bugs import Bugs
from gve_host.wire import Answer

#: after a recovery question, more lines may follow the first (a late answer comes
#: before the answer to `@`, never after it): take the last one within this time
SETTLE_S = 0.03
#: how long `@` is asked before the unit is given up for lost: longer than a restart
#: (about 2 s, spec 2)
ASK_FOR_S = 3.0
#: commands that are not counted in the index (spec 8)
UNCOUNTED = ("@", ">")
#: commands that leave the unit alike run once or twice (M84 12.5.12: "Většina příkazů
#: se dá zopakovat (A,V,PF atd..)"): settings and reads, by their letters
REPEATABLE = frozenset({"V", "A", "B", "T", "$", "SW", "O", "PF", "P", "SR", "F", "ER",
                        "%", "?"})
_LETTERS = re.compile(r"[A-Z$%?]+")
_ST6_WRITE = re.compile(r"SW0*6,")
#: a command's letters and its first decimal parameter (for the number bugs)
_NUMBER = re.compile(r"(L|C|V|A|B|T|\$)(-?\d+)")


class UnitLost(Exception):
    """The unit does not answer, or is no longer in the state the session knows."""


class Session:
    def __init__(self, port: serial.SerialBase, address: int, *, timeout: float = 0.25,
                 char_gap: float = 0.0, bugs: Bugs | None = None,
                 resend_repeatable: bool = False) -> None:
        self.port = port
        self.resend_repeatable = resend_repeatable
        self.bugs = bugs or Bugs()
        self.address = (address + 1) % 8 if self.bugs.on("wrong-address") else address
        self.timeout = None if self.bugs.on("wait-forever") else timeout
        self.char_gap = 0.15 if self.bugs.on("slow-bytes") else char_gap
        self.summed = False           # checksum mode (spec 6)
        self.index: int | None = None

    # -- bytes ----------------------------------------------------------------------------
    def frame(self, body: str, summed: bool | None = None) -> bytes:
        body = self._bugged(body)
        end = b"\n" if self.bugs.on("lf-terminator") else wire.CR
        data = wire.frame(self.address, body, self.summed if summed is None else summed,
                          end=end)
        if self.bugs.on("wrong-checksum") and (self.summed if summed is None else summed):
            total = int(data[-3:-1], 16)
            data = data[:-3] + b"%02X" % ((total + 1) % 256) + data[-1:]
        return data

    def _bugged(self, body: str) -> str:
        """The body as a buggy host would write it."""
        number = _NUMBER.match(body)
        if number and self.bugs.on("non-integer"):
            body = body[: number.end()] + ".0" + body[number.end():]
        if number and self.bugs.on("overlong-frames"):
            body = body[: number.start(2)] + "0" * 96 + body[number.start(2):]
        return body.lower() if self.bugs.on("lower-case") else body

    def send(self, data: bytes) -> None:
        if not self.char_gap:
            self.port.write(data)
            return
        for i in range(len(data)):           # one character at a time, as COM_SEND does
            self.port.write(data[i : i + 1])
            self.port.flush()
            if i < len(data) - 1:
                time.sleep(self.char_gap)

    def read_line(self, deadline: float | None) -> bytes | None:
        """One line up to CR, or None when the deadline passes first."""
        line = bytearray()
        while True:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return None
            self.port.timeout = left
            chunk = self.port.read_until(wire.CR)
            line += chunk
            if line.endswith(wire.CR):
                return bytes(line)

    def drain(self) -> None:
        self.port.reset_input_buffer()

    # -- one command ------------------------------------------------------------------------
    def read_answer(self, body: str, values: int, summed: bool) -> Answer | None:
        """The answer to ``body`` (``values``: how many values an OK answer has), or None
        when none came in time or it came damaged. A line of another shape is an answer
        that came too late for an earlier command: it is passed over."""
        deadline = None if self.timeout is None else time.monotonic() + self.timeout
        while True:
            line = self.read_line(deadline)
            if line is None:
                return None
            answer = wire.parse(line, summed,
                                trust_checksum=self.bugs.on("ignore-answer-checksums"))
            if answer is None:
                return None
            if _shaped(body, answer, values):
                return answer

    def transact(self, body: str, values: int = 0, *, resend: bool = True,
                 summed_answer: bool | None = None) -> Answer | None:
        """Send one command and return its answer, recovering a lost one (spec 8).
        None: the command did not arrive and ``resend`` is False (the caller resends
        something larger, as a whole packet)."""
        data = self.frame(body)
        summed = self.summed if summed_answer is None else summed_answer
        if self.bugs.on("no-wait") and values == 0 and body != "L0,0,0":
            self.send(data)            # and on to the next, the answer left unread
            return Answer(0, False, (), b"0")
        again = False
        while True:
            if self.index is None and body not in UNCOUNTED and not again:
                self.sync()
            before = self.index
            if self.bugs.on("no-wait"):
                self.drain()
            self.send(data)
            answer = self.read_answer(body, values, summed)
            if answer is None and self.bugs.on("blind-resend"):
                continue
            if answer is not None:
                self._count(body, answer)
                if answer.code == ErrorCode.WATCHDOG and body[:2] != "*E":
                    continue          # the watchdog cut it: nothing ran (spec 3)
                return answer
            if self.resend_repeatable and _repeatable(body) and not again:
                print(f"gve_host: no usable answer to {data!r}; sending it again "
                      "(it may be repeated)", file=sys.stderr)
                self.drain()
                self.index, again = None, True    # once or twice: asked before the next
                continue
            again = False
            answer = self.recover(data, before, summed)
            if answer is not None:
                return answer
            if not resend:
                return None

    def _count(self, body: str, answer: Answer) -> None:
        if body in UNCOUNTED or self.index is None:
            return
        if answer.code in (ErrorCode.OK, ErrorCode.QUEUE_FULL) or \
                (answer.code == ErrorCode.COUNT_MISMATCH and body[:2] == "*E"):
            self.index = (self.index + 1) % 256
        else:
            self.index = None         # a 2 from the watchdog, a 4 for a sum: ask again

    def sync(self) -> None:
        """Learn the unit's index."""
        index = self.ask_index()
        if index is None:
            raise UnitLost("the unit does not answer `@`")
        self.index = index

    def recover(self, data: bytes, before: int | None, summed: bool) -> Answer | None:
        """The answer to ``data`` was lost or damaged: find out what became of it."""
        print(f"gve_host: no usable answer to {data!r}; asking the unit (spec 8)",
              file=sys.stderr)
        self.drain()
        index = self.ask_index()
        if index is None:
            raise UnitLost("the unit does not answer `@`")
        if before is None:
            raise UnitLost("lost track of the unit's index")
        if index == before:
            return None               # it never arrived: send it again
        if index != (before + 1) % 256:
            raise UnitLost(f"the unit's index is {index}, not {before} or {before + 1}: "
                           "it restarted, or another host talks to it")
        self.index = index
        got = self.repeat(summed)
        if got is None or got[0] != data.rstrip(b"\r\n"):
            raise UnitLost(f"`>` does not show {data!r} as the last frame")
        return got[1]

    def ask_index(self) -> int | None:
        until = time.monotonic() + ASK_FOR_S
        while time.monotonic() < until:
            self.send(self.frame("@"))
            # a late answer to an earlier command may come first: only a line with the
            # shape of an index counts, and the last one is the answer to this `@`
            lines = self._settled(1, lambda line: self._index_of(line) is not None)
            indexes = [i for i in map(self._index_of, lines) if i is not None]
            if indexes:
                return indexes[-1]
            answer = lines[-1] if lines else None
            if (answer and self.summed and wire.parse(answer, True) is None
                    and wire.parse(answer, False) is not None):
                raise UnitLost("the unit answers without checksums: it has restarted "
                               "(checksum mode is off after power-on, spec 6)")
            self.drain()
        return None

    def _index_of(self, line: bytes) -> int | None:
        """The index in an answer to `@` (`0,<index>`), None for any other line."""
        parsed = wire.parse(line, self.summed)
        if parsed is None or parsed.code != ErrorCode.OK or len(parsed.values) != 1:
            return None
        return int(parsed.values[0]) if parsed.values[0].isdigit() else None

    def repeat(self, summed: bool) -> tuple[bytes, Answer] | None:
        """`>`: the last frame the unit received, and the answer it gave it."""
        self.send(self.frame(">"))
        lines = self._settled(2)
        for i, line in enumerate(lines[:-1]):
            if line.startswith(b"!"):
                answer = wire.parse(lines[i + 1], summed)
                return (line.rstrip(wire.CR), answer) if answer is not None else None
        return None

    def _settled(self, need: int,
                 counts: Callable[[bytes], bool] = lambda line: True) -> list[bytes]:
        """Lines until ``need`` that ``counts`` came and no more follow for a moment."""
        lines: list[bytes] = []
        counted = 0
        deadline = time.monotonic() + (self.timeout or 1.0)
        while True:
            line = self.read_line(deadline)
            if line is None:
                return lines
            lines.append(line)
            counted += counts(line)
            if counted >= need:
                deadline = time.monotonic() + SETTLE_S


def _repeatable(body: str) -> bool:
    """Whether ``body`` may be sent again: a write of ST6 may set the axes moving."""
    letters = _LETTERS.match(body)
    return letters is not None and letters.group(0) in REPEATABLE \
        and _ST6_WRITE.match(body) is None


def _shaped(body: str, answer: Answer, values: int) -> bool:
    """Whether an answer has the shape of one to ``body`` (spec 4, 7): `*E` always
    answers its code and k; an OK answer has its values; a failed one none."""
    if body[:2] == "*E":
        return len(answer.values) == 1
    return len(answer.values) == (values if answer.code == ErrorCode.OK else 0)
