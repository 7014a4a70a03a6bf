"""What the reference has been given so far in an example, as far as a difference
reads it: the dwell a frame may have met, the fastest its axes can have stepped, the
last vector it queued. One tracker, fed every accepted frame; whether a packet is open
is the one view of the wire's (conformance/protocol/view.py), fed every frame and the
reference's answer to it."""

from __future__ import annotations

import math
import re

from conformance.diff.sides import RoundTrip
from conformance.diff.steps import Step
from conformance.motion.tolerance import profile_reach
from conformance.protocol.bounded import decimal
from conformance.protocol.catalogue import classes, eeprom_read_width, eeprom_width
from conformance.protocol.view import View, observe
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import ErrorCode

#: a vector that moves nothing (and so waits no dwell)
_ZERO_VECTOR = re.compile(r"[LC][-+0,]*")
#: frames that change the course of a motion: a difference after them is theirs
_COURSE_CHANGERS = classes(course=True)
_VECTORS = classes(vector=True)
_EMPTIES = classes(empties=True)
_STOPS = classes(stops=True)
#: moves at a speed of its own (the profile's top speed bounds it), not the modal V
_OWN_SPEED = classes(own_speed=True)
#: frames besides vectors that move the axes or set their counters (J restarts them;
#: a packet's vectors are answered by its `*E`)
_MOVERS = _OWN_SPEED | classes(restart=True) | classes(packet="closes")
_RESTARTS = classes(restart=True)


