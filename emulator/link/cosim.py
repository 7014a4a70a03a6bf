"""Co-simulation: the line in virtual time, its clock driven over standard input and
output by whoever runs the test (docs/cosim.md). One command a line in, its reply lines
out; the clock moves only when told (`tx`, `until`), so the driver sees exactly what the
in-process `gve://` line would give it.

    tx HEX [T]     the host's bytes on the line from now; the clock runs to their end
                   (then, with T and no CR to the host meanwhile, on as `until T`)
    until T        advance to the instant T (ns), stopping at a CR to the host
    next           the next instant anything happens (`next T`, `next none`)
    batch D HEX .. frames in turn, each as `tx HEX T` with T its bytes' end + D ns (the
                   extension `batch`, offered on the first line: `cosim 1 batch`), ending
                   after the first frame that got no CR to the host (`batch-stops`)
    baud N         the line's rate
    in, switch, power-on, state, quit, help: the test rig (docs/rig.md)

`tx` and `until` answer `rx T HEX` for the bytes that reached the host meanwhile, then
`now T`; anything malformed answers one `error: ...` line and changes nothing.
"""

from __future__ import annotations

import sys
from typing import BinaryIO, TextIO

from emulator.link import control
from emulator.link.control import Quit
from emulator.link.line import Line, TimeRangeError, byte_time
from emulator.link.server import CONTROL_LIMIT, StdoutGone
from emulator.link.words import decimal

VERSION = 1
#: the optional extensions this simulator speaks, named on its first line (docs/cosim.md)
EXTENSIONS = ("batch", "batch-stops")
CR = b"\r"
#: the fastest line `baud` takes: a byte must take at least a nanosecond
MAX_BAUD = 10**9
HELP = ("commands: tx HEX [T] | until T | batch D HEX [D HEX ...] | next | baud N "
        "| in PORT HEX | switch AXIS POS|none | rate POS|none | power-on | state | quit  "
        "[@ADDRESS on in, switch, rate, power-on, state]")


class CosimError(ValueError):
    """A malformed command: one `error: ...` line, nothing changed."""


def _whole(text: str, what: str) -> int:
    try:
        return decimal(text, what)
    except ValueError as err:
        raise CosimError(str(err)) from None


def _instant(text: str) -> int:
    return _whole(text, "an instant (whole nanoseconds)")


def _hex(text: str) -> bytes:
    try:
        data = bytes.fromhex(text)
    except ValueError:
        data = b""
    if not data or len(text) != 2 * len(data):
        raise CosimError(f"tx takes the bytes as pairs of hex digits, not {text!r}")
    return data


