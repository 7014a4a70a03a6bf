"""Spec 10's commands as Hypothesis strategies for one profile (``grammar.toml``): valid
and invalid parameters, checksums right, wrong and missing, other addresses and every
address the model serves (the GVE114's spindle's), packets, a filled queue, waits, the
rig's hands (inputs, a reference switch, a power-on) where both sides have a rig;
destructive commands only when allowed."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path

from hypothesis import strategies as st

from conformance.diff.labels import command_of
from conformance.diff.steps import FILL, FRAME, INPUT, RIG, WAIT, Step
from conformance.diff.written import Written, tabled
from conformance.protocol.catalogue import Command, Field, classes, commands
from gve_fixtures.profile import Profile

GRAMMAR_FILE = Path(__file__).with_name("grammar.toml")
_DEFAULTS = {"weight": 1, "answer": True, "lines": 1, "destructive": False}
#: commands never drawn at the spindle's address among those it does not serve: motion
#: there would be another unit's for the run's guard
_MOTION = classes(motion=True)


@dataclass(frozen=True)
class Options:
    """What a run allows: destructive commands, the rig's hands (both sides have a rig:
    inputs, a power-on, a reference switch where `W` is drawn too)."""

    destructive: bool = False
    rig: bool = False


@cache
def load_grammar(path: Path = GRAMMAR_FILE) -> dict:
    """grammar.toml, with ``command``: what is drawn of each command of the catalogue, by
    the name a profile's command set uses (``O0``), in the catalogue's order."""
    raw = tomllib.loads(path.read_text(encoding="utf-8"))
    draw = raw.pop("draw", {})
    unknown = set(draw) - set(commands())
    if unknown:
        raise ValueError(f"{path.name}: [draw]: no such command(s) {sorted(unknown)}")
    raw["command"] = {c.known_as: _drawn(c, draw.get(name, {}))
                      for name, c in commands().items()}
    return raw


def _drawn(c: Command, draw: dict) -> dict:
    entry: dict = {}
    if c.known_as != c.name:
        entry["text"] = c.name
    params = draw.get("params", [_kind(f) for f in c.fields])
    if c.repeat == "axes" and params != ["vector"]:
        params = params * 3
    if params:
        entry["params"] = params
    if draw.get("tables") is False:
        entry["tables"] = False
    for key, value in (("weight", draw.get("weight", 1)), ("answer", c.answer),
                       ("lines", c.lines), ("destructive", c.destructive)):
        if value != _DEFAULTS[key]:
            entry[key] = value
    if c.restart:
        entry["then_wait"] = "restart"
    return entry


def _kind(f: Field) -> str:
    """The field kind (grammar.toml) that draws a parameter of the catalogue."""
    if f.kind == "word":
        return "choice:" + "|".join(f.choices)
    if f.kind == "float":
        return "float"
    if f.range == "vector":
        return "vector"
    if isinstance(f.range, str):
        return f"range:{f.range}"
    assert f.range is not None
    return f"{f.kind}:{f.range[0]}:{f.range[1]}"


def _range_of(profile: Profile, kind: str) -> tuple[int, int] | None:
    """The valid values of a field kind, when it is numeric."""
    head, _, rest = kind.partition(":")
    if head == "range" or kind == "seek-rate":
        r = profile.range(rest or "V")
        return r.lo, r.hi
    if head in ("dec", "hex"):
        lo, hi = rest.split(":")
        return int(lo), int(hi)
    return None


def _valid(profile: Profile, kind: str, g: dict) -> st.SearchStrategy[str]:
    head, _, rest = kind.partition(":")
    moves = g["moves"]
    if kind == "vector":
        v, far = moves["vector"], moves["long"]
        return st.one_of(st.integers(-v, v), st.sampled_from([0, 1, -1, v, far, -far])
                         ).map(str)
    if kind == "travel":
        v = moves["travel"]
        return st.integers(-v, v).filter(bool).map(str)
    if kind == "axis":
        return st.sampled_from(profile.axes)
    if kind == "seek-rate":
        lo, hi = _range_of(profile, kind)
        return st.integers(min(hi, max(lo, 3 * moves["travel"])), hi).map(str)
    if kind == "float":
        return st.sampled_from(["0", "1.5", "-2e3", "1e+3", "3.4e39", "0.1"])
    if head == "choice":
        return st.sampled_from(rest.split("|"))
    lo, hi = _range_of(profile, kind)
    if head == "range" and rest in ("position",):
        # counters near where the moves go, now and then at an end of their range
        near = st.integers(max(lo, -moves["vector"]), min(hi, moves["vector"]))
        return st.one_of(near, st.sampled_from([lo, hi])).map(str)
    numbers = st.one_of(st.integers(lo, hi), st.sampled_from([lo, hi]))
    edges = _binary_edges(lo, hi)
    if edges:
        numbers = st.one_of(numbers, st.sampled_from(edges))
    if head == "hex":
        # EEPROM addresses and bytes from a few values, so a write is read back
        numbers = st.one_of(st.sampled_from([lo, min(lo + 1, hi), hi]), numbers)
        return numbers.map(lambda n: "%02X" % n)
    if head == "range" and rest in moves["slow_rates"]:
        numbers = st.one_of(numbers, st.integers(lo, min(hi, max(lo, moves["slow"]))))
    reset = _reset_value(profile, rest) if head == "range" else None
    if reset is not None:
        # a setting shrinks towards its reset value: a finding keeps only the settings
        # it needs, at the values it needs (a cap shrinks to no cap, not to a lower one)
        numbers = st.one_of(st.just(reset), numbers)
    return numbers.map(str)


def _reset_value(profile: Profile, key: str) -> int | None:
    """A modal setting's value after power-on (None: the field is no modal setting)."""
    r = profile.reset
    values = {"V": r.V, "A": r.A, "$": r.dollar, "B": r.B, "T": r.T, "XM": r.XM,
              "VL": r.VL[0] if r.VL else None}
    return values.get(key)


