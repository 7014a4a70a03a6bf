"""Cases: the @case decorator, the registry, and the context a case runs in
(docs/suite.md). A case records checks; the runner grades them."""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from conformance.link.link import Link
from conformance.link.stops import SafetyStop
from conformance.targets.info import TargetInfo
from conformance.verdicts.check import Check
from conformance.verdicts.quoting import as_text
from conformance.verdicts.verdict import CouldNotTest
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import TAGS
from gve_fixtures.rules import load_rules

__all__ = ["REGISTRY", "Case", "CaseContext", "Check", "CouldNotTest", "Missing",
           "SafetyStop", "TargetInfo", "case"]


class Missing(Exception):
    """The profile lacks what the case checks."""


@dataclass(frozen=True)
class Case:
    id: str
    func: Callable[[CaseContext], None]
    rule: str
    tag: str
    source: str
    requires: tuple[str, ...] = ()
    absent: tuple[str, ...] = ()
    applies: Callable[[Profile], bool] | None = None
    rig: bool = False
    destructive: bool = False
    timing: bool = False
    rules: tuple[str, ...] = ()      # IDs of fixtures/rules.toml this case can fail
    hands: bool = False              # needs a hand on the machine: the rig or an operator

    @property
    def section(self) -> str:
        m = re.match(r"\d+(?:\.\d+)*", self.id)
        return m.group(0) if m else self.id.split(".")[0]

    def missing_for(self, profile: Profile) -> str | None:
        """Why the case does not apply to ``profile`` (None when it does)."""
        lacking = [c for c in self.requires if c not in profile.commands]
        if lacking:
            return f"the profile lacks {', '.join(lacking)}"
        present = [c for c in self.absent if c in profile.commands]
        if present:
            return f"checks the refusal of {', '.join(present)}, which the profile has"
        if self.applies is not None and not self.applies(profile):
            return "does not apply to this profile"
        return None


REGISTRY: dict[str, Case] = {}

#: how a tag grades: M and M-ex alike (a golden example is a manual's statement too)
GRADES = {"M": "M", "M-ex": "M", "D": "D", "D-info": "D-info"}


def case(id: str, *, rules: tuple[str, ...], tag: str | None = None,
         requires: tuple[str, ...] = (), absent: tuple[str, ...] = (),
         applies: Callable[[Profile], bool] | None = None, rig: bool = False,
         destructive: bool = False, timing: bool = False, hands: bool = False):
    """Register a case (see docs/suite.md). Its requirement is that of the rules it names
    in fixtures/rules.toml, never written again: the first rule's text and tag, and the
    sources of all of them. ``tag`` only picks another grade among the rules' (a case
    that fails as [M] on a [D] first rule); what a case does beyond its rules is its
    function's docstring."""
    known = load_rules()
    if not rules:
        raise ValueError(f"{id}: name its rules (see fixtures/rules.toml)")
    unknown = [r for r in rules if r not in known]
    if unknown:
        raise ValueError(f"{id}: unknown rule(s) {unknown} (see fixtures/rules.toml)")
    first = known[rules[0]]
    if tag is not None and tag not in TAGS:
        raise ValueError(f"{id}: tag must be one of {', '.join(TAGS)}")
    if tag == first.tag:
        raise ValueError(f"{id}: tag {tag} restates its first rule's; leave it out")
    graded = {GRADES[known[r].tag] for r in rules}
    if tag is not None and GRADES[tag] not in graded:
        raise ValueError(f"{id}: declared tag {tag} contradicts its rules, tagged "
                         f"{', '.join(sorted({known[r].tag for r in rules}))}")
    rule, tag = first.text, first.tag if tag is None else tag
    source = "; ".join(dict.fromkeys(known[r].source for r in rules))

    def register(func: Callable[[CaseContext], None]) -> Callable[[CaseContext], None]:
        old = REGISTRY.get(id)
        # the same function imported again (a module reloaded, as pytester does) replaces
        # its entry; two different functions under one ID are a defect
        if old is not None and (old.func.__module__, old.func.__qualname__) != (
                func.__module__, func.__qualname__):
            raise ValueError(f"case {id} is registered twice")
        REGISTRY[id] = Case(id, func, rule, tag, source, tuple(requires), tuple(absent),
                            applies, rig, destructive, timing, tuple(rules), hands)
        return func
    return register


