"""What each unit on the line did, read from the wire (spec 6, 7, 8, 9, 10.1): the motion
it accepted, with the settings each vector runs under — the oracle of the fault scenarios.

The checksum mode and the open packet are the one view of the unit from the wire
(conformance/protocol/view.py), fed each exchange as the unit got it and answered it;
what is the oracle's own is kept here: the packet's members as the judge read them (to
execute on their `*E`), the settings typed from the profile's reset state, whether a
restart turned the mode off under the host, and what was executed.

A vector is executed when the unit answered it `0` (or `8`: OK while interrupted), a
packet's members when its `*E` answered `0,k` (spec 7: all or nothing). Each executed
vector is kept with the modal settings it was accepted under (spec 10.1), so that a lost
setting shows as well as a lost vector. Zero-length vectors (the `L0,0,0` wait of 10.1)
move nothing and are left out.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from conformance.host.frame_rules import ParsedFrame, parse_frame
from conformance.host.recording import Exchange
from conformance.protocol.catalogue import classes
from conformance.protocol.view import View, observe
from conformance.protocol.wire import Response, parse_response
from gve_fixtures.profile import Profile

#: commands that set modal parameters captured with each vector (spec 10.1)
MODAL = classes(modal=True)
#: settings a fault scenario may target: the modal ones, status words, outputs, motor mode
SETTINGS = MODAL | classes(setting=True)
#: commands that change the motion or the counters: kept in the executed sequence
MARKERS = classes(marks=True)
VECTORS = classes(vector=True)
SWITCHES = classes(switch=True)


@dataclass(frozen=True)
class Executed:
    """One thing the unit executed: a vector with the settings it runs under, or a
    marker (``D``, ``N``, ``power-on``...)."""

    kind: str
    values: tuple[int | str, ...] = ()
    modal: tuple = ()

    def __str__(self) -> str:
        body = f"{self.kind}{','.join(map(str, self.values))}"
        if not self.modal:
            return body
        return f"{body} ({', '.join(f'{k}{v}' for k, v in self.modal)})"


@dataclass
class UnitView:
    """One unit: its motion address and, on a GVE114 at address 0, the spindle address 7
    that shares its checksum mode (spec 6 [D], 12)."""

    profile: Profile
    address: int
    addresses: frozenset[int] = frozenset()
    #: the unit as the wire shows it: its checksum mode, its open packet
    wire: View = field(default_factory=View)
    #: checksum mode was on when the unit last restarted, and no `%` since: a restart
    #: turned it off under the host (spec 6)
    lapsed: bool = False
    #: the open packet's members as the judge read them (the view's packet, parsed)
    members: list[ParsedFrame] = field(default_factory=list)
    modal: dict[str, object] = field(default_factory=dict)
    status: list[int] = field(default_factory=lambda: [0] * 7)
    executed: list[Executed] = field(default_factory=list)
    deaf_until: int = 0
    vectors: int = 0                    # how many vectors the unit has accepted so far

    def __post_init__(self) -> None:
        spindle = self.profile.spindle
        extra = {spindle.address} if spindle is not None and self.address == 0 else set()
        self.addresses = frozenset({self.address, *extra})
        self.wire = View(addresses=self.addresses, checksums=self.profile.reset.checksums)
        self._reset(summing=False)

    @property
    def checksums(self) -> bool:
        return self.wire.checksums

    @property
    def packet(self) -> list[ParsedFrame] | None:
        """The open packet's members (None: none open, as the view reads the wire)."""
        return self.members if self.wire.packet_open else None

    def _reset(self, *, summing: bool) -> None:
        """The reset state; ``summing``: the checksum mode was on just before."""
        r = self.profile.reset
        self.lapsed = summing and not r.checksums
        self.wire = self.wire.restarted().assume(checksums=r.checksums)
        self.members = []
        self.modal = {"V": r.V, "A": r.A, "B": r.B, "$": r.dollar, "T": r.T,
                      "VK": r.VK, "VL": tuple(r.VL), "XM": r.XM}
        self.status = list(r.status)

    def power_on(self, t: int) -> None:
        """The unit restarted (the rig's power cycle): reset state, deaf for a while."""
        self._reset(summing=self.checksums)
        self.executed.append(Executed("power-on"))
        self.deaf_until = t + self.profile.restart_ms * 1_000_000

    def apply(self, ex: Exchange, units: dict[int, Profile]) -> None:
        """Book one exchange for this unit: the frame as the unit got it, its answer."""
        if ex.to_unit is None or not ex.to_unit.endswith(b"\r"):
            return
        f = (ex.parsed if ex.to_unit[:-1] == ex.parsed.raw
             else parse_frame(ex.to_unit[:-1], units, self.checksums))
        if f.address not in self.addresses:
            return
        before = self.wire
        answer = self._answer(ex, f.body)
        self.wire = observe(before, f.body, answer, f.address)
        if self.wire.packet is not None and self.wire.packet != before.packet:
            # a member joined the packet, or an `*S` opened a new one
            self.members = [*self.members, f] if self.wire.packet else []
        name = f.command
        if name is None or answer is None or answer.code is None:
            return
        if name == "*E" and before.packet is not None:
            members, self.members = self.members, []
            if answer.ok:
                for member in members:
                    self._accept(member)
            return
        if answer.ok and name != "*E":
            self._accept(f)
            if name == "J":
                t = ex.answered_at or 0
                self._reset(summing=before.checksums)
                self.deaf_until = t + self.profile.restart_ms * 1_000_000

    def _answer(self, ex: Exchange, body: str) -> Response | None:
        """The unit's answer to ``body`` as the view reads it (None: none)."""
        if not ex.answer:
            return None
        return parse_response(b"".join(ex.answer), summed=self.wire.summed_after(body),
                              lines=len(ex.answer))

    def _accept(self, f: ParsedFrame) -> None:
        name, params = f.command or "", f.params
        if f.address != self.address:           # the spindle: V is its speed (spec 12)
            if name == "%":
                self.checksums = params[:1] == ["+"]
            elif name == "V":
                self.executed.append(Executed("spindle", (int(params[0]),)))
            return
        if name == "%":
            self.lapsed = False                 # the mode is the view's
        elif name in VECTORS:
            values = tuple(int(p) for p in params)
            values += (0,) * (len(self.profile.axes) - len(values))
            if any(values):
                modal = tuple((k, self.modal[k]) for k in sorted(self.modal))
                self.executed.append(Executed(name, values, modal))
                self.vectors += 1
        elif name in SWITCHES:
            self.modal["VK"] = name == "VK"
        elif name == "VL":
            values = tuple(int(p) for p in params)
            self.modal["VL"] = values + tuple(self.modal["VL"])[len(values):]  # type: ignore[arg-type]
        elif name in MODAL:
            self.modal[name] = int(params[0])
        elif name == "SW":
            self.status[int(params[0])] = int(params[1], 16)
        if name in MARKERS:
            self.executed.append(Executed(name, tuple(params)))

    def interrupt_input(self) -> tuple[int, int, int] | None:
        """The interrupt input the host enabled, as (port, bit, active level), or None
        (spec 10.3: ST0/ST2 bit i is input I1 bit i, ST1/ST3 bit i is I2 bit i)."""
        for port, enable, polarity, mask in ((1, 0, 2, self.profile.low_mask),
                                             (2, 1, 3, self.profile.high_mask)):
            bits = self.status[enable] & mask
            if bits:
                bit = (bits & -bits).bit_length() - 1
                return port, bit, (self.status[polarity] >> bit) & 1
        return None


def line_views(units: list[tuple[Profile, int]]) -> list[UnitView]:
    """One view per unit on the line (``units``: profile and address of each)."""
    return [UnitView(profile, address) for profile, address in units]


def by_address(views: list[UnitView]) -> dict[int, UnitView]:
    """Every address on the line with the view of the unit that answers it."""
    return {a: v for v in views for a in v.addresses}


def profiles_by_address(views: list[UnitView]) -> dict[int, Profile]:
    return {a: v.profile for v in views for a in v.addresses}