class Cosim:
    """The commands on one line (see the module's docstring)."""

    def __init__(self, line: Line) -> None:
        if not line.clock.virtual:
            raise ValueError("co-simulation needs the line in virtual time")
        self.line = line

    def handle(self, text: str) -> list[str]:
        """The reply lines to one command line (none for an empty line); Quit on quit."""
        words = text.split()
        if not words:
            return []
        verb = words[0].lower()
        run = _COMMANDS.get(verb)
        if run is None:
            if verb in control.COMMANDS:
                reply = control.handle(self.line, text)
                return [] if reply is None else [reply]
            return [f"error: unknown command {text.strip()[:80]!r} ({HELP})"]
        try:
            return run(self, words[1:])
        except (CosimError, TimeRangeError) as err:
            return [f"error: {err}"]

    # -- the clock ---------------------------------------------------------------------------
    def _tx(self, args: list[str]) -> list[str]:
        if len(args) not in (1, 2):
            raise CosimError("tx HEX [T]")
        return self._send(_hex(args[0]), _instant(args[1]) if len(args) == 2 else None)[0]

    def _send(self, data: bytes, until: int | None) -> tuple[list[str], bool]:
        """The reply to `tx`, and whether a CR reached the host meanwhile."""
        line = self.line
        end = line.now + len(data) * line.byte_ns
        if until is not None and until < end:
            raise CosimError(f"tx ... {until}: before the bytes' end at {end}")
        line.write(data)                       # the clock runs to the end of the bytes
        out = line.take_timed()
        if until is not None and not any(CR in data for _, data in out):
            self._run_to(until)
            out += line.take_timed()
        return [*_rx_lines(out), f"now {line.now}"], any(CR in data for _, data in out)

    def _batch(self, args: list[str]) -> list[str]:
        """Each frame in turn as `tx HEX T`, T the end of its bytes + D: the replies
        those would give one after the other, in one exchange, up to and with the first
        frame during which no CR reached the host (`batch-stops`: the rest is not run)."""
        if not args or len(args) % 2:
            raise CosimError("batch D HEX [D HEX ...]")
        frames = [(_instant(args[i]), _hex(args[i + 1])) for i in range(0, len(args), 2)]
        out: list[str] = []
        for wait, data in frames:
            reply, answered = self._send(data, self.line.now + len(data) * self.line.byte_ns
                                         + wait)
            out += reply
            if not answered:
                break
        return out

    def _until(self, args: list[str]) -> list[str]:
        if len(args) != 1:
            raise CosimError("until T")
        t = _instant(args[0])
        if t < self.line.now:
            raise CosimError(f"until {t}: before now ({self.line.now})")
        self._run_to(t)
        return [*_rx_lines(self.line.take_timed()), f"now {self.line.now}"]

    def _run_to(self, t: int) -> None:
        """Advance to ``t``, or to the instant a CR to the host is complete if sooner;
        every unit event on the way (which may emit an answer with an earlier CR)."""
        line = self.line
        while True:
            cr = line.next_byte_at(CR)
            stop = t if cr is None or cr > t else cr
            event = line.next_deadline()
            if event is not None and event < stop:
                line.advance_to(event)
                continue
            line.advance_to(stop)
            return

    def _next(self, args: list[str]) -> list[str]:
        if args:
            raise CosimError("next takes no arguments")
        due = self.line.wake_instant()
        return [f"next {due}" if due is not None else "next none"]

    def _baud(self, args: list[str]) -> list[str]:
        if len(args) != 1:
            raise CosimError("baud N")
        baud = _whole(args[0], "baud N: N")
        if not 0 < baud <= MAX_BAUD:
            raise CosimError(f"baud N with N from 1 to {MAX_BAUD}, not {baud}")
        self.line.baud = baud
        self.line.byte_ns = byte_time(self.line.baud)
        return ["ok"]

    def _help(self, args: list[str]) -> list[str]:
        return [HELP]


def _rx_lines(runs: list[tuple[int, bytes]]) -> list[str]:
    return [f"rx {t} {data.hex().upper()}" for t, data in runs]


_COMMANDS = {"tx": Cosim._tx, "until": Cosim._until, "batch": Cosim._batch,
             "next": Cosim._next, "baud": Cosim._baud, "help": Cosim._help}


def serve_cosim(line: Line, stdin: BinaryIO | None = None, stdout: TextIO | None = None
                ) -> None:
    """Speak the protocol on ``stdin``/``stdout`` (default: the process's) until `quit`
    or the end of input (the driver is gone)."""
    stdin = stdin if stdin is not None else sys.stdin.buffer
    stdout = stdout if stdout is not None else sys.stdout
    cosim = Cosim(line)

    def say(lines: list[str]) -> None:
        try:
            stdout.write("".join(f"{x}\n" for x in lines))
            stdout.flush()
        except BrokenPipeError:
            raise StdoutGone from None

    say([" ".join(("cosim", str(VERSION), *EXTENSIONS))])
    while True:
        raw = stdin.readline(CONTROL_LIMIT + 1)
        if not raw:
            return
        if len(raw) > CONTROL_LIMIT and not raw.endswith(b"\n"):
            while raw and not raw.endswith(b"\n"):          # the rest of that line
                raw = stdin.readline(CONTROL_LIMIT + 1)
            say([f"error: a command line longer than {CONTROL_LIMIT} bytes"])
            continue
        try:
            replies = cosim.handle(raw.decode("utf-8", "replace"))
        except Quit:
            return
        if replies:
            say(replies)
