"""The co-simulation protocol's client (docs/cosim.md): a program that prints ``cosim 1``
as its first line hands its clock to the suite, which drives it on the program's
standard input and output. The suite speaks the text protocol only (the simulator is
somebody else's; the emulator is one more such program).

:class:`CosimLine` is the line as a virtual-time link sees the embedded emulator's
(``now``, ``advance``, ``advance_to``; reads that wait in virtual time), and
:class:`CosimPort` the pyserial port on it that links write and read. A write is sent
with the next operation (``tx HEX T`` when that is a read: one exchange per frame).
Where the simulator takes commands ahead (`pipeline`), those whose words do not depend
on the replies before them (a wait's `until`s, a power-on, its restart and the `state`
after it) go in one write, each reply read when the suite comes to its command.

Every reply is checked as it comes: a simulator that breaks the protocol — no reply or
no ``now`` within :data:`REPLY_SECONDS`, time going backwards, a byte stamped before the
command began or after its ``now``, a clock that overshoots or stops short, an
``error:`` where the clock was to move, a line that is none of the replies — is
:class:`ProtocolBroken` (the target not responding, saying what it sent), and so is every
later use of the line: the run's cases FAIL or are COULD-NOT-TEST, never an ERROR.
"""

from __future__ import annotations

import contextlib
import time
from collections import deque
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import NoReturn, Protocol

from conformance.link.liveness import TargetNotResponding
from conformance.protocol.bounded import decimal
from conformance.verdicts.quoting import shown
from gve_fixtures.protocol import SECOND

VERSION = 1
CR = b"\r"
#: wall-clock seconds within which every reply must be complete
REPLY_SECONDS = 10.0
#: the most virtual time one command asks for (a slow simulator answers each in time)
STEP_NS = SECOND
#: the most bytes one reply may report
REPLY_BYTES = 1 << 20
#: a read without a timeout waits at most this long in virtual time
LONGEST_WAIT_NS = 3600 * SECOND


class ProtocolBroken(TargetNotResponding):
    """The co-simulator broke the protocol: the target is gone, saying how."""


class Channel(Protocol):
    """The program's side (conformance.targets.program.Program)."""

    @property
    def alive(self) -> bool: ...

    def send(self, text: str) -> bool: ...

    def line(self, timeout: float) -> str | None: ...

    def wait(self, seconds: float) -> bool: ...

    def ended(self) -> str: ...


def announced(first: str) -> int | None:
    """The protocol version a program's first line announces (None: not ``cosim N``,
    which the names of the extensions it offers may follow)."""
    words = first.split()
    return decimal(words[1]) if len(words) >= 2 and words[0] == "cosim" else None


def offered(first: str) -> frozenset[str]:
    """The optional extensions a program's first line ``cosim N NAME...`` offers."""
    return frozenset(first.split()[2:]) if announced(first) is not None else frozenset()


@dataclass(frozen=True)
class Ahead:
    """A frame told the simulator ahead (`batch`): where the suite will send it, the
    instant its answer was awaited until, and what the simulator did."""

    data: bytes
    start: int
    goal: int
    rx: bytes
    now: int
    cr: bool


def byte_ns(baud: int) -> int:
    return round(10 * SECOND / baud)


