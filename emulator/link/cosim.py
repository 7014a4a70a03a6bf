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
    snapshot       the whole simulation kept as it is now (the extension `snapshot`,
                   offered with --snapshot)
    restore        back to the last snapshot, the clock not going back: the unit stands
                   from the snapshot's instant to now (`now T`, T the present instant)
    in, switch, power-on, state, quit, help: the test rig (docs/rig.md)

Commands may come before the reply to the one before has been read (the extension
`pipeline`): each is answered in turn, and the replies to those already waiting go out
together.

`tx` and `until` answer `rx T HEX` for the bytes that reached the host meanwhile, then
`now T`; anything malformed answers one `error: ...` line and changes nothing.
"""

from __future__ import annotations

import contextlib
import gc
import os
import select
import sys
from collections.abc import Callable
from typing import BinaryIO, NoReturn, TextIO

from emulator.link import control
from emulator.link.awake import Awake
from emulator.link.control import Quit
from emulator.link.line import Line, TimeRangeError, byte_time
from emulator.link.server import CONTROL_LIMIT, StdoutGone
from emulator.link.words import decimal

VERSION = 1
#: the optional extensions this simulator speaks, named on its first line (docs/cosim.md)
EXTENSIONS = ("batch", "batch-stops", "pipeline", "snapshot")
CR = b"\r"
#: the fastest line `baud` takes: a byte must take at least a nanosecond
MAX_BAUD = 10**9
HELP = ("commands: tx HEX [T] | until T | batch D HEX [D HEX ...] | next | baud N "
        "| snapshot | restore | in PORT HEX | switch AXIS POS|none | rate POS|none "
        "| power-on | state | quit  [@ADDRESS on in, switch, rate, power-on, state]")


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

    def stand(self, t: int) -> list[str]:
        """The unit left alone until the instant ``t`` (a restored state brought to the
        present): the reply to `restore`."""
        self.line.advance_to(t)
        return [*_rx_lines(self.line.take_timed()), f"now {self.line.now}"]

    def _help(self, args: list[str]) -> list[str]:
        return [HELP]


def _rx_lines(runs: list[tuple[int, bytes]]) -> list[str]:
    return [f"rx {t} {data.hex().upper()}" for t, data in runs]


_COMMANDS = {"tx": Cosim._tx, "until": Cosim._until, "batch": Cosim._batch,
             "next": Cosim._next, "baud": Cosim._baud, "help": Cosim._help}


#: the exit status of a serving process that handed over to its snapshot's standby
_RESTORED = 75


class _Snapshots:
    """`snapshot` and `restore` by fork, as snapshot fuzzers keep a state. `snapshot`
    forks: the parent keeps the state as it was (the keeper), the child serves on; the
    keeper forks a standby from the kept state at once, which waits. `restore`: the
    serving process wakes the standby with the present instant and ends; the standby
    stands until that instant, answers and serves on, and the keeper forks the next
    standby meanwhile. A newer snapshot gives the older one up (its standby ends; its
    keeper only waits for the process it forked to end). A keeper ends, with that
    process's status, once it ended otherwise than by a `restore` (`quit`, the end of
    input): the process the driver started ends last."""

    def __init__(self) -> None:
        self.wake: int | None = None       # the pipe to the latest snapshot's standby

    def snapshot(self, flush: Callable[[], None]) -> int | None:
        """Fork; None in the child that serves on; in a standby woken by a `restore`,
        the instant it stands until."""
        flush()
        # the objects as they are now stay out of the collector's walks: a process forked
        # from them then copies only the pages it writes, not every page it would walk
        gc.collect()
        gc.freeze()
        if self.wake is not None:
            os.close(self.wake)            # the older snapshot's standby ends
            self.wake = None
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(r)
            self.wake = w
            return None
        os.close(w)
        return self._keep(pid, r)

    def _keep(self, serving: int, r: int) -> int:
        """The keeper: a standby at a time, woken through ``r``; returns in a woken
        standby (the instant to stand until)."""
        while True:
            next_r, next_w = os.pipe()
            standby = os.fork()
            if standby == 0:
                os.close(next_r)
                word = _read_word(r)
                os.close(r)
                if word is None:           # the serving process ended: so does this one
                    os._exit(0)
                self.wake = next_w
                return word
            os.close(r)
            os.close(next_w)
            r = next_r
            _, status = os.waitpid(serving, 0)
            code = os.waitstatus_to_exitcode(status)
            if code != _RESTORED:
                os.close(r)
                os.waitpid(standby, 0)
                os._exit(code)
            serving = standby

    def restore(self, now: int) -> NoReturn:
        """In the serving process: the standby is woken with the present instant; this
        process ends (the standby answers the `restore`)."""
        assert self.wake is not None
        os.write(self.wake, f"{now}\n".encode())
        os._exit(_RESTORED)


def _read_word(fd: int) -> int | None:
    """The instant a serving child wrote (None: it ended without one)."""
    data = b""
    while not data.endswith(b"\n"):
        try:
            part = os.read(fd, 64)
        except InterruptedError:
            continue
        if not part:
            return None
        data += part
    return int(data)


def serve_cosim(line: Line, stdin: BinaryIO | None = None, stdout: TextIO | None = None,
                *, snapshots: bool = False) -> None:
    """Speak the protocol on ``stdin``/``stdout`` (default: the process's) until `quit`
    or the end of input (the driver is gone). ``snapshots``: offer `snapshot` and
    `restore` (by fork: the process's own standard input and output only; each restore
    forks the next standby, which on a busy machine costs more than a power-on and its
    restart in virtual time, hence not offered unless asked)."""
    commands = _Commands(stdin if stdin is not None else sys.stdin.buffer)
    stdout = stdout if stdout is not None else sys.stdout
    cosim = Cosim(line)
    kept = _Snapshots() if snapshots and hasattr(os, "fork") else None
    offered = EXTENSIONS if kept is not None else tuple(
        x for x in EXTENSIONS if x != "snapshot")

    def say(lines: list[str]) -> None:
        try:
            stdout.write("".join(f"{x}\n" for x in lines))
            # the replies to commands already here go out with those to come: the
            # driver that sent them ahead wakes once for all of them
            if not commands.waiting():
                stdout.flush()
        except BrokenPipeError:
            raise StdoutGone from None

    say([" ".join(("cosim", str(VERSION), *offered))])
    try:
        _serve(cosim, commands, say, kept, stdout.flush)
    finally:
        with contextlib.suppress(BrokenPipeError, ValueError):
            stdout.flush()


def _serve(cosim: Cosim, commands: _Commands, say: Callable[[list[str]], None],
           kept: _Snapshots | None, flush: Callable[[], None]) -> None:
    """Each command in turn, until `quit` or the end of input."""
    while True:
        raw = commands.readline(CONTROL_LIMIT + 1)
        if not raw:
            return
        if len(raw) > CONTROL_LIMIT and not raw.endswith(b"\n"):
            while raw and not raw.endswith(b"\n"):          # the rest of that line
                raw = commands.readline(CONTROL_LIMIT + 1)
            say([f"error: a command line longer than {CONTROL_LIMIT} bytes"])
            continue
        text = raw.decode("utf-8", "replace")
        words = text.split()
        verb = words[0].lower() if words else ""
        if verb in ("snapshot", "restore") and kept is not None:
            say(_snapshot_or_restore(cosim, kept, verb, words[1:], flush))
            continue
        try:
            replies = cosim.handle(text)
        except Quit:
            return
        if replies:
            say(replies)


class _Commands:
    """The driver's command lines, read as they come (from a pipe or a terminal: its
    descriptor; any other stream: its own lines), and whether another one is already
    here."""

    def __init__(self, stream: BinaryIO) -> None:
        self.stream = stream
        try:
            self.fd: int | None = stream.fileno()
        except (AttributeError, OSError, ValueError):
            self.fd = None
        self.pending = bytearray()
        self.awake = Awake()

    def readline(self, limit: int) -> bytes:
        """The next line with its newline, at most ``limit`` bytes of it (b"": the end)."""
        if self.fd is None:
            return self.stream.readline(limit)
        while True:
            k = self.pending.find(b"\n", 0, limit)
            if k >= 0 or len(self.pending) >= limit:
                end = k + 1 if k >= 0 else limit
                out = bytes(self.pending[:end])
                del self.pending[:end]
                return out
            data = self._read()
            if not data:
                out = bytes(self.pending)
                self.pending.clear()
                return out
            self.pending += data

    def _read(self) -> bytes:
        """What comes next on the descriptor, awake for it a while first (awake.py)."""
        assert self.fd is not None
        self.awake.until_readable(self.fd)
        return os.read(self.fd, 1 << 16)

    def waiting(self) -> bool:
        """Whether a whole command is here already, read or on the descriptor."""
        if self.fd is None:
            return False
        if b"\n" in self.pending:
            return True
        try:
            return bool(select.select([self.fd], [], [], 0)[0])
        except (OSError, ValueError):
            return False


def _snapshot_or_restore(cosim: Cosim, kept: _Snapshots, verb: str, args: list[str],
                         flush: Callable[[], None]) -> list[str]:
    """The reply to `snapshot` or `restore` (given in the process that serves on)."""
    if args:
        return [f"error: {verb} takes no arguments"]
    if verb == "restore":
        if kept.wake is None:
            return ["error: restore: no snapshot was taken"]
        flush()                                # the replies before it go out first
        kept.restore(cosim.line.now)           # ends here; the keeper's child goes on
    # a child the keeper made after a `restore` comes back here, with the instant to
    # stand until
    stand = kept.snapshot(flush)
    if stand is None:
        return ["ok"]
    return cosim.stand(stand)
