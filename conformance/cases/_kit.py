"""Small helpers the directed cases share."""

from __future__ import annotations

import math
from collections.abc import Callable

from conformance.case.context import CaseContext, case
from conformance.case.preconditions import feature
from conformance.link.account import Spent
from conformance.link.framing import Response
from conformance.link.link import MARGIN
from conformance.motion.probe import Probe
from conformance.verdicts.quoting import answer_text
from gve_fixtures.protocol import ErrorCode


def show(r: Response | None) -> str:
    """An answer in a message, as checks write it (``8,D0``: without its final CR)."""
    return "nothing" if r is None else answer_text(r.raw)


def answers(ctx: CaseContext, r: Response | None, text: str, what: str, *,
            tag: str | None = None, rule: str | None = None) -> bool:
    """Expect the answer's exact bytes (``text`` without the final CR)."""
    return ctx.expect(r is not None and r.raw == text.encode() + b"\r", what,
                      observed=r, expected=text, tag=tag, rule=rule)


def code_text(value: int, inta: bool | None = None) -> str:
    """A response code as every check writes it: ``code 5``; ``code 5, INTA set`` where
    the check judges the INTA bit (the answer's first digit then reads D)."""
    return f"code {value}" + ("" if inta is None else f", INTA {'set' if inta else 'clear'}")


def code(ctx: CaseContext, r: Response | None, value: ErrorCode, what: str, *,
         tag: str | None = None, inta: bool | None = None, rule: str | None = None) -> bool:
    ok = r is not None and r.code == value and (inta is None or r.inta == inta)
    seen = (r if r is None or r.code is None
            else code_text(r.code, None if inta is None else bool(r.inta)))
    return ctx.expect(ok, what, observed=seen, expected=code_text(int(value), inta), tag=tag,
                      rule=rule)


def refused_beyond_ff(ctx: CaseContext, r: Response | None, what: str, *,
                      rule: str) -> None:
    """A hex field one beyond FF (`100`): refused under ``rule`` by every reading (the
    manuals write hex fields 00..FF, so three digits may be a syntax error, 4), and 5, a
    value range-checked, as 3.params.hex-digits decides."""
    ctx.expect(r is not None and r.code in (ErrorCode.SYNTAX, ErrorCode.RANGE),
               f"{what}: refused", observed=show(r), expected="code 5 (or 4: three hex digits)",
               rule=rule)
    code(ctx, r, ErrorCode.RANGE, f"{what}: three hex digits range-checked → 5",
         rule="3.params.hex-digits")


def vector(ctx: CaseContext, x: int, y: int = 0, z: int = 0) -> str:
    """The parameters of an L/C vector for the profile's axes."""
    return f"{x},{y},{z}"


def finished(ctx: CaseContext, seconds: float,
             until: Callable[[Response], bool] = lambda r: r.ok) -> Response | None:
    """The manual's wait until everything queued has run: `L0,0,0` until ``until`` its
    answer (taken only once everything before it has finished, spec 10.1 [M]), then, once
    it is taken, `SR6` until RUN = 0 (spec 10.3 [M]) for at most the longest T dwell and
    the line's margin: to a reader of "program považuje za normální vektor" `L0,0,0` is a
    normal vector, whose T dwell may hold RUN after it (N, M, R, D, L refused meanwhile).
    The answer to the last `L0,0,0` (None: none in time)."""
    link = ctx.link
    r = link.poll("L" + vector(ctx, 0), until, seconds)
    if r is not None and r.ok:
        link.wait_idle(ctx.profile.range("T").hi / 1000 + 2 * MARGIN)
    return r


def setup(ctx: CaseContext, body: str, expect: str | tuple[str, ...] = "0",
          **kw) -> Response | None:
    """A setup step: if it does not answer as expected (one of ``expect``, where the
    manuals allow several answers) the case cannot judge."""
    r = ctx.link.send(body, **kw)
    allowed = (expect,) if isinstance(expect, str) else expect
    ctx.require(r is not None and r.raw.split(b",")[0].rstrip(b"\r").decode(
                    "ascii", "replace") in allowed,
                f"setup {body} answered {show(r)}, expected {' or '.join(allowed)}")
    return r