class Conversation:
    """One command and its reply at a time with the simulator's program: the line is
    broken for good from the first reply that breaks the protocol (or a reply cut off),
    saying why."""

    def __init__(self, program: Channel) -> None:
        self.program = program
        self.broken = ""
        self.exchanges = 0                    # commands sent
        self.writes = 0                       # writes they went in (one each, or ahead)
        #: commands sent ahead (`pipeline`), their replies not read yet, in order
        self.ahead: deque[str] = deque()
        #: a command to go in one write with the next one sent (sent ahead with it)
        self.then: str | None = None

    def fail(self, why: str) -> NoReturn:
        self.broken = self.broken or f"the co-simulator broke the protocol: {why}"
        raise ProtocolBroken(self.broken)

    def usable(self) -> None:
        if self.broken:
            raise ProtocolBroken(self.broken)

    def send(self, command: str) -> None:
        if self.ahead:          # (the line reads their replies before it sends another)
            self.fail(f"{command!r} was to be sent before the replies to "
                      f"{self.ahead[0]!r} and the commands sent with it were read")
        then, self.then = self.then, None
        self.exchanges += 1 + (then is not None)
        self.writes += 1
        if not self.program.send(command if then is None else f"{command}\n{then}"):
            self.ended(command)
        if then is not None:
            self.ahead.append(then)

    def send_ahead(self, commands: Sequence[str]) -> None:
        """Commands in one write, their replies read as each is exchanged in turn
        (:meth:`exchange`) or by the line when it needs another."""
        self.usable()
        if not commands:
            return
        if self.then is not None:
            commands, self.then = [*commands, self.then], None
        self.exchanges += len(commands)
        self.writes += 1
        if not self.program.send("\n".join(commands)):
            self.ended(commands[0])
        self.ahead.extend(commands)

    @contextlib.contextmanager
    def exchange(self, command: str) -> Iterator[None]:
        """One command and its whole reply; a reply left half read (a third Ctrl-C,
        an error of the suite) would be taken for the next command's: the line is broken
        from then on, saying so."""
        self.usable()
        done = False
        try:
            if self.ahead and self.ahead[0] == command:
                self.ahead.popleft()          # sent ahead: its reply is on its way
            else:
                self.send(command)
            yield
            done = True
        finally:
            if not done and not self.broken:
                self.broken = (f"the exchange {command!r} was cut off before its reply was "
                               "read: the co-simulation cannot go on")

    def ended(self, command: str) -> NoReturn:
        self.program.wait(1.0)
        ended = self.program.ended()
        self.broken = (f"the target's program ended: {ended}" if ended else
                       f"the co-simulator stopped reading its input at {command!r}")
        raise ProtocolBroken(self.broken)

    def reply(self, command: str, deadline: float, said: str) -> str:
        text = self.program.line(max(0.0, deadline - time.monotonic()))
        if text is None:
            if not self.program.alive or self.program.wait(0.2):
                self.ended(command)
            self.fail(f"no reply to {command!r} within {REPLY_SECONDS:g} s" if not said
                        else f"after {command!r} it sent {shown(said, 120)} and then nothing "
                        f"within {REPLY_SECONDS:g} s (no `now`)")
        return text


