"""The faults a real line and unit bring, injected by the relay at one point of the host's
job. Each fault acts through the same few hooks of the relay:

- ``hold(partial)``: keep the bytes of the frame in progress back from the unit for now;
- ``frame(ex)``: what the unit gets for a frame that was held whole (None: nothing);
- ``answer(ex)``: what the host gets for the unit's answer, and how late;
- ``after(ex)`` / ``tick(now)``: act on the unit through its rig (an input, a power cycle).

The point of the job comes from the clean run: "the middle vector", "the middle `*E`",
"the middle setting", or "after half of the job's vectors" (:class:`JobPoint`). Only the
fault's own point is faulted; everything else passes through untouched.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from conformance.host.frame_rules import byte_sum
from conformance.host.recording import Exchange, show
from conformance.protocol.catalogue import classes
from gve_fixtures.protocol import INTA_BIT, SECOND, ErrorCode

#: frames `>` never shows (spec 8): the last one remembered stays what it was
_FORGOTTEN = classes(remembered=False)

#: how late a late answer is: longer than a host's least patience (checks.PATIENCE)
LATE_S = 0.4
#: noise before an answer: bytes no response can contain (spec 4), so a careful host can
#: tell them from an answer
NOISE = b"\x00\xff"
#: how long the queue pretends to be full, and an input stays active
QUEUE_FULL_S = 0.3
INTERRUPT_S = 0.3


class Context(Protocol):
    """What a fault may use of the relay (and, through it, the units' test rig)."""

    def now(self) -> int: ...
    def vectors(self) -> int: ...
    def in_packet(self, address: int | None) -> bool: ...
    def checksums(self, address: int | None) -> bool: ...
    def note_fault(self, kind: str, detail: str) -> None: ...
    def power_on(self, address: int) -> None: ...
    def set_input(self, port: int, value: int, address: int) -> None: ...


@dataclass(frozen=True)
class JobPoint:
    """A point of the job: the frame (bytes from `!` to before CR) of the clean run and how
    many vectors the unit had accepted before it; ``raw`` empty = any frame after
    ``vectors`` accepted vectors."""

    raw: bytes
    vectors: int

    def reached(self, ctx: Context) -> bool:
        return ctx.vectors() >= self.vectors

    def matches(self, raw: bytes, ctx: Context) -> bool:
        return raw == self.raw and self.reached(ctx)

    def __str__(self) -> str:
        what = f"`{show(self.raw)}`" if self.raw else "the next frame"
        return f"{what} after {self.vectors} accepted vector(s)"


@dataclass
class Delivery:
    """What the host is given for an answer, ``delay`` seconds after the unit sent it."""

    data: bytes | None
    delay: float = 0.0


class Fault:
    """The clean line: everything passes through."""

    kind = "clean"

    def __init__(self) -> None:
        self.injected = False

    def describe(self) -> str:
        return "no fault"

    def hold(self, partial: bytes, ctx: Context) -> bool:
        return False

    def frame(self, ex: Exchange, ctx: Context) -> bytes | None:
        return ex.frame.raw + b"\r"

    def answer(self, ex: Exchange, ctx: Context) -> Delivery:
        return Delivery(b"".join(ex.answer))

    def after(self, ex: Exchange, ctx: Context) -> None:
        pass

    def tick(self, now: int, ctx: Context) -> None:
        pass


class AnswerFault(Fault):
    """The unit's answer to the target frame is lost, damaged, late, or has noise before
    it. Only an answer of `0` is faulted: the host must find out that its command did
    run (spec 8)."""

    def __init__(self, kind: str, target: JobPoint) -> None:
        super().__init__()
        self.kind, self.target = kind, target

    def describe(self) -> str:
        return f"{self.kind} on the answer to {self.target}"

    def answer(self, ex: Exchange, ctx: Context) -> Delivery:
        data = b"".join(ex.answer)
        if self.injected or ex.code != ErrorCode.OK or not self.target.matches(ex.frame.raw, ctx):
            return Delivery(data)
        self.injected = True
        ex.fault = self.kind
        out = DAMAGE[self.kind](data, ctx.checksums(ex.parsed.address))
        ctx.note_fault(self.kind, f"the unit answered {show(data)}; the host gets "
                                  f"{'nothing' if out.data is None else show(out.data)}"
                                  f"{f' {out.delay:g} s late' if out.delay else ''}")
        return out


def _lost(data: bytes, summed: bool) -> Delivery:
    return Delivery(None)


def _corrupt(data: bytes, summed: bool) -> Delivery:
    """In checksum mode the code digit changes (0 ↔ 1) under the old checksum; otherwise
    the first byte's bit 7 flips, which no response byte has (spec 4)."""
    if summed:
        code = int(data[:1], 16) ^ 1
        return Delivery(b"%X" % code + data[1:])
    return Delivery(bytes([data[0] ^ 0x80]) + data[1:])


def _late(data: bytes, summed: bool) -> Delivery:
    return Delivery(data, LATE_S)


def _noise(data: bytes, summed: bool) -> Delivery:
    return Delivery(NOISE + data)


DAMAGE = {"lost-answer": _lost, "corrupt-answer": _corrupt, "late-answer": _late,
          "noise": _noise}


class FrameFault(Fault):
    """The target frame never reaches the unit (``lost-frame``), or only its first half
    does and the unit's watchdog ends it (``cut-frame``, spec 3)."""

    def __init__(self, kind: str, target: JobPoint) -> None:
        super().__init__()
        self.kind, self.target = kind, target

    def describe(self) -> str:
        what = "lost on its way" if self.kind == "lost-frame" else "cut by the watchdog"
        return f"the frame {self.target} is {what}"

    def hold(self, partial: bytes, ctx: Context) -> bool:
        return (not self.injected and self.target.raw.startswith(partial)
                and self.target.reached(ctx))

    def frame(self, ex: Exchange, ctx: Context) -> bytes | None:
        raw = ex.frame.raw + b"\r"
        if self.injected or not self.target.matches(ex.frame.raw, ctx):
            return raw
        self.injected = True
        ex.fault = self.kind
        if self.kind == "lost-frame":
            ctx.note_fault(self.kind, f"{show(raw)} not passed to the unit")
            return None
        part = raw[: max(2, len(ex.frame.raw) // 2)]
        ctx.note_fault(self.kind, f"only {show(part)} of {show(raw)} passed to the unit")
        return part


class QueueFull(Fault):
    """For a while from the target on, the unit answers `1` to every vector and `*E`
    (spec 5, 10.1: try again later). The vector does not reach the unit; the unit gets
    `F` instead, so that its index counts the frame as a full queue's would (spec 8), and
    a packet's `*E` reaches it with a wrong count, so that it drops the packet. A `>`
    after it shows the host's frame and the `1` it got, as a full queue's unit would."""

    kind = "queue-full"

    def __init__(self, target: JobPoint) -> None:
        super().__init__()
        self.target = target
        self.until: int | None = None
        self._faked: set[int] = set()
        #: per address, what `>` shows while a faked frame is the last one remembered:
        #: the host's frame as sent (through its checksum) and the answer it got
        self._remembered: dict[int, tuple[bytes, bytes]] = {}
        self._repeats: set[int] = set()

    def describe(self) -> str:
        return f"the queue is full for {QUEUE_FULL_S:g} s from {self.target}"

    def _active(self, ctx: Context) -> bool:
        if self.until is None:                    # the window opens at the target
            return self.target.reached(ctx)
        return ctx.now() < self.until

    def hold(self, partial: bytes, ctx: Context) -> bool:
        return self._active(ctx)

    def frame(self, ex: Exchange, ctx: Context) -> bytes | None:
        raw = ex.frame.raw + b"\r"
        f = ex.parsed
        if f.command == ">" and f.address in self._remembered:
            self._repeats.add(ex.n)
        elif f.command is not None and f.command not in _FORGOTTEN:
            self._remembered.pop(f.address, None)
        if not self._active(ctx) or f.command is None:
            return raw
        packet = ctx.in_packet(f.address)
        if f.command in classes(vector=True) and not packet:
            frame = b"!%dF" % f.address
        elif f.command == "*E" and packet and f.params:
            frame = b"!%d*E%d" % (f.address, int(f.params[0]) + 1)
        else:
            return raw
        if self.until is None:
            self.until = ctx.now() + round(QUEUE_FULL_S * SECOND)
        self.injected = True
        self._faked.add(ex.n)
        ex.fault = self.kind
        if ctx.checksums(f.address):
            frame += b",%02X" % byte_sum(frame + b",")
        ctx.note_fault(self.kind, f"{show(raw)} passed to the unit as {show(frame)}\\r")
        return frame + b"\r"

    def answer(self, ex: Exchange, ctx: Context) -> Delivery:
        data = b"".join(ex.answer)
        if ex.n in self._repeats and ex.answer:
            frame, answer = self._remembered[ex.parsed.address]
            ctx.note_fault(self.kind, f"`>` answered {show(data)}; the host gets the frame "
                                      f"it sent and the 1 it got")
            return Delivery(frame + b"\r" + answer + b"\r")
        if ex.n not in self._faked or not ex.answer:
            return Delivery(data)
        line = ex.answer[-1].rstrip(b"\r")
        head = int(line[:1], 16)
        values = line.split(b",")[1:]
        if ctx.checksums(ex.parsed.address):
            values = values[:-1]
        if ex.parsed.command != "*E":
            values = []                       # F's status byte is not the vector's answer
        code = ErrorCode.QUEUE_FULL | (head & INTA_BIT)
        out = b",".join([b"%X" % code, *values])
        if ctx.checksums(ex.parsed.address):
            out += b",%02X" % byte_sum(out + b",")
        ctx.note_fault(self.kind, f"the unit answered {show(data)}; the host gets "
                                  f"{show(out)}\\r")
        self._remembered[ex.parsed.address] = (ex.frame.raw, out)
        return Delivery(out + b"\r")


class Interrupt(Fault):
    """After half of the job's vectors, the interrupt input the host enabled becomes
    active for a while, then is released (spec 10.3)."""

    kind = "interrupt"

    def __init__(self, target: JobPoint, port: int, bit: int, level: int,
                 address: int) -> None:
        super().__init__()
        self.target, self.port, self.bit, self.level = target, port, bit, level
        self.address = address
        self.release_at: int | None = None

    def describe(self) -> str:
        return (f"input I{self.port} bit {self.bit} active for {INTERRUPT_S:g} s after "
                f"{self.target.vectors} accepted vector(s)")

    def _set(self, level: int, ctx: Context) -> None:
        value = 0xFF & ~(1 << self.bit) | (level << self.bit)
        ctx.set_input(self.port, value, self.address)

    def after(self, ex: Exchange, ctx: Context) -> None:
        if self.injected or not self.target.reached(ctx) or ex.answered_at is None:
            return
        self.injected = True
        self._set(self.level, ctx)
        self.release_at = ex.answered_at + round(INTERRUPT_S * SECOND)
        ctx.note_fault(self.kind, f"input I{self.port} bit {self.bit} set to {self.level} "
                                  "(active)")

    def tick(self, now: int, ctx: Context) -> None:
        if self.release_at is not None and now >= self.release_at:
            self.release_at = None
            self._set(1 - self.level, ctx)
            ctx.note_fault(self.kind, f"input I{self.port} bit {self.bit} released")


class Restart(Fault):
    """After half of the job's vectors the unit is power-cycled (spec 2, 9): INFO, how
    the host reacts."""

    kind = "restart"

    def __init__(self, target: JobPoint, address: int) -> None:
        super().__init__()
        self.target, self.address = target, address

    def describe(self) -> str:
        return f"the unit restarts after {self.target.vectors} accepted vector(s)"

    def after(self, ex: Exchange, ctx: Context) -> None:
        if self.injected or not self.target.reached(ctx):
            return
        self.injected = True
        ctx.power_on(self.address)
        ctx.note_fault(self.kind, "the unit is power-cycled (deaf while it restarts, "
                                  "then in its reset state)")