def configured(ctx: CaseContext, name: str, *, required: bool = True) -> bool:
    """Setup: the feature ``name`` configured as its manual requires before a case relies
    on it (conformance/case/preconditions.toml): every parameter it names read, and one the
    manual does not allow written and read back (EEPROM: needs --allow-destructive; the
    session puts the bytes back after the case). COULD-NOT-TEST where a write is needed
    and not allowed, or does not take; not ``required``, a write that is not allowed
    leaves the unit as it is and the answer is False (the case grades what it then sees
    as a reading)."""
    f = feature(name)
    wrote = False
    for p in f.params_for(ctx.profile):
        r = ctx.link.send(p.read())
        if r is not None and r.ok and p.holds(r.values):
            continue
        if not required and not ctx.target.allow_destructive:
            return False
        ctx.require(ctx.target.allow_destructive,
                    f"{f.name} needs {p.shown} ({f.source}); it reads {show(r)}, and "
                    "writing it needs --allow-destructive")
        setup(ctx, p.write())
        wrote = True
        r = ctx.link.send(p.read())
        ctx.require(r is not None and r.ok and p.holds(r.values),
                    f"{f.name} needs {p.shown}: {p.write()} was taken, yet it reads {show(r)}")
    if wrote and "J" in ctx.profile.commands:
        # the manuals do not say when an EEPROM value takes effect: a reader may read its
        # settings at reset only (as M114 10.1 says of the switches), so J applies them
        setup(ctx, "J")
        # the unit is ready again after about 2 s (spec 2, M84 12.4)
        ctx.link.wait(ctx.profile.restart_ms / 1000 + 0.5, Spent.MANUAL)
    return True


def still_seconds(ctx: CaseContext) -> float:
    """How long a case watches for a motion that must not happen (a vector refused,
    deleted, held): a vector a unit took would begin within the longest dwell T (spec 10,
    M84 12.5.2: at most 24 ms) and make its first step from rest within sqrt(2/A) at the
    slowest acceleration the ranges allow (A in thousands of pulses/s^2: 45 ms at A1),
    read after the line's margin."""
    dwell = ctx.profile.range("T").hi / 1000
    first_step = math.sqrt(2 / (ctx.profile.range("A").lo * 1000.0))
    return dwell + first_step + MARGIN


def halted_with_queue(ctx: CaseContext, vectors: int = 3, steps: int = 330) -> None:
    """Setup: CONT vectors queued and running, then HALT (INTA = 1, RUN = 1): halted half
    a second into the first vector (at V500 about 250 steps), the rest queued. The
    vectors stay within the default envelope (2000 full steps) even counted twice, as a
    real unit's guard counts a queue kept with K and restored with R."""
    setup(ctx, "V500")
    for _ in range(vectors):
        setup(ctx, "C" + vector(ctx, steps))
    ctx.link.wait(0.5, Spent.MOTION)
    r = ctx.link.send("H")
    ctx.require(r is not None and r.ok and r.inta, f"H answered {show(r)}")


def halted_line(ctx: CaseContext, steps: int, seconds: float) -> None:
    """Setup: an L of ``steps`` along X halted after ``seconds`` (INTA = 1, RUN = 1)."""
    setup(ctx, "L" + vector(ctx, steps))
    ctx.link.wait(seconds, Spent.MOTION)
    r = ctx.link.send("H")
    ctx.require(r is not None and r.inta, f"H answered {show(r)}")


def fresh_reset(ctx: CaseContext) -> None:
    """Cases about the state right after a reset: the emulator gives a fresh unit; a real
    unit is restarted with J, which needs --allow-destructive."""
    if not ctx.target.real:
        return
    ctx.require(ctx.target.allow_destructive, "needs a reset (J): run with --allow-destructive")
    r = ctx.link.send("J")
    ctx.require(r is not None and r.ok, f"J answered {show(r)}")
    ctx.link.wait(2.5, Spent.MANUAL)             # ready about 2 s after J (spec 2)


def queries_counted(ctx: CaseContext, address: int | None = None) -> bool:
    """Whether the unit's ``@`` advances its own index: the manuals leave what counts
    open (8.index.queries-uncounted [D]), so a case measures it once (two ``@`` in a
    row) and judges only the frames it sent."""
    key = ("queries-counted", address, id(ctx.link))
    if key not in ctx.measured:
        a, b = _read_index(ctx, address), _read_index(ctx, address)
        ctx.measured[key] = a is not None and b == (a + 1) % 256
    return ctx.measured[key]