class SentAhead:
    """The `pipeline` extension's part of :class:`CosimLine` (which it is mixed into):
    commands whose words do not hang on the replies before them sent in one write, each
    reply read when the suite comes to its command (:meth:`CosimLine.ask`, the `until`s
    of :meth:`CosimLine.advance_to`), those it does not come to read before the next
    command is sent (:meth:`_drain`)."""

    talk: Conversation
    extensions: frozenset[str]
    now: int

    @property
    def pipelines(self) -> bool:
        """Whether commands may be sent ahead of the replies before them."""
        return "pipeline" in self.extensions

    def untils(self, t: int) -> list[str]:
        """The `until`s that take the clock from now to the instant ``t``, each as far
        as one command may ask (:meth:`advance_to` sends them, one at a time)."""
        out, at = [], self.now
        while at < t:
            at = min(t, at + STEP_NS)
            out.append(f"until {at}")
        return out

    def send_ahead(self, commands: Sequence[str]) -> bool:
        """Commands the suite is about to send one after the other, each in its turn as
        it would (:meth:`ask`, :meth:`advance_to`), sent now in one write where the
        simulator takes them so and more than one is to go (else each goes in its turn);
        whether they were sent. The line must be quiet: nothing of its own under way."""
        if not (len(commands) > 1 and self._quiet):
            return False
        self.talk.send_ahead(commands)
        return True

    @property
    def _quiet(self) -> bool:
        """Commands may be sent ahead: the simulator takes them so, and nothing of the
        line's own is under way."""
        return (self.pipelines and self._tx is None and self._inflight is None
                and self._told is None and not self._ahead and not self.talk.ahead)

    def launch_wait(self, seconds: float) -> bool:
        """The `until`s of a wait of ``seconds`` from now (:meth:`advance`) sent now, their
        replies read by that wait: the suite may do other work meanwhile, while the
        simulator runs them. Whether they were sent (the line quiet)."""
        commands = self.untils(self.now + round(seconds * SECOND))
        if not (commands and self._quiet):
            return False
        self.talk.send_ahead(commands)
        return True

    def power_on_ahead(self, seconds: float, *, state: bool) -> bool:
        """A power-on through the rig, its restart waited out for ``seconds`` (on the
        clock as :meth:`advance` waits) and, with ``state``, the rig's `state` after it,
        sent in one write (:meth:`send_ahead`); whether they were."""
        self._flush()
        self._catch_up()
        t = self.now + round(seconds * SECOND)
        return self.send_ahead(["power-on", *self.untils(t), *(["state"] if state else [])])

    def ask_next(self, command: str) -> None:
        """A rig command (`state`) the suite will ask once the next command sent has
        been answered (a frame's `tx`, a `batch`), sent in one write with it where the
        simulator takes commands ahead; if the suite asks something else first, its
        reply is read then and dropped."""
        if self.pipelines:
            self.talk.then = command

    def _drain(self, but: str | None = None) -> None:
        """The replies to the commands sent ahead that the suite did not come to in their
        turn (a read that stopped early at a CR, another command first): read in order,
        the clock where they took it, the rest of them dropped; up to ``but``, where it
        is the next of them (its reply is the caller's)."""
        talk = self.talk
        while talk.ahead and talk.ahead[0] != but:
            command = talk.ahead.popleft()
            try:
                if command.startswith("until "):
                    goal = decimal(command.split()[1])
                    self._moved(command, self.now, self.now,
                                self.now if goal is None else goal)
                else:
                    talk.reply(command, time.monotonic() + REPLY_SECONDS, "")
            except BaseException:
                talk.ahead.clear()
                if not talk.broken:
                    talk.broken = (f"the exchange {command!r} was cut off before its reply "
                                   "was read: the co-simulation cannot go on")
                raise


class KeptState:
    """The `snapshot` extension's part of :class:`CosimLine` (which it is mixed into): the
    simulator keeps its whole state, and returns to it."""

    extensions: frozenset[str]
    now: int

    def snapshot(self) -> bool:
        """The simulator keeps its whole state as it is now (`snapshot`, docs/cosim.md);
        False where it does not offer it, or refuses it (not used from then on)."""
        if "snapshot" not in self.extensions:
            return False
        if self.ask("snapshot").strip().lower() != "ok":
            self.extensions = self.extensions - {"snapshot"}
            return False
        return True

    def restore(self) -> None:
        """Back to the state the last `snapshot` kept, the clock not going back: the
        unit has stood since then (its reply `now T` is the present instant)."""
        self._flush()
        self._catch_up()
        self._drain()
        self._move("restore", self.now, self.now, self.now)


