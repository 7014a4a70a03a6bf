"""Spec section 2, Link: the line rate a unit chooses itself (M114 10.1, 13.3; M54 SERIE).

Every rate the profile lists is reached the way the manual chooses it: the rig's rate
switch (the GVE114's COM SPEED sw1/sw2, the GVE54's jumpers) and, on the GVE114, the range
byte EEPROM 0D, then a power cycle, the host following to the rate the table gives. A
change of rate must never lose the unit: every case puts the switch, the range byte and
the host's rate back as found and verifies the unit at its first rate, searching the
profile's every rate for it when it is not where the table says. A GVE84's rate is fixed
at order time (M84 12.3): the cases do not apply to it."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from conformance.case.context import CaseContext, case
from conformance.cases._kit import answers, setup, show
from conformance.link.account import Spent
from gve_fixtures.profile import BaudChoice


def _switchable(profile) -> bool:
    return profile.baud is not None


def _choice(ctx: CaseContext) -> BaudChoice:
    """The profile's rate table, once the case can move the unit's rate and follow it."""
    rig = ctx.link.rig
    ctx.require(rig is not None and hasattr(rig, "set_rate_switch"),
                "it needs the rig's rate switch and power cycle (docs/rig.md `rate`, "
                "`power-on`); a technician's run sets the rate once, before power-on "
                "(each rate by its own run, `?baud=`)")
    # the host's rate reaches the unit only where the link's far end is the line itself
    # (the embedded emulator, a co-simulation's `baud N`); a pty or TCP carries no rate
    ctx.require(getattr(ctx.link.port, "line", None) is not None,
                f"the host cannot change the line's rate through this {ctx.target.kind}: "
                "target (a pty or TCP carries no rate to the unit)")
    # the switch set where it stands: a rig without the `rate` command says so here,
    # before anything was changed
    rig.set_rate_switch(_found_position(rig))
    return ctx.profile.baud


def _found_position(rig) -> int | None:
    """The rate switch's position as the rig's state gives it (None: never set)."""
    found = rig.state().get("rate_position")
    return found if isinstance(found, int) and not isinstance(found, bool) else None


def _host_rate(ctx: CaseContext, baud: int) -> None:
    ctx.link.port.baudrate = baud
    ctx.link.baud = baud


def _answers_at(ctx: CaseContext, baud: int) -> bool:
    """Whether the unit answers `?` with the host at ``baud`` (the host stays there)."""
    _host_rate(ctx, baud)
    ctx.link.port.reset_input_buffer()
    r = ctx.link.send("?")
    return r is not None and r.ok


def _restart(ctx: CaseContext, how: str) -> None:
    if how == "J":
        ctx.link.send("J")
    else:
        ctx.link.rig.power_on()
    ctx.link.wait(ctx.profile.restart_ms / 1000 + 0.5, Spent.MANUAL)


def _range_byte(ctx: CaseContext) -> int | None:
    choice = ctx.profile.baud
    if choice.range_address is None:
        return None
    r = ctx.link.send("ER%02X" % choice.range_address)
    ctx.require(r is not None and r.ok and len(r.values) == 1,
                f"ER{choice.range_address:02X} (the rate range) answered {show(r)}")
    return r.hex()


def _find(ctx: CaseContext, first: int) -> int | None:
    """The rate the unit answers at: the one the rig's state says it read, if it says,
    else ``first``, else each rate the profile lists."""
    told = ctx.link.rig.state().get("rate")
    told = (told,) if isinstance(told, int) and told in ctx.profile.bauds else ()
    for baud in dict.fromkeys((*told, first, *ctx.profile.bauds)):
        if _answers_at(ctx, baud):
            return baud
    return None


@contextmanager
def _as_found(ctx: CaseContext) -> Iterator[int | None]:
    """The unit's rate, switch and range byte put back as found after the body, whatever
    the body did: the unit is found at whatever rate it answers, its range byte written
    back, the switch set back, the power cycled, and the unit verified at the host's
    first rate. Gives the range byte as found."""
    choice = _choice(ctx)
    start, rig = ctx.link.baud, ctx.link.rig
    found = _found_position(rig)
    code = _range_byte(ctx)
    try:
        yield code
    finally:
        here = _find(ctx, ctx.link.baud)
        if here is not None and code is not None:
            _host_rate(ctx, here)
            ctx.link.send("EW%02X,%02X" % (choice.range_address, code))
        rig.set_rate_switch(found)
        _restart(ctx, "power-on")
        back = _answers_at(ctx, start)
        ctx.expect(back, f"the switch{' and the range byte' * (code is not None)} put "
                   f"back and the power cycled: the unit answers at {start} again",
                   observed=f"it answers at {here}" if not back else "it answers",
                   expected=f"? answered at {start}", rule="2.link.rate-by-switch")
        if not back:
            _find(ctx, start)
        elif code is not None:
            answers(ctx, ctx.link.send("ER%02X" % choice.range_address), "0,%02X" % code,
                    f"EEPROM {choice.range_address:02X} restored", rule="10.cmd.eeprom-bytes")


def _power_at(ctx: CaseContext, position: int, baud: int, what: str,
              rule: str) -> int | None:
    """The switch to ``position``, a power cycle: the unit answers at ``baud``. Where the
    profile's table of positions is ours, not the manual's, a unit found at another rate
    of the list is graded by the table's own [D] rule and followed there. Gives the rate
    the unit answers at (None: not found)."""
    ctx.link.rig.set_rate_switch(position)
    _restart(ctx, "power-on")
    table_rule = ctx.profile.baud.table_rule
    ok = _answers_at(ctx, baud)
    here = baud if ok else (_find(ctx, baud) if table_rule else None)
    ctx.expect(ok, f"{what}: after power-on the unit answers at {baud}",
               observed="it answers" if ok else
               "no answer at that rate" if here is None else f"it answers at {here}",
               expected=f"? answered at {baud}",
               rule=rule if ok or here is None else table_rule)
    return here


def _write_range(ctx: CaseContext, code: int) -> None:
    address = ctx.profile.baud.range_address
    setup(ctx, "EW%02X,%02X" % (address, code))
    answers(ctx, ctx.link.send("ER%02X" % address), "0,%02X" % code,
            f"EEPROM {address:02X} reads back {code:02X}", rule="10.cmd.eeprom-bytes")


def _shown(choice: BaudChoice, position: int, code: int | None) -> str:
    where = f"switch {choice.positions[position]}"
    return where if code is None else f"EEPROM {choice.range_address:02X} = {code:02X}, {where}"


@case("2.link.rate.every-listed-rate", rig=True, destructive=True, applies=_switchable,
      rules=("2.link.rate-by-switch", "10.cmd.eeprom-bytes", "2.link.rate-jumper-table"))
def every_rate(ctx: CaseContext) -> None:
    """Every range the range byte lists, every position of the switch: the unit, power
    cycled, answers at the rate the manual's table gives (each rate the profile lists is
    reached), then is put back as found."""
    with _as_found(ctx):
        choice = ctx.profile.baud
        for code in sorted(choice.ranges, key=lambda c: -1 if c is None else c):
            if code is not None:
                _write_range(ctx, code)
            reached = set()
            for position in range(len(choice.positions)):
                baud = choice.rate(position, code)
                here = _power_at(ctx, position, baud, _shown(choice, position, code),
                                 "2.link.rate-by-switch")
                if here is None:
                    ctx.require(_find(ctx, baud) is not None,
                                "the unit answers at none of the profile's rates")
                reached.add(here)
            if choice.table_rule and None not in reached:
                # whatever the table, the jumpers select the rate: not one rate for all
                ctx.expect(len(reached) > 1, "the positions select more than one rate",
                           observed=f"{len(reached)} rate(s): "
                                    f"{', '.join(map(str, sorted(reached)))}",
                           expected="different rates", rule="2.link.rate-by-switch")


@case("2.link.rate.read-at-power-on", rig=True, destructive=True, applies=_switchable,
      rules=("2.link.rate-read-at-power-on", "2.link.rate-range-at-restart",
             "2.link.rate-by-switch", "10.cmd.eeprom-bytes", "2.link.rate-jumper-table"))
def read_at_power_on(ctx: CaseContext) -> None:
    """The switch moved after power-on does not change the rate at `J`; on the GVE114
    neither does EEPROM 0D written before `J` [D]: only the next power-on reads them."""
    choice = ctx.profile.baud
    default = choice.unlisted_range              # the range as shipped (GVE114: FF)
    first, last = 0, len(choice.positions) - 1
    with _as_found(ctx):
        if default is not None:
            _write_range(ctx, default)
        expected = choice.rate(first, default)
        baud = _power_at(ctx, first, expected, _shown(choice, first, default),
                         "2.link.rate-by-switch")
        ctx.require(baud is not None, f"the unit does not answer at {expected} after power-on")
        ctx.link.rig.set_rate_switch(last)
        _restart(ctx, "J")
        ok = _answers_at(ctx, baud)
        ctx.expect(ok, f"switch moved to {choice.positions[last]}, then J: the unit still "
                   f"answers at {baud}", observed="it answers" if ok else "no answer",
                   expected=f"? answered at {baud}", rule="2.link.rate-read-at-power-on")
        if not ok:
            ctx.require(_find(ctx, baud) is not None,
                        "the unit answers at none of the profile's rates")
            return
        ctx.link.rig.set_rate_switch(first)
        other = [c for c in choice.ranges if c is not None
                 and choice.rate(first, c) != baud]
        if not other:
            return
        _write_range(ctx, other[0])
        _restart(ctx, "J")
        ok = _answers_at(ctx, baud)
        ctx.expect(ok, f"EEPROM {choice.range_address:02X} = {other[0]:02X} written, then "
                   f"J: the unit still answers at {baud}",
                   observed="it answers" if ok else "no answer", expected=f"? answered at {baud}",
                   rule="2.link.rate-range-at-restart")


def _unlisted(choice: BaudChoice) -> list[int]:
    """The bytes beside each range the manual lists (and 00), which it does not list."""
    listed = {c for c in choice.ranges if c is not None}
    return sorted({(c + d) & 0xFF for c in listed for d in (-1, 1)} | {0x00} - listed)


@case("2.link.rate.unlisted-range", rig=True, destructive=True,
      applies=lambda p: p.baud is not None and p.baud.range_address is not None,
      rules=("2.link.rate-range-unlisted", "10.cmd.eeprom-bytes", "2.link.rate-by-switch"))
def unlisted_range(ctx: CaseContext) -> None:
    """A range byte beside the listed ones (00, 02, FE) is stored as any byte (EW takes
    00..FF) and, at power-on, selects the default's range [D]; wherever the unit then
    answers, it is found and put back."""
    choice = ctx.profile.baud
    with _as_found(ctx):
        for code in _unlisted(choice):
            _write_range(ctx, code)
            baud = choice.rate(0, code)
            if _power_at(ctx, 0, baud, _shown(choice, 0, code),
                         "2.link.rate-range-unlisted") is None:
                here = _find(ctx, baud)
                ctx.require(here is not None, "the unit answers at none of the profile's rates")
                ctx.note(f"EEPROM {choice.range_address:02X} = {code:02X}: the unit answers "
                         f"at {here}")