@dataclass
class CaseContext:
    case: Case
    profile: Profile
    target: TargetInfo
    settings: Any
    _open_link: Callable[..., Link]
    checks: list[Check] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    artifacts: dict[str, str] = field(default_factory=dict)
    traces: list[dict] = field(default_factory=list)
    links: list[Link] = field(default_factory=list)
    _link: Link | None = None
    seed: int | None = None      # the run's seed for the Hypothesis machines (None: settings)
    operator: Any = None         # conformance.operator.hands.Hands: hand steps (rig or technician)
    #: what the case measured of the unit's readings once (e.g. whether @ counts itself)
    measured: dict[Any, Any] = field(default_factory=dict)

    @property
    def link(self) -> Link:
        if self._link is None:
            self._link = self.fresh_link()
        return self._link

    def fresh_link(self, address: int | None = None) -> Link:
        """A new link in the known state (on the emulator: a new unit, at ``address``
        when given)."""
        link = self._open_link(address)
        if self._link is not None:
            self._link.superseded = True
            link.index_form = self._link.index_form     # the unit's, once measured
        self.links.append(link)
        self._link = link
        return link

    def expect(self, ok: bool, what: str, *, observed: Any = None, expected: Any = None,
               tag: str | None = None, rule: str | None = None,
               machinery: bool = False) -> bool:
        """Record one check of ``rule``, graded by that rule's tag. ``rule`` is one of the
        case's ``rules``, and may be left out only when the case names one; with
        ``machinery`` it is a rule of the link or of a machine's bookkeeping that the
        case does not list (a second answer, a position read). ``tag`` overrides the
        grade (``"always"``: a crash-class failure whatever the rule). A check that
        names no rule is a defect of the suite: a failure would be graded by nothing
        the spec says."""
        known = load_rules()
        if rule is not None and rule not in self.case.rules and not (
                machinery and rule in known):
            raise ValueError(f"{self.case.id}: a check names {rule!r}, which the case does "
                             f"not list in its rules")
        if rule is None and len(self.case.rules) == 1:
            rule = self.case.rules[0]
        if rule is None:
            raise ValueError(f"{self.case.id}: a check ({what!r}) must name its rule: the "
                             f"case has {len(self.case.rules)}")
        graded = tag or known[rule].tag
        self.checks.append(Check(bool(ok), what, as_text(observed), as_text(expected),
                                 graded, rule))
        return bool(ok)

    def expect_equal(self, observed: Any, expected: Any, what: str, *,
                     tag: str | None = None, rule: str | None = None,
                     machinery: bool = False) -> bool:
        """Record one check that ``observed`` equals ``expected``, as :meth:`expect` does:
        the value judged is the value reported, read once by the caller (a second read,
        e.g. a second `PF` of a moving unit, may differ from the one judged)."""
        return self.expect(observed == expected, what, observed=observed, expected=expected,
                           tag=tag, rule=rule, machinery=machinery)

    def require(self, ok: bool, why: str) -> None:
        if not ok:
            raise CouldNotTest(why)

    def note(self, text: str) -> None:
        self.notes.append(text)

    def artifact(self, name: str, text: str) -> None:
        self.artifacts[name] = text

    def step_train(self, name: str) -> None:
        """Record the pulses per axis the emulator's stepper core gave on the current link
        so far, for the reports (through the test rig; nothing on a real unit, nor through
        a simulator's control channel, which gives no pulses)."""
        rig = self.link.rig
        if rig is None or not hasattr(rig, "pulses"):
            return
        origin = rig.now - self.link.now            # the link's instant 0 on the rig's clock
        pulses = [[(t - origin) / 1e9, mask] for t, mask in rig.pulses(origin)]
        self.traces.append({"name": name, "pulses": pulses, "total": len(pulses),
                            "axes": list(self.profile.axes)})

    def trace(self, name: str, *, samples: list[tuple[float, list[int]]],
              model: list[tuple[float, list[int]]], tolerance: dict[str, float],
              params: dict[str, Any], faults: list[dict] | None = None) -> None:
        """Record a motion trace for the reports: ``samples`` as read from the target
        (seconds since the motion's origin, positions per axis), ``model`` the spec
        model's positions at those or denser instants, ``tolerance`` the band the check
        used (``seconds``, ``steps``), ``params`` the parameters (A, V, B, T, XM...),
        ``faults`` what the checks found wrong, to be marked on the picture: an instant
        (``{"kind": "instant", "what", "observed": t, "expected": [t_lo, t_hi],
        "expected_what"}``) or a reading (``{"kind": "position", "t", "axis",
        "observed": steps, "expected": [lo, hi]}``)."""
        self.traces.append({"name": name,
                            "samples": [[float(t), [int(p) for p in ps]] for t, ps in samples],
                            "model": [[float(t), [int(p) for p in ps]] for t, ps in model],
                            "tolerance": dict(tolerance), "params": dict(params),
                            **({"faults": list(faults)} if faults else {})})