class CosimLine(SentAhead, KeptState):
    """The simulator's line, driven in virtual time (see the module's docstring)."""

    def __init__(self, program: Channel, baud: int, extensions: frozenset[str] = frozenset()
                 ) -> None:
        self.program = program
        self.talk = Conversation(program)
        self.extensions = extensions
        self.baud = baud
        self.byte_ns = byte_ns(baud)
        self.now = 0                          # the simulator's clock, as it last said
        self._rx = bytearray()                # bytes to the host, not read yet
        self._tx: tuple[bytes, int] | None = None   # a write not sent yet, and its start
        self._ahead: deque[Ahead] = deque()   # frames the simulator has run, to be sent
        #: a write sent with the read to come (launch), its reply not read yet:
        #: (command, start, end of its bytes, goal)
        self._inflight: tuple[str, int, int, int] | None = None
        #: frames told ahead whose reply is not read yet (tell): the command, its plan
        self._told: tuple[str, list[tuple[bytes, int]]] | None = None

    @property
    def broken(self) -> str:
        """Why the line is broken for good ("" while it is not)."""
        return self.talk.broken

    def start(self) -> str:
        """The line at the target's rate (`baud N`), then the reply to `state`: the
        rig's state, or an ``error:`` line when it has none."""
        command = f"baud {self.baud}"
        with self.talk.exchange(command):
            reply = self.talk.reply(command, time.monotonic() + REPLY_SECONDS, "")
        if reply.strip() != "ok":
            self.talk.fail(f"it answered 'baud {self.baud}' with {shown(reply, 120)}, not ok")
        return self.ask("state")

    def ask(self, command: str) -> str:
        """A rig command (docs/rig.md) at the current instant: its one reply line."""
        self._flush()
        self._catch_up()
        if self.talk.then == command:
            self.talk.then = None             # asked now: it goes now, alone
        self._drain(but=command)
        with self.talk.exchange(command):
            return self.talk.reply(command, time.monotonic() + REPLY_SECONDS, "")

    def next_event(self) -> int | None:
        """The instant the simulator says something next happens (None: nothing is
        due until the host sends or the rig acts); LookupError when it does not tell
        (`next` is optional, docs/cosim.md)."""
        reply = self.ask("next")
        if reply.startswith("error"):
            raise LookupError(f"the co-simulator does not tell its next event: {reply[:120]}")
        words = reply.split()
        if len(words) == 2 and words[0] == "next" and words[1] == "none":
            return None
        due = decimal(words[1]) if len(words) == 2 and words[0] == "next" else None
        if due is not None:
            return due
        self.talk.fail(f"it answered 'next' with {shown(reply, 120)}, not next T or next none")

    # -- the clock -----------------------------------------------------------------------------
    def _move(self, command: str, start: int, end: int, goal: int) -> bool:
        """Send ``command`` (tx or until), which runs the clock from ``start``: through
        the host's bytes to ``end``, then on to ``goal`` unless a CR reached the host by
        ``end``, stopping at the first CR after ``end``. Takes the reply's bytes; True
        when a CR ended it (or came during the bytes)."""
        with self.talk.exchange(command):
            return self._moved(command, start, end, goal)

    def _moved(self, command: str, start: int, end: int, goal: int) -> bool:
        """The reply to ``command`` (see :meth:`_move`)."""
        deadline = time.monotonic() + REPLY_SECONDS
        b, last, got = self.byte_ns, start, 0
        cr_sent = False                       # a CR reached the host by `end`
        stop: int | None = None               # the CR after `end` where the clock stops
        said = ""
        while True:
            said = self.talk.reply(command, deadline, said)
            words = said.split()
            if len(words) == 3 and words[0] == "rx":
                t, data = _rx(words)
                if t is None or not data:
                    self.talk.fail(f"it answered {command!r} with {shown(said, 120)}: not rx T HEX")
                if t <= start:
                    self.talk.fail(f"after {command!r} it sent {shown(said, 120)}: a byte stamped "
                                f"{t}, not after the instant {start} the command began "
                                "(a byte in the past)")
                if t < last:
                    self.talk.fail(f"after {command!r} it sent {shown(said, 120)}: stamped {t}, "
                                f"before the byte it sent before ({last})")
                first = 0 if cr_sent or stop is not None else data.find(CR)  # none breaks before CR
                for i in range(len(data) if first < 0 else first, len(data)):
                    value, at = data[i], t + i * b
                    if stop is not None or (cr_sent and at > end):
                        self.talk.fail(f"after {command!r} it sent {shown(said, 120)}: a byte at "
                                    f"{at}, after the CR at "
                                    f"{stop if stop is not None else end} where the clock "
                                    "was to stop")
                    if value == CR[0]:
                        if at <= end:
                            cr_sent = True
                        else:
                            stop = at
                last = t + (len(data) - 1) * b
                got += len(data)
                if got > REPLY_BYTES:
                    self.talk.fail(f"it answered {command!r} with more than {REPLY_BYTES} bytes")
                self._rx += data
            elif len(words) == 2 and words[0] == "now":
                now = decimal(words[1])
                if now is None:
                    self.talk.fail(f"it answered {command!r} with {shown(said, 120)}: not now T")
                self._arrived(command, said, now, start, end, goal, last,
                              end if cr_sent else stop if stop is not None else goal)
                return cr_sent or stop is not None
            elif said.startswith("error"):
                self.talk.fail(f"it refused {command!r}: {shown(said)}")
            else:
                self.talk.fail(f"it answered {command!r} with {shown(said, 120)}: not rx T HEX "
                            "or now T")

    def _arrived(self, command: str, said: str, now: int, start: int, end: int, goal: int,
                 last: int, expected: int) -> None:
        """``now`` must be where the command was to take the clock."""
        if now < start:
            self.talk.fail(f"after {command!r} it sent {shown(said)}: time went backwards "
                        f"(it was {start})")
        if now < last:
            self.talk.fail(f"after {command!r} it sent {shown(said)}: before the last byte it sent "
                        f"({last}), a byte in the future")
        if now > goal:
            self.talk.fail(f"after {command!r} it sent {shown(said)}: past the instant {goal} "
                        "it was asked for")
        if now != expected:
            self.talk.fail(f"after {command!r} it sent {shown(said)}, where the clock had to stop "
                        f"at {expected}" + (" (the end of the host's bytes)" if expected ==
                                            end and end > start else ""))
        self.now = now

    def _step(self, t: int) -> bool:
        """One command toward the instant ``t`` (the write not sent yet first): True when
        it stopped at a CR to the host."""
        self.landed()
        if self._inflight is not None:
            return self._land()
        self.talk.usable()
        if self._tx is not None:
            data, start = self._tx
            self._tx = None
            end = self.now
            goal = min(max(t, end), end + STEP_NS)
            if self._ahead:
                head = self._ahead.popleft()
                # told with its answer's due instant, earlier than the read's goal: a CR
                # by then is the same outcome, none leaves the read to go on from there
                if (head.data, head.start) == (data, start) and (
                        head.goal == goal or (head.goal < goal and "batch-stops"
                                              in self.extensions)):
                    self._rx += head.rx
                    self.now = head.now
                    return head.cr
                self._ahead.appendleft(head)
                wait = goal - end
                self._catch_up()                  # the bytes go out from where it is
                self._drain()
                start, end = self.now, self.now + len(data) * self.byte_ns
                self.now, goal = end, end + wait
            command = f"tx {data.hex().upper()}" + (f" {goal}" if goal > end else "")
            return self._move(command, start, end, goal)
        self._catch_up()
        goal = max(self.now, min(t, self.now + STEP_NS))
        if self.talk.ahead and self.talk.ahead[0] != f"until {goal}":
            self._drain()                     # stopped early at a CR: they run on
            if self.now >= t:
                return False
            goal = max(self.now, min(t, self.now + STEP_NS))
        return self._move(f"until {goal}", self.now, self.now, goal)

    # -- a write sent before its read ------------------------------------------------------------
    def launch(self, timeout: float | None) -> None:
        """The write not sent yet goes out now as the read of up to ``timeout`` s that
        comes next would send it; its reply is read (and checked) when that read comes,
        or before anything else the line is asked: the suite may do other work
        meanwhile, while the simulator runs the frame. Only when that read has to send
        it: nothing waits to be read (bytes received already, say during an injected
        pause, may be the answer the read takes, and the write then waits)."""
        self.landed()
        if self._tx is None or self._ahead or self._rx or self.talk.broken \
                or self.talk.ahead:
            return
        data, start = self._tx
        end = self.now
        deadline = end + (LONGEST_WAIT_NS if timeout is None else round(timeout * SECOND))
        goal = min(max(deadline, end), end + STEP_NS)
        command = f"tx {data.hex().upper()}" + (f" {goal}" if goal > end else "")
        self._tx = None
        self.talk.send(command)
        self._inflight = (command, start, end, goal)

    def _land(self) -> bool:
        """The reply to the command launched: True when a CR to the host ended it."""
        assert self._inflight is not None
        command, start, end, goal = self._inflight
        self._inflight = None
        self.talk.usable()
        try:
            return self._moved(command, start, end, goal)
        except BaseException:
            if not self.talk.broken:
                self.talk.broken = (f"the exchange {command!r} was cut off before its reply was "
                               "read: the co-simulation cannot go on")
            raise

    # -- frames told ahead (the `batch` extension) ---------------------------------------------
    def expect(self, frames: Sequence[tuple[bytes, float] | tuple[bytes, float, int | None]]
               ) -> int:
        """The frames the host is about to send one after the other, each with the seconds
        its answer is to be awaited (and, where known, the ns from its first byte by which
        its answer is due). A simulator that offers `batch` runs them all in one exchange;
        each frame's write and read then take their part of its reply, checked, timed and
        read exactly as one exchange a frame would be. One that also offers `batch-stops`
        ends the batch after a frame that got no CR: a frame awaited longer than one
        command may ask for (H, answered once the axes have stopped) is told with that
        much, and the frames after it run only if it was answered meanwhile; a frame
        whose answer is due is told with that, so that one answered later (or not at
        all) ends the batch, its read going on from there.
        Returns how many of the frames the simulator ran (0: none was told)."""
        return self.landed() if self.tell(frames) else 0

    def tell(self, frames: Sequence[tuple[bytes, float] | tuple[bytes, float, int | None]]
             ) -> bool:
        """:meth:`expect`'s exchange sent and its reply left to be read when the line is
        next used (whatever use): the suite may do other work meanwhile, while the
        simulator runs the frames. Whether they were told."""
        if not self.tells:
            return False
        self.talk.usable()
        self._drain()
        if not self.tells:                   # (bytes came meanwhile: one at a time)
            return False
        stops = "batch-stops" in self.extensions
        plan: list[tuple[bytes, int]] = []
        for data, timeout, *due in frames:
            wait = round(timeout * SECOND)
            if not data or (wait > STEP_NS and not stops):
                break
            if stops and due and due[0] is not None:
                wait = min(wait, max(due[0] - len(data) * self.byte_ns, 0))
            plan.append((bytes(data), min(wait, STEP_NS)))
        if len(plan) < 2:
            return False
        command = "batch " + " ".join(f"{wait} {data.hex().upper()}" for data, wait in plan)
        self.talk.send(command)
        self._told = (command, plan)
        return True

    @property
    def tells(self) -> bool:
        """Whether frames may be told now: the simulator takes `batch`, and nothing is
        under way on the line (a write, bytes unread, frames told before)."""
        return ("batch" in self.extensions and self._tx is None and not self._rx
                and not self._ahead and self._inflight is None and self._told is None)

    def landed(self) -> int:
        """Read the reply to the frames told (:meth:`tell`), checked frame by frame: how
        many of them the simulator ran (0: none is told)."""
        if self._told is None:
            return 0
        command, plan = self._told
        self._told = None
        self.talk.usable()
        stops = "batch-stops" in self.extensions
        here, ahead = self.now, []
        try:
            for i, (data, wait) in enumerate(plan):
                start = self.now
                end = start + len(data) * self.byte_ns
                label = f"batch (frame {i + 1}: tx {data.hex().upper()} {end + wait})"
                cr = self._moved(label, start, end, end + wait)
                ahead.append(Ahead(data, start, end + wait, bytes(self._rx), self.now, cr))
                self._rx.clear()
                if stops and not cr:
                    break                         # the simulator ran none after it
        except BaseException:
            if not self.talk.broken:
                self.talk.broken = (f"the exchange {command[:60]!r}... was cut off before its "
                               "reply was read: the co-simulation cannot go on")
            raise
        self.now = here
        self._ahead.extend(ahead)
        return len(ahead)

    def _catch_up(self) -> None:
        """Frames told ahead and then not sent as told (Ctrl-C, a frame the guard
        refused, a target given up): the simulator has run them all the same. The clock
        catches up with its clock, their answers are dropped."""
        if self._ahead:
            self.now = self._ahead[-1].now
            self._ahead.clear()

    def _flush(self) -> None:
        """Send the write not sent yet (its clock to the end of its bytes), or read the
        reply to the one launched, or to the frames told."""
        self.landed()
        if self._inflight is not None:
            self._land()
        if self._tx is not None:
            self._step(self.now)

    def advance_to(self, t: int) -> None:
        """Let virtual time pass up to the instant ``t`` (a write not sent yet goes out
        with it: `tx HEX T`, one exchange)."""
        self.landed()
        if self._inflight is not None:
            self._land()
        if self._tx is not None:
            self._step(t)
        self._catch_up()
        if not self.talk.ahead:
            self.send_ahead(self.untils(t))
        while self.now < t:
            self._step(t)

    def advance(self, seconds: float) -> None:
        self.advance_to(self.now + round(seconds * SECOND))

    def run_until_idle(self, max_seconds: float = 3600.0) -> bool:
        """Advance from event to event until none is due; False if ``max_seconds`` ran
        out first."""
        limit = self.now + round(max_seconds * SECOND)
        while (due := self.next_event()) is not None:
            if due > limit:
                self.advance_to(limit)
                return False
            self.advance_to(due)
        return True

    # -- the host's side -----------------------------------------------------------------------
    def write(self, data: bytes) -> int:
        """The host's bytes, one byte time each from now: the clock moves to their end
        (sent with the next operation)."""
        self._flush()
        self.talk.usable()
        if self._ahead and (self._ahead[0].data, self._ahead[0].start) != (data, self.now):
            self._catch_up()
        if not self._ahead:
            self._drain()          # the bytes go out after the commands sent ahead
        if data:
            self._tx = (bytes(data), self.now)
            self.now += len(data) * self.byte_ns
        return len(data)

    def ran(self, data: bytes) -> bool:
        """Whether the host's bytes ``data``, written now, are the next frame told ahead:
        the simulator has run them already (their write only takes its part of the
        reply)."""
        self.landed()
        return (self._tx is None and self._inflight is None and bool(self._ahead)
                and (self._ahead[0].data, self._ahead[0].start) == (data, self.now))

    def _take(self, size: int, terminator: bytes | None) -> bytes:
        end = min(size, len(self._rx))
        if terminator:
            k = self._rx.find(terminator, 0, end)
            if k >= 0:
                end = k + len(terminator)
        out = bytes(self._rx[:end])
        del self._rx[:end]
        return out

    def read(self, size: int, timeout: float | None, terminator: bytes | None = None) -> bytes:
        """Up to ``size`` bytes (stopping after ``terminator``), waiting at most
        ``timeout`` seconds of virtual time: the clock stops when the terminator is there
        (a CR, as every answer ends) or at the timeout."""
        self.landed()
        if self._tx is None:
            self._catch_up()
        deadline = self.now + (LONGEST_WAIT_NS if timeout is None else round(timeout * SECOND))
        out = bytearray(self._take(size, terminator))
        while len(out) < size and not (terminator and out.endswith(terminator)):
            if self._tx is None and self._inflight is None and self.now >= deadline:
                break
            self._step(deadline)
            out += self._take(size - len(out), terminator)
        return bytes(out)

    @property
    def in_waiting(self) -> int:
        self._flush()
        return len(self._rx)

    def discard_received(self) -> None:
        self._flush()
        self._rx.clear()

    def set_baud(self, baud: int) -> None:
        reply = self.ask(f"baud {baud}")
        if reply.strip() != "ok":
            self.talk.fail(f"it answered 'baud {baud}' with {shown(reply, 120)}, not ok")
        self.baud, self.byte_ns = baud, byte_ns(baud)


