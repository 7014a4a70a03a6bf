"""One emulated GVE unit: bytes in, bytes out, at instants (docs/architecture.md).

The unit frames the byte stream (framer.py), checks address and checksum, counts the
index and keeps the history for `>` (the session), collects packet members, runs the
other commands from its address's table (tables.py) on the device (device.py), and
answers through ``emit``. It owns the framer, the answers that are due later (H, W),
and nothing else: the machine's state is the device's, the conversation's the session's.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import replace
from pathlib import Path
from typing import Any

from emulator.mutants import Mutant
from emulator.protocol.checksum import checksum
from emulator.protocol.cmd_session import commit_on_arrival, member
from emulator.protocol.device import MS, Device
from emulator.protocol.framer import Frame, Framer
from emulator.protocol.params import CommandError
from emulator.protocol.reply import Answer, Deferred, Plain, Reply
from emulator.protocol.response import response
from emulator.protocol.session import Member, Session
from emulator.protocol.tables import (
    CLOSE,
    COMMANDS,
    DISCARD,
    Command,
    main_table,
    spindle_table,
    split,
)
from emulator.readings import Readings
from gve_fixtures.profile import Profile, load_profile
from gve_fixtures.protocol import MAX_FRAME, ErrorCode

_HEX = frozenset(b"0123456789ABCDEFabcdef")
_LONG_DECIMAL = re.compile(r"[0-9]{13}")
#: a + at the start of a field (the reading plus-sign drops it)
_PLUS = re.compile(r"(^|,)\+(?=[0-9])")
_LOWER_HEX = re.compile(r"[a-f]")
#: the hex fields of each command, by position (the reading hex-two-digits)
_HEX_FIELDS = {"ER": (0,), "EW": (0, 1), "EFR": (0,), "EFW": (0,), "EUR": (0,), "EUW": (0,),
               "O": (1,), "SW": (1,)}
#: N<axis> and I<port>: the letter after the command is a parameter (spec 5, code 3)
_LACKING = re.compile(r"N[A-Z]\Z|I[0-9]\Z")
#: the reading slow-watchdog: a second, the time a reader may take for "in time"
SLOW_WATCHDOG_MS = 1000
#: the readings half-second-watchdog (a frame) and packet-watchdog (an open packet)
HALF_SECOND_MS = 500
#: the reading longer-frames: the longest frame a unit with a byte-wide length counter holds
LONG_FRAME = 255


def _discard(data: bytes, t: int) -> None:
    pass


def _long_hex(name: str | None, params: str) -> bool:
    """Whether a hex field of the frame has more than two characters."""
    parts = params.split(",")
    return any(i < len(parts) and len(parts[i]) > 2 for i in _HEX_FIELDS.get(name or "", ()))


def begins_one(name: str, commands: Iterable[str]) -> bool:
    """Whether letters before the end of ``name`` begin a command of ``commands`` (`V` of
    `VL`, `N` of `NX`, `X` of `XA` for `XM`): a unit may read the frame as that command
    with parameters it does not take."""
    return any(c.startswith(name[:i]) for i in range(1, len(name)) for c in commands)


class Unit:
    def __init__(self, profile: Profile | str | Path, address: int | None = None, *,
                 eeprom_path: str | Path | None = None, mutant: str | None = None,
                 watchdog_ms: int | None = None, stepper: str | None = None,
                 origin: int = 0, readings: tuple[str, ...] = ()) -> None:
        if not isinstance(profile, Profile):
            profile = load_profile(profile)
        self.profile = profile
        self.address = profile.address if address is None else address
        self.mutant = Mutant(mutant)
        self.readings = Readings(frozenset(readings))
        self.device = Device(profile, mutant=self.mutant, eeprom_path=eeprom_path,
                             stepper=stepper, origin=origin, readings=self.readings)
        self.session = Session(profile.reset.checksums)
        self.tables: dict[int, dict[str, Command]] = {self.address: main_table(profile)}
        if profile.spindle is not None and self.address == 0:
            self.tables[profile.spindle.address] = spindle_table(profile)
            if self.mutant.active("spindle-refuses-eeprom"):
                for name in ("ER", "EW"):
                    self.tables[profile.spindle.address].pop(name, None)
        self.addresses = frozenset(self.tables)
        wd = profile.watchdog_ms if watchdog_ms is None else watchdog_ms
        if watchdog_ms is None and self.readings.active("half-second-watchdog"):
            wd = HALF_SECOND_MS
        if watchdog_ms is None and self.readings.active("slow-watchdog"):
            wd = SLOW_WATCHDOG_MS
        self.framer = Framer(None if self.mutant.active("watchdog-never") else wd * MS,
                             LONG_FRAME if self.readings.active("longer-frames") else MAX_FRAME)
        self.emit: Callable[[bytes, int], None] = _discard
        self.now = origin
        self._pending: list[tuple[bytes, Deferred, bool]] = []   # (frame, answer, remembered)
        #: the reading packet-watchdog: an open packet's last byte (None: not timed)
        self._packet_quiet: int | None = None

    # -- the rig ----------------------------------------------------------------------------
    def power_on(self, t: int) -> None:
        """Power cycle: the reset state; bytes are lost until the restart ends."""
        self.advance(t)
        self.device.reset(t)
        self.device.read_rate()
        summed = self.session.checksums
        self.session.reset(self.profile.reset.checksums)
        if self.mutant.active("power-on-keeps-checksums"):
            self.session.checksums = summed
        self.framer.reset()
        self._pending = []
        self._packet_quiet = None

    def set_input(self, port: int, value: int, t: int) -> None:
        self.advance(t)
        self.device.set_input(port, value, t)

    def set_switch(self, axis: str, position: int | None) -> None:
        self.device.switches[axis] = position

    def set_rate_switch(self, position: int | None) -> None:
        """The rate switch (jumpers) moved: read at the next power-on only."""
        choice = self.profile.baud
        if choice is None:
            raise ValueError(f"the {self.profile.name}'s rate is fixed at order time: "
                             "it has no rate switch")
        if position is not None and not 0 <= position < len(choice.positions):
            raise ValueError(f"rate switch positions are 0..{len(choice.positions) - 1}, "
                             f"not {position}")
        self.device.rate_position = position

    def hears(self, baud: int) -> bool:
        """Whether the unit's UART runs at the line's rate ``baud`` (else bytes both ways
        are lost as framing errors)."""
        return self.device.rate is None or self.device.rate == baud

    # -- time -------------------------------------------------------------------------------
    def next_deadline(self) -> int | None:
        """The next instant after now at which the unit acts by itself: the watchdog, the
        motion's next event, the end of a restart, an answer that is due later. The line
        asks on every read and write, so the usual case (only the motion) goes first."""
        now = self.now
        best = self.device.motion.next_event()
        if best is not None and best <= now:
            best = None
        deaf = self.device.deaf_until
        if deaf > now and (best is None or deaf < best):
            best = deaf
        if self.framer.buf is not None or self._pending or self._packet_quiet is not None \
                or self.device.due:
            for c in (self.framer.deadline(), self._packet_deadline(),
                      *(d.instant for _, d, _ in self._pending), self.device.next_due()):
                if c is not None and c > now and (best is None or c < best):
                    best = c
        return best

    def _packet_deadline(self) -> int | None:
        """The reading packet-watchdog: when an open packet that received nothing since
        its last byte is dropped (a frame under way has its own watchdog)."""
        if self._packet_quiet is None or self.framer.buf is not None \
                or self.session.packet is None:
            return None
        return self._packet_quiet + HALF_SECOND_MS * MS

    def advance(self, t: int) -> None:
        if self.device.due:
            self.device.run_due(t)
        if self._pending or self.framer.buf is not None or self._packet_quiet is not None:
            while True:
                expiry = self.framer.deadline()
                packet = self._packet_deadline()
                answer = min((d.instant for _, d, _ in self._pending), default=None)
                due = min((x for x in (expiry, packet, answer) if x is not None and x <= t),
                          default=None)
                if due is None:
                    break
                if due == packet:
                    self._packet_expired(due)
                elif due == expiry:
                    dropped = self.framer.expire(due)
                    if dropped is not None:
                        self._watchdog(dropped[0], due)
                else:
                    self._finish_pending(due)
        if t > self.now:
            self.now = t

    def _finish_pending(self, t: int) -> None:
        still = []
        for raw, d, remembered in self._pending:
            if d.instant <= t:
                code, values = d.finish(d.instant)
                self._answer(raw, code, values, d.instant, remember=remembered)
            else:
                still.append((raw, d, remembered))
        self._pending = still

    def _packet_expired(self, t: int) -> None:
        """The reading packet-watchdog: the open packet did not arrive whole in time:
        dropped, answered as a count mismatch is, `2,k` (k members received)."""
        members, self.session.packet = self.session.packet or [], None
        self._packet_quiet = None
        self._answer(b"", ErrorCode.WATCHDOG, [str(len(members))], t, remember=False,
                     arrived=False)

    def _watchdog(self, head: bytes, t: int) -> None:
        if len(head) < 2 and self.readings.active("lone-bang-answered"):
            self._answer(head, ErrorCode.WATCHDOG, [], t, remember=False, arrived=False)
            return
        if len(head) < 2 or self._address(head) is None:
            return                                  # only '!' arrived, or not ours
        self._answer(head, ErrorCode.WATCHDOG, [], t, remember=False, arrived=False)

    # -- bytes in ---------------------------------------------------------------------------
    def receive(self, data: bytes, t: int, byte_ns: int) -> None:
        i, n = 0, len(data)
        while i < n:
            at = t + i * byte_ns
            deaf = self.device.deaf_until
            if at < deaf:                         # restarting: these bytes are lost
                i = max(i + 1, -(-(deaf - t) // byte_ns)) if byte_ns else n
                self.framer.reset()
                continue
            self.advance(at)
            frame, i, end = self.framer.step(data, i, t, byte_ns)
            if frame is not None:
                self.advance(end)
                self._frame(frame, end)
            self._packet_quiet = t + (i - 1) * byte_ns \
                if self.session.packet is not None \
                and self.readings.active("packet-watchdog") else None

    def _address(self, raw: bytes) -> int | None:
        a = raw[1] - 48 if len(raw) > 1 else -1
        if a in self.addresses:
            return a
        if 0 <= a <= 7 and self.mutant.active("wrong-address-answers"):
            return self.address
        return None

    def _verify(self, frame: Frame) -> tuple[bool, bytes]:
        """Checksum mode: whether the frame's checksum verifies, and its body."""
        raw = frame.raw
        tail = frame.tail if frame.too_long else raw[-3:]
        if len(tail) < 3 or frame.length < 5 or tail[0] != 0x2C or tail[1] not in _HEX \
                or tail[2] not in _HEX:
            return False, raw[2:]
        comma = not self.mutant.active("checksum-no-comma")
        if frame.too_long:
            summed = (frame.total - tail[1] - tail[2] - (0 if comma else 0x2C)) & 0xFF
        else:
            summed = checksum(raw[:-2], comma=comma)
        good = summed == int(tail[1:], 16) or self.mutant.active("checksum-unchecked")
        return good, raw[2:-3]

    def _frame(self, frame: Frame, t: int) -> None:
        raw = frame.raw
        address = self._address(raw)
        if address is None:
            return
        if self._pending and not COMMANDS.get(raw[2:3].decode("latin-1"), _NONE).while_pending:
            return                 # an H or W answer is due: other frames are dropped [D]
        ses = self.session
        body = raw[2:]
        if ses.checksums:
            good, body = self._verify(frame)
            if not good:
                if ses.packet is not None:    # a failing member, whatever its body
                    ses.packet.append(Member(None, None, ErrorCode.SYNTAX))
                else:
                    name, _ = split(body.decode("latin-1"))
                    self._answer(raw, ErrorCode.SYNTAX, [], t, arrived=False,
                                 remember=COMMANDS.get(name or "", _NONE).remembered)
                return
        text = body.decode("latin-1")
        if self.mutant.active("lower-case-command") or self.readings.active("commands-any-case"):
            text = text.upper()
        name, params = split(text)
        known = COMMANDS.get(name or "", _NONE)
        delimiter = name in ("*S", "*E") and self.readings.active("packet-frames-uncounted")
        if (known.counted and not delimiter) or self.mutant.active("index-counts-queries") \
                or self.readings.active("queries-counted"):
            ses.count()
        if frame.too_long:                     # a syntax error (spec 3), also as a member
            if ses.packet is not None:
                ses.packet.append(Member(None, None, ErrorCode.SYNTAX))
            else:
                self._answer(raw, ErrorCode.SYNTAX, [], t, remember=known.remembered)
            return
        command = self.tables[address].get(name or "")
        if ses.packet is not None and not self._leaves_packet(command, name):
            m = member(self.device, name if command else None, params)
            if self.readings.active("packet-committed-on-arrival"):
                m = commit_on_arrival(self.device, m, t)
            ses.packet.append(m)
            return
        if command is None:
            lacking = self.readings.active("missing-letter-range") and _LACKING.match(name or "")
            prefixed = self.readings.active("absent-command-syntax") \
                and begins_one(name or "", self.tables[address])
            code = ErrorCode.RANGE if lacking else ErrorCode.SYNTAX if prefixed \
                else ErrorCode.UNKNOWN
            self._answer(raw, code, [], t, remember=known.remembered)
            return
        if command.packet == DISCARD and not (
                name in ("@", ">") and self.readings.active("packet-open-through-queries")):
            ses.packet = None
        self._run(raw, command, name, params, t)

    def _leaves_packet(self, command: Command | None, name: str | None) -> bool:
        """Whether a frame inside an open packet is run rather than taken as a member:
        `*E`, and the breakers H, @, >, J (the reading packet-closed-only-by-end makes
        them members; a second *S still restarts the packet)."""
        if command is None or command.packet not in (DISCARD, CLOSE):
            return False
        return command.packet == CLOSE or name == "*S" \
            or not self.readings.active("packet-closed-only-by-end")

    def _run(self, raw: bytes, command: Command, name: str | None, params: str,
             t: int) -> None:
        act = self.mutant.active
        reads = self.readings.active
        if name == "@" and reads("index-remembered"):
            command = replace(command, remembered=True)
        try:
            if reads("plus-sign"):
                params = _PLUS.sub(r"\1", params)
            if reads("hex-upper-only") and _LOWER_HEX.search(params):
                raise CommandError(ErrorCode.SYNTAX, "lower-case hex digits")
            if reads("hex-two-digits") and _long_hex(name, params):
                raise CommandError(ErrorCode.SYNTAX, "a hex field of more than two digits")
            if name == "NA" and reads("set-axis-xyz-only"):
                raise CommandError(ErrorCode.SYNTAX, "N takes the axes X, Y, Z")
            if command.bare and params:
                if not act("params-ignored-on-bare-commands"):
                    raise CommandError(ErrorCode.SYNTAX, "this command takes no parameters")
                params = ""
            if act("long-decimal-syntax-error") and _LONG_DECIMAL.search(params):
                raise CommandError(ErrorCode.SYNTAX, "more than 12 digits")
            if name == ">" and act("repeat-reexecutes") and self.session.history:
                self._rerun(self.session.history)
            reply = command.run(self.device, self.session, params, t)
            if name == "?" and reads("long-version"):
                reply = [f"{self.profile.version} (c) Gravos (P.Borovsky)"]
        except CommandError as err:
            code = err.code
            if code == ErrorCode.RANGE and act("range-error-code"):
                code = ErrorCode.SYNTAX
            self._answer(raw, code, [], t, remember=command.remembered)
            return
        self._reply(raw, command, reply, t)

    def _reply(self, raw: bytes, command: Command, reply: Reply, t: int) -> None:
        if isinstance(reply, list):
            self._answer(raw, ErrorCode.OK, reply, t, remember=command.remembered)
        elif isinstance(reply, Answer):
            self._answer(raw, reply.code, reply.values, t, remember=command.remembered)
        elif isinstance(reply, Deferred):
            self._pending.append((raw, reply, command.remembered))
        elif isinstance(reply, Plain):
            self.emit(reply.data, t)

    def _rerun(self, history: tuple[bytes, bytes]) -> None:
        """The mutant repeat-reexecutes: run the last frame again, silently."""
        last, answer = history
        silent, self.emit = self.emit, _discard
        try:
            self._frame(Frame(last, len(last), 0, b"", self.framer.limit), self.now)
        finally:
            self.emit = silent
        self.session.history = (last, answer)

    def _answer(self, raw: bytes, code: int, values: list[str], t: int, *,
                remember: bool = True, arrived: bool = True) -> None:
        """Answer ``raw``; ``arrived``: whether the index counted it when it arrived (a
        frame the watchdog dropped, or whose checksum failed, never was)."""
        ses = self.session
        # a refused frame the index counted is taken back; a query (@, >) counts only
        # where a reading or a mutant makes it count
        counted = arrived and (remember or self.readings.active("queries-counted")
                               or self.mutant.active("index-counts-queries"))
        if code and counted and (self.mutant.active("index-skips-refused")
                                 or self.readings.active("refused-uncounted")):
            ses.index = (ses.index - 1) & 0xFF
        data = response(
            code, values,
            inta=self.device.state.inta and not self.mutant.active("inta-bit-missing"),
            summed=ses.checksums,
            comma=not self.mutant.active("checksum-no-comma"),
            lower=self.mutant.active("checksum-lower-case"))
        if remember:
            ses.history = (raw, data)
        self.emit(data, t)

    # -- the rig's view --------------------------------------------------------------------------
    def snapshot(self, t: int) -> dict[str, Any]:
        """The unit's state as one JSON-serializable dict (the control channel's `state`,
        docs/rig.md)."""
        self.advance(t)
        return {
            "profile": self.profile.name,
            "addresses": sorted(self.addresses),
            "time_ns": t,
            **self.device.snapshot(t),
            "index": self.session.index,
            "checksums": self.session.checksums,
            "packet_open": self.session.packet is not None,
            "mutant": self.mutant.name,
        }


#: the flags of a name that is no command
_NONE = Command(lambda dev, ses, p, t: None)