def _read_index(ctx: CaseContext, address: int | None) -> int | None:
    return ctx.link.read_index(address)


def index(ctx: CaseContext, address: int | None = None) -> int | None:
    """The index as ``@`` reads it (at ``address``; default the link's): on a real unit
    it is wherever the unit's use left it, so cases judge how far it moves."""
    queries_counted(ctx, address)
    return ctx.link.read_index(address)


def index_moved(ctx: CaseContext, before: int | None, frames: int, what: str, *,
                tag: str | None = None, rule: str | None = None,
                address: int | None = None, queries: bool = False) -> bool:
    """Expect the index to have advanced by ``frames`` since ``before`` (spec 8), the
    reading ``@`` itself not counted on a unit whose ``@`` counts (``queries``: the
    check judges that very point, so nothing is taken off)."""
    counted = queries_counted(ctx, address) and not queries
    after = index(ctx, address)
    expected = None if before is None else (before + frames + counted) % 256
    return ctx.expect(after is not None and after == expected, what, observed=after,
                      expected=expected, tag=tag, rule=rule)


def fill_queue(ctx: CaseContext, count: int | None = None, *,
               rule: str | None = None) -> bool:
    """Setup: stop the unit (H, so INTA = 1 and vectors wait in the queue [D 10.1]) and
    queue ``count`` (default: the buffer's size) one-step vectors going back and forth,
    so that a real unit's axes stay within the envelope. Returns whether every vector
    was accepted; records a check per refusal."""
    r = ctx.link.send("H")
    ctx.require(r is not None and r.inta, f"H answered {show(r)}")
    for i in range(ctx.profile.buffer if count is None else count):
        r = ctx.link.send("C" + vector(ctx, 1 if i % 2 == 0 else -1))
        if not ctx.expect(r is not None and r.ok, f"vector {i + 1} is accepted",
                          observed=r if r is None or r.code is None
                          else code_text(r.code), expected=code_text(0), rule=rule):
            return False
    return True


def position(ctx: CaseContext) -> list[int] | None:
    r = ctx.link.send("PF")
    if r is None or not r.ok or len(r.values) < 3:
        return None
    return r.decs()


def step_factor(ctx: CaseContext) -> int:
    """Counter units per commanded step in the micro-step mode a case starts in (the
    reset's: GVE54 MF, one sixteenth; 1 where there is no micro-stepping)."""
    m = ctx.profile.microstep
    return 1 if m is None else m.factors[m.reset_mode]


def fill_scenario(step, ctx: CaseContext):
    """The scenario's placeholders: ``{max}`` the variant's maximum rate, ``{max10}`` a
    tenth of it, ``{xm}`` an override doubling V where the profile has XM."""
    if not isinstance(step, str):
        return step
    rate = ctx.profile.max_rate
    return step.format(max=rate, max10=rate // 10, xm="XM200" * ("XM" in ctx.profile.commands))


def measured_case(id: str, rules: tuple[str, ...], requires: tuple[str, ...],
                  families: tuple[str, ...], scenario: list) -> None:
    """Register the case ``id`` of the motion measured. Each case runs a short scenario,
    reads ``PF`` at known instants and judges every reading against the suite's own model of
    spec 10.2 (conformance/motion), with the tolerance printed in each check: zero on the
    embedded emulator's virtual clock (and not printed); on serial and TCP targets the window
    in which the unit processed each frame, widened by the line's band (from the round trip
    measured at the session's start and the scenario's own, conformance/link/line_band.py),
    and one step: a position read at rest after an override, a HALT or a micro-step change is
    judged with what the event's instant so widened can change (``±1.8 ms line, ±7 steps``).

    A scenario is a list: a frame to send, seconds to sample ``PF`` for (every 50 ms, or a
    pair: seconds and how often), or a position (in commanded steps) to poll ``PF`` until."""
    placement = "10.2.motion.step-placement"     # the probe's grade of another placement
    every = rules if placement in rules else (*rules, placement)

    @case(id, rules=every, requires=requires, timing=True,
          applies=(lambda p: p.family in families) if families else None)
    def measured(ctx: CaseContext) -> None:
        steps = (fill_scenario(s, ctx) for s in scenario)
        Probe(ctx, id, rules[0]).script([s for s in steps if s])
