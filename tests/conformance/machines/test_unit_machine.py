"""What every machine shares: it is made for its case's context, one machine (and one
fresh link) per example; the frames it sends through `send` are booked in its model; the
index check is an invariant only of the machines that take it."""

from __future__ import annotations

from typing import ClassVar

import pytest
from hypothesis.stateful import rule

from conformance.case import settings as settings_profiles
from conformance.case.context import CaseContext, CouldNotTest
from conformance.case.settings import example_database
from conformance.machines.as_case import Factory, run_machine
from conformance.machines.checksum import ChecksumMachine
from conformance.machines.keep import KeepMachine
from conformance.machines.recovery import RecoveryMachine
from conformance.machines.unit_machine import UnitMachine, index_invariant
from conformance.run.selection import select
from conformance.targets import parse_target

#: a case whose rules name the index's
CASE = "6.machine.checksum-framing"


def context(profile: str = "GVE84-100", readings: str = "") -> CaseContext:
    (case,) = select([CASE])
    target = parse_target(f"emu:{profile}" + (f"?reading={readings}" if readings else ""))
    return CaseContext(case, target.profile, target.info, settings_profiles.get("ci"),
                       target.session.open_link)


class Booked(UnitMachine):
    """Sends every frame through `send`: the model counts them all."""

    index_is_the_models = index_invariant()
    made: ClassVar[list[Booked]] = []

    def __init__(self, ctx: CaseContext) -> None:
        super().__init__(ctx)
        Booked.made.append(self)

    @rule()
    def speed(self) -> None:
        assert self.send("V1000").code == 0


class Repeats(UnitMachine):
    """Refused frames, each repeated by `>` (whose answer is the refused frame's)."""

    index_is_the_models = index_invariant()

    @rule()
    def refused_then_repeated(self) -> None:
        assert self.send("T99").code == 5
        assert self.send(">", lines=2).code == 5


class Unbooked(UnitMachine):
    """Sends a frame past the model: the unit's index runs ahead of the model's."""

    @rule()
    def speed(self) -> None:
        assert self.link.send("V1000").code == 0


class UnbookedChecked(Unbooked):
    index_is_the_models = index_invariant()


def failed(ctx: CaseContext) -> list[tuple[str, str]]:
    return [(c.what, c.rule) for c in ctx.checks if not c.ok]


def test_a_machine_is_made_for_its_context_once_an_example():
    Booked.made.clear()
    ctx = context()
    run_machine(ctx, Booked)
    assert not failed(ctx) and len(Booked.made) > 1
    assert all(m.ctx is ctx for m in Booked.made)
    # every example on a link of its own, none shared
    assert len({id(m.link) for m in Booked.made}) == len(Booked.made)
    assert [m.link for m in Booked.made] == ctx.links[-len(Booked.made):]


def test_the_index_invariant_holds_only_where_a_machine_takes_it():
    ctx = context()
    run_machine(ctx, Unbooked)                  # its model is wrong, and nothing checks it
    assert not failed(ctx)
    ctx = context()
    run_machine(ctx, UnbookedChecked)
    (what, rule), = failed(ctx)
    assert what.startswith("UnbookedChecked: index ") and rule == "8.index.counts"


@pytest.mark.parametrize(("machine", "checked"), [(ChecksumMachine, True),
                                                  (RecoveryMachine, False),
                                                  (KeepMachine, False)])
def test_which_machines_check_the_index(machine, checked):
    assert (getattr(machine, "index_is_the_models", None) is not None) == checked


def test_each_machine_keeps_its_own_examples(tmp_path):
    """The example database keys a machine's examples by its factory, which is named for
    its machine: two machines failing in one database keep two sets of examples."""
    def entries() -> int:
        return sum(1 for p in (tmp_path / "GVE84-100").rglob("*") if p.is_file())

    with example_database(str(tmp_path)):
        run_machine(context(), UnbookedChecked)
        one = entries()
        run_machine(context(), UnbookedChecked)
        assert entries() == one                 # the same machine: the same example
        run_machine(context(), type("OtherChecked", (UnbookedChecked,), {}))
        assert one > 0 and entries() > one
    assert Factory(ChecksumMachine, context()).__name__ == "ChecksumMachine"


@pytest.mark.parametrize("machine", [KeepMachine, RecoveryMachine])
def test_the_machines_that_check_positions_book_the_index_too(machine):
    """Their every frame goes through `send`: with the index invariant added they keep
    it, faults and detours and all."""
    checked = type(f"Checked{machine.__name__}", (machine,),
                   {"index_is_the_models": index_invariant()})
    ctx = context()
    run_machine(ctx, checked)
    assert not failed(ctx) and any(c.ok for c in ctx.checks)


def test_an_example_that_cannot_start_from_the_known_state_is_could_not_test():
    # the third example's known state finds the unit not at rest: the case cannot test,
    # and no invariant of that example (or a later one, or a replay) is failed
    (case,) = select([CASE])
    target = parse_target("emu:GVE84-100")
    opened = []

    def open_link(address=None):
        opened.append(address)
        if len(opened) >= 3:
            raise CouldNotTest("the unit is not at rest after the known state: SR6 reads "
                               "0,40 (RUN)")
        return target.session.open_link(address)

    ctx = CaseContext(case, target.profile, target.info, settings_profiles.get("ci"),
                      open_link)
    with pytest.raises(CouldNotTest, match="Booked: an example could not start from the "
                                           "known state: the unit is not at rest"):
        run_machine(ctx, Booked)
    assert not failed(ctx)
    assert len(opened) == 3                 # not tried again once it could not start


@pytest.mark.parametrize("readings", ["", "refused-uncounted", "queries-counted",
                                      "refused-uncounted,queries-counted"])
def test_the_model_combines_what_counts_as_the_unit_measured(readings):
    # whether refused frames count and whether queries count, measured, both at once:
    # the code `>` answers with is the refused frame's, not a refusal of the `>`
    ctx = context(readings=readings)
    run_machine(ctx, Repeats)
    assert not failed(ctx)