def _beyond(profile: Profile, kind: str) -> list[str]:
    """The values one past each end of a numeric field's range."""
    bounds = _range_of(profile, kind)
    if bounds is None:
        return []
    hexa = kind.startswith("hex")
    return ["%02X" % v if hexa else str(v) for v in (bounds[0] - 1, bounds[1] + 1)
            if not (hexa and v < 0)]


def _binary_edges(lo: int, hi: int) -> list[int]:
    """The values inside ``lo..hi`` where a field held in fewer bits than the range
    needs wraps (2^k - 1 and 2^k, and their negatives), as a fuzzer's interesting values
    are: a unit that decodes or stores a field too narrow shows there, not at the ends."""
    out = {v for k in range(4, 32) for v in (2 ** k - 1, 2 ** k, -(2 ** k), -(2 ** k) - 1)}
    return sorted(v for v in out if lo < v < hi)


def _invalid(profile: Profile, kind: str, g: dict) -> st.SearchStrategy[str]:
    forms = list(g["invalid"]["forms"])
    bounds = _range_of(profile, kind)
    out = []
    for form in forms:
        if form in ("below", "above"):
            if bounds is not None:
                value = bounds[0] - 1 if form == "below" else bounds[1] + 1
                out.append("%02X" % value if kind.startswith("hex") and value >= 0 else
                           str(value))
        else:
            out.append(form)
    if kind.startswith("choice") or kind == "axis":
        out += ["?", "0"]
    forms_of = st.sampled_from(out)
    if bounds is not None and "above" in forms:
        # beyond the top by more than one: a unit that keeps what fits of a refused value
        # keeps other bits than the top's
        far = st.integers(bounds[1] + 2, max(bounds[1] * 16, bounds[1] + 2) + 15)
        forms_of = st.one_of(forms_of, far.map(
            (lambda v: "%X" % v) if kind.startswith("hex") else str))
    return forms_of


def _body(name: str, entry: dict, params: list[str]) -> str:
    text = entry.get("text", name)
    kinds = entry.get("params", [])
    if not params:
        return text
    if kinds and (kinds[0].startswith("choice") or kinds[0] == "axis"):
        # a glued first field (`M4`, `%+`, `WY,...`)
        return text + params[0] + "".join("," + p for p in params[1:])
    return text + ",".join(params)


def command_names(profile: Profile, options: Options) -> list[str]:
    """The grammar's commands the profile has and the run allows."""
    g = load_grammar()
    return [name for name, entry in g["command"].items()
            if name in profile.commands and (options.destructive or not entry.get("destructive"))]