def _rx(words: list[str]) -> tuple[int | None, bytes]:
    t = decimal(words[1])
    if t is None:
        return None, b""
    try:
        data = bytes.fromhex(words[2])
    except ValueError:
        return None, b""
    return t, data if len(words[2]) == 2 * len(data) else b""


class CosimPort:
    """The port a link writes and reads: pyserial's interface on a :class:`CosimLine`
    (``.line`` gives the clock, as the embedded emulator's port does)."""

    def __init__(self, line: CosimLine, timeout: float | None = 0.5) -> None:
        self.line = line
        self.timeout = timeout
        self.is_open = True

    @property
    def baudrate(self) -> int:
        return self.line.baud

    @baudrate.setter
    def baudrate(self, baud: int) -> None:
        self.line.set_baud(baud)

    def write(self, data: bytes) -> int:
        return self.line.write(bytes(data))

    def expect(self, frames: Sequence[tuple[bytes, float] | tuple[bytes, float, int | None]]
               ) -> int:
        """The frames about to be sent, each with its answer's timeout and due instant
        (CosimLine.expect): how many the simulator ran."""
        return self.line.expect(frames)

    def tell(self, frames: Sequence[tuple[bytes, float] | tuple[bytes, float, int | None]]
             ) -> bool:
        """The frames about to be sent, their reply read when the line is next used
        (CosimLine.tell): whether they were told."""
        return self.line.tell(frames)

    def landed(self) -> int:
        """The reply to the frames told, read now (CosimLine.landed): how many ran."""
        return self.line.landed()

    @property
    def tells(self) -> bool:
        """Whether frames may be told now (CosimLine.tells)."""
        return self.line.tells

    def ran(self, data: bytes) -> bool:
        """Whether ``data`` written now was told ahead and run already (CosimLine.ran)."""
        return self.line.ran(data)

    def snapshot(self) -> bool:
        """The simulator keeps its state (CosimLine.snapshot): whether it did."""
        return self.line.snapshot()

    def restore(self) -> None:
        """Back to the state kept (CosimLine.restore)."""
        self.line.restore()

    def power_on_ahead(self, seconds: float, *, state: bool) -> bool:
        """A power-on, its restart and a `state` sent in one write (CosimLine.power_on_ahead)."""
        return self.line.power_on_ahead(seconds, state=state)

    def ask_next(self, command: str) -> None:
        """``command`` sent with the next one (CosimLine.ask_next)."""
        self.line.ask_next(command)

    def launch(self, timeout: float | None) -> None:
        """The write goes out now for the read to come with ``timeout`` (CosimLine.launch)."""
        self.line.launch(timeout)

    def launch_wait(self, seconds: float) -> bool:
        """A wait's commands sent now, read by the wait (CosimLine.launch_wait)."""
        return self.line.launch_wait(seconds)

    def read(self, size: int = 1) -> bytes:
        return self.line.read(size, self.timeout)

    def read_until(self, expected: bytes = b"\n", size: int | None = None) -> bytes:
        return self.line.read(size or 1 << 30, self.timeout, expected)

    @property
    def in_waiting(self) -> int:
        return self.line.in_waiting

    def reset_input_buffer(self) -> None:
        self.line.discard_received()

    def reset_output_buffer(self) -> None:
        """Nothing waits to go out: a write is on the line at once."""

    def flush(self) -> None:
        self.line._flush()

    def close(self) -> None:
        self.is_open = False