class Course:
    """The reference's course through one example.

    - The modal dwell T and when the reference last took a vector: a frame sent less than
      T after it may have met the vector still in its dwell (spec 10.2), which is what a
      difference there points at, whatever command showed it.
    - The fastest its axes can have stepped (steps/s): the highest V it took, raised by
      the highest override (XM) and by 17/16 for each XU; a reference run (W) or the hand
      wheel (Y) may step at the variant's top rate. A reading taken while moving is
      uncertain by this rate times its window, not by the top rate (spec 10.2: a vector
      cruises at V at most, a short one at B if lower, and no ramp or junction exceeds
      the cruise; B lowers a rate, it never raises one).
    - The last vector it queued: ``C+C`` when a C followed a C (the two meet at a
      junction, spec 10.2); a D empties the queue.
    - The reference as the wire shows it (:attr:`wire`): whether a packet is open, as
      the link and the guard read it (an answered `*S` opens none, a frame answered
      inside one ends it).
    - How far from where the example began each axis can be (the counter units of every
      vector it took, in the micro-step mode of its time; unknown after anything else
      that moves or sets a counter): a position beyond is not a matter of *when* (a rate)
      but of *where* the vectors go (their unit, the mode's step).
    - The VL it took and the axes its vectors moved: VL capping only axes the vectors
      never moved, below the rate they ran at, changed nothing on the reference.
    - Whether a `K` save is held (a `K` taken and no `R` or restart since): what `R` and
      a second `K` meet is the manual's only with one held.
    - The EEPROM addresses it wrote: a byte read that no write in the example reached
      reads what the unit was shipped with (a manual names some of them).
    - Whether the GVE114's hand wheel holds the axes (its mode on, EEPROM 06 enabling it):
      whether it does with its parameters never set is a reading (9.reset.mpg-parameters).
    """

    def __init__(self, profile: Profile) -> None:
        self.t_ns = profile.reset.T * 1_000_000
        self.vector_at: int | None = None
        #: when the reference took an `L0,0,0`, and the longest T dwell a reader may give
        #: it (a normal vector to a reader of "program považuje za normální vektor")
        self.zero_at: int | None = None
        self.longest_t_ns = profile.range("T").hi * 1_000_000
        self.shortest_t_ns = profile.range("T").lo * 1_000_000
        self.t_given = False               # a T taken: the dwell is no reader's choice
        self.top = profile.max_rate
        self.speed = profile.reset.V
        self.override = max(100, profile.reset.XM) / 100
        self.up = 1.0
        self.queued: str | None = None
        #: the vector the dwell is measured from is a C that starts from rest
        self.c_from_rest = False
        #: a C queued right after a C reversing an axis (a junction where braking to 0 is
        #: a reading, 10.2.motion.junction-reversal): everything after it is timed by it
        self.reversal = False
        self._last_c: list[int] | None = None
        #: the frames to the unit (and its spindle's address) and the reference's answers
        self.wire = View()
        self.spindle = profile.spindle.address if profile.spindle is not None else None
        self.factors = dict(profile.microstep.factors) if profile.microstep else {}
        self.factor = self.factors[profile.microstep.reset_mode] if profile.microstep else 1
        #: the smallest acceleration it took (commanded steps/s²): the longest last step
        #: of a ramp to rest
        self.accel = profile.reset.A * 1000
        #: the vectors that may have started from rest (every L, a C with no C to join),
        #: the highest V they may have cruised at, and whether VK was taken: what another
        #: profile of the same motion reads (Pair's reading_ns)
        self.starts = 0
        self.cruise = profile.reset.V
        self.path = False
        #: each axis's direction in the last vector that moved it (0: none did)
        self.heading = [0] * len(profile.axes)
        #: the ramps at A to and from the speeds of the runs at a speed of their own (W)
        self.run_ramps_ns = 0
        #: GVE54: vectors held by a stop (H, SW6) that no D or K threw away, and an M taken
        #: while they were: whether their remainder keeps the mode they were accepted in
        #: is a reading (10.1.queue.captured [D])
        self.held = False
        self.mode_over_held = False
        self.reach: list[int] | None = [0] * len(profile.axes)
        self.caps: list[int] | None = None
        self.moved: set[int] = set()
        self.kept = False
        self.written: set[int] = set()
        self.named = set(profile.eeprom.defaults)
        self.mpg = profile.mpg
        self.mpg_mode = profile.mpg.reset_mode if profile.mpg else ""
        #: whether the mode is a `Y` sent's (M114 13.6.8's RUN = 1 is "při odeslání")
        self.mpg_sent = False
        self.mpg_byte = (profile.eeprom.defaults.get(profile.mpg.enable_address,
                                                     profile.eeprom.erased)
                         if profile.mpg else 0)

    # -- what it was given -----------------------------------------------------------------
    def took(self, command: str, body: str, reference: RoundTrip, *, first: bool = True
             ) -> None:
        """The reference answered ``body``; ``first``: not a later frame of a fill (whose
        vectors join the first: no dwell)."""
        if reference.code != ErrorCode.OK:
            return
        if first:
            self._dwell(command, body, reference)
        self._queue(command, body)
        self._ceiling(command, body)
        self._where(command, body)
        self._saved(command, body)

    def _saved(self, command: str, body: str) -> None:
        params = body[len(command):]
        if command == "K":
            self.kept = True
        elif command == "R":
            self.kept = False
        elif command in _RESTARTS:         # the reset state: no save, the MPG's mode
            self.kept = False
            self.mpg_mode = self.mpg.reset_mode if self.mpg else ""
            self.mpg_sent = False
        elif command == "Y":
            self.mpg_mode = params
            self.mpg_sent = True
        elif eeprom_width(command):
            written = _addresses(params, eeprom_width(command))
            self.written |= written
            if self.mpg is not None and self.mpg.enable_address in written:
                value = _first_number(params.partition(",")[2], 16)
                self.mpg_byte = value if value is not None else self.mpg_byte

    def exchanged(self, step: Step, reference: RoundTrip) -> None:
        """A frame of ``step`` went to the reference, which answered ``reference``
        (frames to another unit's address tell nothing of it)."""
        if step.address is None or step.address == self.spindle:
            self.wire = observe(self.wire, step.body, reference.response)

    def powered_on(self) -> None:
        """The reference restarted (a rig's power-on): the reset state (spec 9)."""
        self.wire = self.wire.restarted()

    @property
    def in_packet(self) -> bool:
        return self.wire.packet_open

    def _dwell(self, command: str, body: str, reference: RoundTrip) -> None:
        answer = reference.response
        if command == "L" and _ZERO_VECTOR.fullmatch(body.upper()) and answer is not None \
                and answer.code == ErrorCode.OK and not answer.inta:  # (with INTA it waits for G)
            self.zero_at = reference.sent_at
        if command in _VECTORS and not _ZERO_VECTOR.fullmatch(body.upper()):
            self.vector_at = reference.sent_at
            # a C with no C before it to join starts from rest: whether it waits the
            # dwell is a reading (10.2.motion.dwell-before-c [D])
            self.c_from_rest = command == "C" and self.queued in (None, "L")
            self.starts += command == "L" or self.c_from_rest
        elif command in _COURSE_CHANGERS:
            self.vector_at = None          # what follows is the halt's, the resume's...
        elif command == "T" and (ms := decimal(body[1:])) is not None:
            self.t_ns = ms * 1_000_000
            self.t_given = True

    def _queue(self, command: str, body: str) -> None:
        if command in _STOPS and self.queued is not None:
            self.held = True
        if command in _EMPTIES:      # D and K alike, as the timing takes them
            self.queued = None
            self.held = False
        elif command in _VECTORS and not _ZERO_VECTOR.fullmatch(body.upper()):
            steps = _numbers(body[1:]) if command == "C" else None
            if steps and self.queued in ("C", "C+C") and self._last_c and any(
                    a * b < 0 for a, b in zip(self._last_c, steps, strict=False)):
                self.reversal = True
            self._last_c = steps
            self.queued = "C+C" if command == "C" and self.queued in ("C", "C+C") else command

    def _ceiling(self, command: str, body: str) -> None:
        value = _first_number(body[len(command):])
        if command == "V" and value is not None:
            self.speed = max(self.speed, value)
            self.cruise = max(self.cruise, value)
        elif command == "VK":
            self.path = True
        elif command == "XM" and value is not None:
            self.override = max(self.override, value / 100)
        elif command == "A" and value is not None and value > 0:
            self.accel = min(self.accel, value * 1000)
        elif command == "XU":          # each XU scales the held vectors again
            self.up *= 17 / 16
        elif command in _OWN_SPEED:
            self.speed = self.top
            moves, ramps = self.own_run(command, body)
            self.starts += moves
            self.run_ramps_ns += ramps

    def _where(self, command: str, body: str) -> None:
        params = body[len(command):]
        if command in _VECTORS:
            d = _numbers(params)
            if d is None or self.reach is None:
                self.reach = None
                return
            for i, n in enumerate(d[:len(self.heading)]):
                if n:
                    self.heading[i] = 1 if n > 0 else -1
            for i, n in enumerate(d[:len(self.reach)]):
                self.reach[i] += abs(n) * self.factor
                if n:
                    self.moved.add(i)
        elif command == "M" and params in self.factors:
            self.factor = self.factors[params]
            self.mode_over_held |= self.held
        elif command == "VL":
            self.caps = _numbers(params)
        elif command in _MOVERS or command.startswith("N"):
            self.reach = None

    # -- what a difference reads ---------------------------------------------------------
    def context(self, t: int, command: str, body: str, position: list[str] | None
                ) -> set[str]:
        """The labels' context flags the course gives a difference at ``t`` on the frame
        ``body`` (``position``: the target's values where it is a position's)."""
        dwell = self.within_dwell(t)
        shipped = self.unwritten(command, body)
        flags = {
            "in-dwell": dwell,
            "c-from-rest": dwell and self.c_from_rest,
            "after-zero-vector": self.after_zero_vector(t),
            "reversal": self.reversal,
            "beyond-reach": position is not None and self.beyond_reach(position),
            "capped-elsewhere": self.capped_elsewhere,
            "kept": self.kept,
            "nothing-kept": not self.kept,
            shipped: bool(shipped),
            "mpg-on": self.mpg_on,
            "mpg-disabled": self.mpg_disabled,
            "mode-over-held": self.mode_over_held,
        }
        return {flag for flag, on in flags.items() if on}

    def within_dwell(self, t: int) -> bool:
        return self.vector_at is not None and t - self.vector_at < self.t_ns

    def after_zero_vector(self, t: int) -> bool:
        """Whether ``t`` is within the longest T dwell after an `L0,0,0` the reference
        took (what a unit holding RUN for that dwell does differently then is
        10.2.motion.zero-length's [D])."""
        return self.zero_at is not None and t - self.zero_at < self.longest_t_ns

    @property
    def rate(self) -> int:
        return min(self.top, math.ceil(self.speed * self.override * self.up))

    @property
    def dwell_reach(self) -> tuple[int, int]:
        """How much sooner and later than the reference's a start from rest may come for
        its dwell T (ns): with no T taken, a reader's T after reset (1..24 ms, spec 9 [D])
        placed before every start; with one taken, that T before every start, none
        sooner."""
        if self.t_given:
            return 0, self.t_ns
        return self.t_ns - self.shortest_t_ns, self.longest_t_ns

    @property
    def ramp_ns(self) -> int:
        """The longest a vector's ramp from rest to its cruise can take (ns): the highest V
        (raised by XM and XU) at the smallest A."""
        cruise = min(self.top, self.cruise * self.override * self.up)
        return math.ceil(cruise * 1_000_000_000 / self.accel)

    def reading_ns(self, changes: int, command: str = "", body: str = "") -> tuple[int, int]:
        """How much earlier and later a unit of somebody else's may place the example's
        motion than the reference (tolerance.py's profile_reach), ``changes``: the frames
        that changed its course, the run of the frame ``body`` (a W's, answered when it
        ends) included."""
        moves, ramps = self.own_run(command, body)
        sooner, later = self.dwell_reach
        return profile_reach(starts=self.starts + moves, changes=changes,
                             sooner_ns=sooner, later_ns=later,
                             ramp_ns=self.ramp_ns if self.path else 0,
                             run_ramps_ns=self.run_ramps_ns + ramps)

    def own_run(self, command: str, body: str) -> tuple[int, int]:
        """A run at a speed of its own (`W<axis>,n2,n3,n4,n5`): its moves from rest (to
        the switch and back) and how long ramps at the smallest A to and from its speeds
        n3 and n5 take (ns); (0, 0) for anything else."""
        fields = [int(n) for n in re.findall(r"-?\d+", body[len(command) + 1:])]
        if command not in _OWN_SPEED or len(fields) != 4:
            return 0, 0
        speeds = abs(fields[1]) + abs(fields[3])
        return 2, 2 * math.ceil(speeds * 1_000_000_000 / self.accel)

    def beyond_reach(self, position: list[str]) -> bool:
        """Whether ``position`` (a `P`/`PF` answer's values) has an axis farther from
        where the example began than every vector taken could carry it."""
        values = _numbers(",".join(position))
        return (self.reach is not None and values is not None
                and any(abs(v) > r for v, r in zip(values, self.reach, strict=False)))

    @property
    def capped_elsewhere(self) -> bool:
        """VL capped some axis below the rate the vectors ran at, and only axes none of
        them moved (so the reference's motion owes VL nothing)."""
        if self.caps is None or not self.moved:
            return False
        low = {i for i, cap in enumerate(self.caps) if cap < self.rate}
        return bool(low) and not low & self.moved

    @property
    def junction(self) -> bool:
        return self.queued == "C+C"

    def unwritten(self, command: str, body: str) -> str:
        """What an EEPROM read of ``body`` meets where no write of the example reached:
        "named" (a byte a manual names, the profile's defaults), "unwritten", or "" (not
        such a read)."""
        width = eeprom_read_width(command)
        read = _addresses(body[len(command):], width) if width else set()
        if not read or read & self.written:
            return ""
        return "named" if read & self.named else "unwritten"

    @property
    def mpg_on(self) -> bool:
        """Whether the hand wheel holds the axes: its mode on and EEPROM 06 enabling it."""
        return (self.mpg is not None and self.mpg_mode in ("+", "&")
                and self.mpg_byte in self.mpg.enabling_values)

    @property
    def mpg_disabled(self) -> bool:
        """Whether a `Y+` or `Y&` sent left the hand wheel's mode on with EEPROM 06 not
        enabling it: whether it then holds RUN (M114 13.6.8) or is inert (12.2) is a
        reading."""
        return (self.mpg is not None and self.mpg_sent and self.mpg_mode in ("+", "&")
                and self.mpg_byte not in self.mpg.enabling_values)


def _addresses(params: str, width: int) -> set[int]:
    """The ``width`` EEPROM bytes a read or write from the address in ``params`` spans."""
    try:
        first = int(params.split(",")[0], 16)
    except ValueError:
        return set()
    return set(range(first, first + width))


def _numbers(params: str) -> list[int] | None:
    try:
        return [int(p) for p in params.split(",")]
    except ValueError:
        return None


def _first_number(params: str, base: int = 10) -> int | None:
    try:
        return int(params.split(",")[0], base)
    except ValueError:
        return None