class Grammar:
    """The strategies of one profile and run, built once (drawing from prebuilt
    strategies inside one composite is much cheaper than building them per example)."""

    def __init__(self, profile: Profile, options: Options) -> None:
        g = self.g = load_grammar()
        self._cache: dict[tuple, st.SearchStrategy] = {}
        self.profile = profile
        self.options = options
        self.names = command_names(profile, options)
        #: the steps written in the grammar's data (frames of the run's names, SW6)
        self.written = Written(profile, options.rig, set(self.names) | {"SW6"} | {
            n for n, c in commands().items() if c.known_as in self.names}, g)
        self.weighted = [n for n in self.names for _ in range(g["command"][n].get("weight", 1))]
        kinds = {k for n in self.names for k in g["command"][n].get("params", [])} | {"vector"}
        self.invalid = {k: _invalid(profile, k, g) for k in kinds}
        self.valid = {k: _valid(profile, k, g) for k in kinds}
        self.beyond = {k: st.sampled_from(_beyond(profile, k)) for k in kinds
                       if _beyond(profile, k)}
        self.invalid_chance = round(g["invalid"]["chance"] * 100)
        self.modal = [n for n in g["motion"]["modal"] if n in self.names]
        self.vectors = [n for n in self.names if n in classes(vector=True)]
        self.events = [e for e in g["motion"]["events"]
                       if e.rstrip("0123456789,") in profile.commands]
        self.states = [r for r in g["motion"]["states"] if command_of(r) in self.names]
        self.checksums = "%" in profile.commands
        self.vector_counts = [3, 4] if profile.family == "GVE114" else [len(profile.axes)]
        steps = g["steps"]
        self.kinds = ["frame"] * steps["frame"] + ["wait"] * steps["wait"]
        if options.rig and profile.input_ports:
            self.kinds += ["input"] * steps["input"]
        if options.rig:
            self.kinds += ["power-on"] * steps["power_on"]
        # a switch only W sees (docs/rig.md): placed where a W is drawn to meet it
        self.switch_axes = list(profile.axes) if "W" in self.names else []
        if options.rig and self.switch_axes:
            self.kinds += ["switch"] * steps["switch"]
        spindle = profile.spindle
        self.spindle_names = [n for n in self.names if spindle is not None
                              and n in spindle.commands]
        self.spindle_others = [n for n in self.names if spindle is not None
                               and n not in spindle.commands and n not in _MOTION
                               and n in profile.commands]
        if self.spindle_names:
            self.kinds += ["spindle"] * g["spindle"]["weight"]
            r = spindle.range
            self.spindle_values = st.one_of(st.integers(r.lo, r.hi),
                                            st.sampled_from([r.lo, r.lo + 1, r.hi, r.hi + 1])
                                            ).map(str)
        if "*S" in profile.commands:
            self.kinds += ["packet"] * g["packet"]["weight"]
        if "C" in profile.commands:
            self.kinds += ["fill"] * g["fill"]["weight"]
        if self.vectors:
            self.kinds += ["motion"] * g["motion"]["weight"]
        self.readbacks = [(w, r) for w, r in g["readback"]["pairs"]
                          if w in self.names and r in self.names]
        if self.readbacks:
            self.kinds += ["readback"] * g["readback"]["weight"]
        self.scenarios = [tuple(s) for s in g["scenarios"]["list"] if self.written.can(s)]
        if self.scenarios:
            self.kinds += ["scenario"] * g["scenarios"]["weight"]
        self.tables = [s for idiom in g["tables"]["list"] for s in tabled(profile, idiom)
                       if self.written.can(s)]
        # every table value of every command, each a frame of its own
        self.tables += [(body,) for body in value_frames(profile, self.names)]
        if self.tables:
            self.kinds += ["tables"] * g["tables"]["weight"]
        # every input port (the GVE54's I0 too: its bits are read, none interrupts)
        self.ports = list(profile.input_ports) or [1]
        self.input_values = st.one_of(st.sampled_from([0xFF, 0xFE, 0x7F, 0x00, 0xFD]),
                                      st.integers(0, 255))
        self.member_names = [n for n, c in commands().items()
                             if c.packet == "member" and n in profile.commands]
        self.other_members = [n for n in g["packet"]["others"] if n in profile.commands]

    # -- pieces ----------------------------------------------------------------------------
    def pick(self, draw, choices) -> object:
        """One of ``choices`` (strategies built once: building one per draw is slow)."""
        key = ("pick", tuple(choices))
        if key not in self._cache:
            self._cache[key] = st.sampled_from(list(choices))
        return draw(self._cache[key])

    def number(self, draw, lo: int, hi: int) -> int:
        key = ("int", lo, hi)
        if key not in self._cache:
            self._cache[key] = st.integers(lo, hi)
        return draw(self._cache[key])

    def field(self, draw, kind: str, valid: bool) -> str:
        """A field: a valid value, now and then (unless ``valid``) an invalid form."""
        if not valid and self.number(draw, 0, 99) < self.invalid_chance:
            return draw(self.invalid[kind])
        return draw(self.valid[kind])

    def body(self, draw, name: str, *, valid: bool = False) -> str:
        entry = self.g["command"][name]
        kinds = entry.get("params", [])
        if kinds == ["vector"]:
            kinds = ["vector"] * self.pick(draw, self.vector_counts)
        params = [self.field(draw, k, valid) for k in kinds]
        body = _body(name, entry, params)
        if valid:
            return body
        inv = self.g["invalid"]
        roll = self.number(draw, 0, 99)
        if roll < inv["lower"] * 100:
            return body.lower()
        if roll < (inv["lower"] + inv["extra"]) * 100:
            extra = self.pick(draw, ["1", "0,0"])
            return body + (extra if not kinds else "," + extra)
        return body

    def frame(self, draw, name: str) -> list[Step]:
        entry = self.g["command"][name]
        fr = self.g["frames"]
        body = self.body(draw, name)
        roll = self.number(draw, 0, 99)
        checksum, address, stall = "auto", None, None
        if self.checksums and roll < fr["bad_checksum"] * 100:
            checksum = "bad"
        elif self.checksums and roll < (fr["bad_checksum"] + fr["no_checksum"]) * 100:
            checksum = "none"
        elif roll >= 100 - fr["other_address"] * 100:
            address = (self.profile.address + 1 + roll % 6) % 8
        elif roll >= 100 - (fr["other_address"] + fr["stall"]) * 100:
            stall = (self.number(draw, 2, 4), (self.profile.watchdog_ms + 50) / 1000)
        answer = entry.get("answer", True) and address is None
        out = [Step(FRAME, body, checksum, address, answer, entry.get("lines", 1), stall)]
        if entry.get("then_wait") == "restart":
            out.append(self.written.restart_wait())
        return out

    def packet(self, draw) -> list[Step]:
        pk = self.g["packet"]
        count = self.number(draw, 1, pk["members"])
        members = []
        for _ in range(count):
            other = self.number(draw, 0, 99) < pk["other_member"] * 100
            name = self.pick(draw, self.other_members if other else self.member_names)
            members.append(Step(FRAME, self.body(draw, name), answer=False))
        off = 0
        if self.number(draw, 0, 99) < pk["wrong_count"] * 100:
            off = self.pick(draw, [-1, 1])
        return [Step(FRAME, "*S", answer=False), *members,
                Step(FRAME, f"*E{max(count + off, 0)}")]

    def fill(self, draw) -> list[Step]:
        f = self.g["fill"]
        zeros = ",0" * (len(self.profile.axes) - 1)
        most = self.profile.buffer + 2
        # a queue many times `queue` vectors long is filled (to any count) as often as
        # filling it costs no more than a `queue`-long one does; else a few C are queued
        if self.number(draw, 0, max(0, most // f["queue"] - 1)) == 0:
            times = draw(st.one_of(st.integers(1, most), st.just(most)))
        else:
            times = self.number(draw, 1, f["queue"])
        return [Step(FILL, f"C{self.g['fill']['vector']}{zeros}", times=times)]

    def motion(self, draw) -> list[Step]:
        """A move watched: modal settings, vectors, then reads of where and how it runs."""
        return self.settings(draw) + self.vectors_drawn(draw) + self.reads(draw)

    def settings(self, draw) -> list[Step]:
        """Up to ``settings`` modal settings before a move: valid values, now and then one the
        unit must refuse (a field out of its range or of a wrong form, one parameter too
        many) or one sent to another address (the GVE114's spindle's): the move after it
        shows whether it was set all the same."""
        m, out = self.g["motion"], []
        for _ in range(self.number(draw, 0, m["settings"]) if self.modal else 0):
            name = self.pick(draw, self.modal)
            roll = self.number(draw, 0, 99)
            if roll < m["refused"] * 100:
                out.append(Step(FRAME, self.refused_body(draw, name)))
            elif roll < (m["refused"] + m["elsewhere"]) * 100:
                out.append(self.elsewhere(self.body(draw, name, valid=True)))
            else:
                out.append(Step(FRAME, self.body(draw, name, valid=True)))
        return out

    def refused_body(self, draw, name: str) -> str:
        """A frame of ``name`` the unit must refuse: one field in an invalid form (else,
        for a command without fields, one parameter too many)."""
        entry = self.g["command"][name]
        kinds = entry.get("params", [])
        if kinds == ["vector"]:
            kinds = ["vector"] * self.pick(draw, self.vector_counts)
        params = [draw(self.valid[k]) for k in kinds]
        if not kinds or self.number(draw, 0, 3) == 0:
            extra = self.pick(draw, ["1", "0,0"])
            body = _body(name, entry, params)
            return body + (extra if not kinds else "," + extra)
        i = self.number(draw, 0, len(kinds) - 1)
        # half the time just beyond an end of its range (what a unit that clamps keeps)
        beyond = self.beyond.get(kinds[i])
        params[i] = draw(beyond if beyond is not None and self.number(draw, 0, 1)
                         else self.invalid[kinds[i]])
        return _body(name, entry, params)

    def beside(self, draw, kind: str, place: str) -> str:
        """Another place of a read: the place with one bit of its number flipped (as a
        memory's address lines are tested: a unit that decodes one of them wrong reads
        the write there), else any place of its kind."""
        bounds = _range_of(self.profile, kind)
        head = kind.partition(":")[0]
        try:
            number = int(place, 16 if head == "hex" else 10)
        except ValueError:
            number = None
        if bounds is not None and number is not None and bounds[1] > 0:
            # the top bit first (shrinking towards it): the one a narrow decoder drops
            flipped = number ^ (1 << self.pick(draw, range(bounds[1].bit_length() - 1, -1, -1)))
            if bounds[0] <= flipped <= bounds[1]:
                return "%02X" % flipped if head == "hex" else str(flipped)
        return draw(self.valid[kind])

    def elsewhere(self, body: str) -> Step:
        """A frame to another address: the spindle's where the profile has one (answered
        by it), else one no unit answers."""
        spindle = self.profile.spindle
        if spindle is not None:
            return Step(FRAME, body, address=spindle.address)
        return Step(FRAME, body, address=(self.profile.address + 1) % 8, answer=False)

    def vectors_drawn(self, draw) -> list[Step]:
        """Up to ``vectors`` vectors with valid values; now and then one moving one axis
        alone (each axis, the GVE114's A too) or one of zero length."""
        m, out = self.g["motion"], []
        # now and then one command for all of them (C after C meet at junctions), and
        # then now and then one vector cut in pieces (each the same: the junctions at speed)
        joined = self.pick(draw, self.vectors) if self.number(draw, 0, 1) else None
        if joined is not None and self.number(draw, 0, 1):
            body = self.body(draw, joined, valid=True)
            return [Step(FRAME, body)] * self.number(draw, 2, m["vectors"])
        for _ in range(self.number(draw, 1, m["vectors"])):
            name = joined or self.pick(draw, self.vectors)
            roll = self.number(draw, 0, 99)
            if roll < m["alone"] * 100:
                count = self.pick(draw, self.vector_counts)
                axis = self.number(draw, 0, count - 1)
                size = draw(self.valid["vector"])
                body = self.g["command"][name].get("text", name) + ",".join(
                    size if i == axis else "0" for i in range(count))
                # moved, then read: whether it runs (RUN) shows an axis no read shows
                out.append(Step(FRAME, body))
                if self.states:
                    out.append(self.written.fixed(self.pick(draw, self.states)))
                continue
            elif roll < (m["alone"] + m["zero"]) * 100:
                count = self.pick(draw, self.vector_counts)
                body = self.g["command"][name].get("text", name) + ",".join("0" * count)
            else:
                body = self.body(draw, name, valid=True)
            out.append(Step(FRAME, body))
        return out

    def reads(self, draw) -> list[Step]:
        """Up to ``reads`` of: a position read, a wait, an event (a command acting on
        the motion), the status word or the flags (RUN: whether an axis no read shows
        moves)."""
        m, out = self.g["motion"], []
        waits = self.g["moves"]["waits"]
        for _ in range(self.number(draw, 1, m["reads"])):
            what = self.number(draw, 0, 3)
            if what == 0:
                out.append(Step(FRAME, "PF" if "PF" in self.profile.commands else "P"))
            elif what == 1:
                out.append(Step(WAIT, seconds=self.pick(draw, waits)))
            elif what == 2 and self.events:
                out.append(self.written.fixed(self.pick(draw, self.events)))
            elif what == 3 and self.states:
                out.append(self.written.fixed(self.pick(draw, self.states)))
        return out

    def group(self, draw) -> list[Step]:
        kind = self.pick(draw, self.kinds)
        if kind == "frame":
            return self.frame(draw, self.pick(draw, self.weighted))
        if kind == "wait":
            return [Step(WAIT, seconds=self.pick(draw, self.g["moves"]["waits"]))]
        if kind == "input":
            return self.input(draw)
        if kind == "packet":
            return self.packet(draw)
        if kind == "motion":
            return self.motion(draw)
        if kind == "readback":
            return self.readback(draw)
        if kind == "scenario":
            return self.scenario(draw)
        if kind == "power-on":
            return [Step(RIG, "power-on"), self.written.restart_wait()]
        if kind == "switch":
            return self.switch(draw)
        if kind == "spindle":
            return self.spindle(draw)
        if kind == "tables":
            return self.written.idiom(self.pick(draw, self.tables))
        return self.fill(draw)

    def input(self, draw) -> list[Step]:
        """A rig input set, now and then read back at once (the port's bits as set)."""
        port = self.pick(draw, self.ports)
        out = [Step(INPUT, port=port, value=draw(self.input_values))]
        if f"I{port}" in self.names and self.number(draw, 0, 1):
            out.append(self.written.fixed(f"I{port}"))
        return out

    def switch(self, draw) -> list[Step]:
        """A reference switch placed on an axis within W's travel from where the sequence
        began (its far side now and then), then a W on that axis (whether the run meets
        it, and where it zeroes), now and then the switch taken off again."""
        axis = self.pick(draw, self.switch_axes)
        travel = self.g["moves"]["travel"]
        where = self.number(draw, -2 * travel, 2 * travel)
        entry = self.g["command"]["W"]
        kinds = entry["params"][1:]
        w = _body("W", entry, [axis, *(draw(self.valid[k]) for k in kinds)])
        out = [Step(RIG, f"switch {axis} {where}"), self.written.fixed(w)]
        if self.number(draw, 0, 1):
            out.append(Step(RIG, f"switch {axis} none"))
        return out

    def spindle(self, draw) -> list[Step]:
        """A frame to the spindle's address (spec 12): a command it serves, drawn as at the
        unit's own address (`V` a setting of the spindle's range), now and then one it does
        not serve (answered 3 [D]); a write read back at once, at either address; else now
        and then a read at the unit's own address of what the spindle's frame may have
        changed there (`after`)."""
        sp = self.g["spindle"]
        at = self.profile.spindle.address
        others = self.spindle_others and self.number(draw, 0, 99) < sp["others"] * 100
        name = self.pick(draw, self.spindle_others if others else self.spindle_names)
        if name == "V" and self.number(draw, 0, 99) >= self.invalid_chance:
            body = "V" + draw(self.spindle_values)
        else:
            body = self.body(draw, name)
        out = [replace(self.written.fixed(body), address=at)]
        if self.g["command"][name].get("then_wait") == "restart":
            out.append(self.written.restart_wait())
        reader = dict(self.readbacks).get(name)
        if reader is not None:
            text = self.g["command"][name].get("text", name)
            place = body[len(text):].split(",")[0]
            read = self.written.fixed(self.g["command"][reader].get("text", reader) + place)
            out.append(replace(read, address=at) if self.number(draw, 0, 1) else read)
        elif self.number(draw, 0, 1):
            out.append(self.written.fixed(self.pick(draw, [n for n in sp["after"]
                                                  if n in self.profile.commands])))
        return out

    def scenario(self, draw) -> list[Step]:
        """An idiom drawn whole, a move before it now and then, and now and then the reads
        of a move after it (what it left running shows while it runs)."""
        out = []
        if self.vectors and self.number(draw, 0, 1):
            out.append(Step(FRAME, self.body(draw, self.pick(draw, self.vectors), valid=True)))
        out += self.written.idiom(self.pick(draw, self.scenarios))
        return out + (self.reads(draw) if self.number(draw, 0, 1) else [])

    def idiom(self, lines: list[str] | tuple[str, ...]) -> list[Step]:
        """The steps of an idiom (written.py)."""
        return self.written.idiom(lines)

    def probes(self) -> list[tuple[dict, list[Step]]]:
        """The probes this profile and run can send, with their steps (written.py)."""
        return self.written.probes()

    def sweep(self) -> list[list[Step]]:
        """The grammar's tables run whole once (written.py)."""
        return self.written.sweep(self.tables)

    def sequences(self) -> st.SearchStrategy[list[Step]]:
        """A sequence of steps for one example (groups flattened)."""
        group = st.composite(lambda draw: self.group(draw))()
        return st.lists(group, min_size=1, max_size=self.g["steps"]["max"]).map(
            lambda gs: [s for grp in gs for s in grp])

    def readback(self, draw) -> list[Step]:
        """A write read back at once: the place written, and now and then another place
        of the same read (a unit that decodes its places too narrowly wrote that one);
        the write now and then one the unit must refuse (it must store nothing)."""
        rb = self.g["readback"]
        write, read = self.pick(draw, self.readbacks)
        if self.number(draw, 0, 99) < rb["refused"] * 100:
            body = self.refused_body(draw, write)
        else:
            body = self.body(draw, write, valid=True)
        text = self.g["command"][write].get("text", write)
        reader = self.g["command"][read]
        first = body[len(text):].split(",")[0]
        places = [first]
        kinds = reader.get("params", [])
        if kinds and self.number(draw, 0, 99) < rb["elsewhere"] * 100:
            places.append(self.beside(draw, kinds[0], first))
        return [Step(FRAME, body)] + [
            Step(FRAME, reader.get("text", read) + ("" if read == "PF" else place))
            for place in places]


#: the field kinds whose values are a range's ends (the others have no table)
_ENDS = ("range", "dec", "hex")
#: a fixed range of fewer values than this: each of them
SMALL = 8
#: a field's value where another field of the frame is the one at an end of its table
_PLAIN = {"vector": "0", "travel": "100", "seek-rate": "1000", "float": "1.5"}


def table_values(profile: Profile, kind: str) -> list[str]:
    """The table values of a field kind (what `diff` counts it reached, and draws each
    of through `[tables]`): a range's two ends (each value of a range of a few), each
    word, each axis; none for the kinds drawn otherwise (short moves and travels, a
    travel's rates, floats)."""
    head, _, rest = kind.partition(":")
    if head == "choice":
        return rest.split("|")
    if head == "axis":
        return list(profile.axes)
    if head not in _ENDS:
        return []
    if head == "range":
        if rest not in profile.ranges:
            return []
        r = profile.range(rest)
        return [str(r.lo), str(r.hi)]
    lo, hi = (int(x) for x in rest.split(":"))
    # a few values (a status word's number, the one output port): each; else the ends
    values = range(lo, hi + 1) if hi - lo < SMALL else (lo, hi)
    return ["%02X" % v if head == "hex" else str(v) for v in values]


def value_frames(profile: Profile, names: list[str]) -> list[str]:
    """A frame for each table value of each command in ``names``: that field at the
    value, the others at their table's first value (or a plain one)."""
    g = load_grammar()
    out = []
    for name in names:
        entry = g["command"][name]
        kinds = entry.get("params", []) if entry.get("tables", True) else []
        plain = [(table_values(profile, k) or [_PLAIN.get(k, "0")])[0] for k in kinds]
        for i, kind in enumerate(kinds):
            for value in table_values(profile, kind):
                out.append(_body(name, entry, [*plain[:i], value, *plain[i + 1:]]))
    return list(dict.fromkeys(out))


def probes(profile: Profile, options: Options) -> list[tuple[dict, list[Step]]]:
    """The probes the search runs whole before it draws a sequence (``probes.toml``)."""
    return Grammar(profile, options).probes()


def sequences(profile: Profile, options: Options) -> st.SearchStrategy[list[Step]]:
    """A sequence of steps for one example (groups flattened)."""
    return Grammar(profile, options).sequences()
