"""Running a RuleBasedStateMachine as a case: the machine is made for the case context by
a factory, every example starts from a fresh link, a failing example's wire log is saved
as a transcript."""

from __future__ import annotations

from hypothesis import seed
from hypothesis.errors import Flaky, FlakyFailure
from hypothesis.stateful import run_state_machine_as_test

from conformance.case import settings as settings_profiles
from conformance.case.context import CaseContext, CouldNotTest
from conformance.link.framing import UnitDataError
from conformance.machines.unit_machine import UnitMachine
from conformance.verdicts.verdict import ALWAYS, UNREADABLE


class Factory:
    """Makes ``machine`` for ``ctx``, one machine per example. Hypothesis keys a
    machine's examples in its database by the factory: an object (no source of its own,
    unlike a lambda written once here for every machine) is keyed by its name, the
    machine's, so each machine keeps its own examples."""

    def __init__(self, machine: type[UnitMachine], ctx: CaseContext) -> None:
        self.machine = machine
        self.ctx = ctx
        self.__name__ = machine.__name__
        #: why an example could not start from the known state: the case is then
        #: COULD-NOT-TEST, never a failed invariant of that example or a later one
        self.unsettled = ""

    def __call__(self) -> UnitMachine:
        if self.unsettled:                  # every later example and replay alike
            raise CouldNotTest(self.unsettled)
        try:
            return self.machine(self.ctx)
        except CouldNotTest as err:
            self.unsettled = f"{self.__name__}: an example could not start from the " \
                             f"known state: {err}"
            raise CouldNotTest(self.unsettled) from None


def run_machine(ctx: CaseContext, machine: type[UnitMachine]) -> None:
    """Run ``machine`` with ctx.settings, the run's seed and its example database (the
    failing examples found before are tried first); a failure becomes a failed check."""
    run_settings, run_seed = settings_profiles.machine_run(ctx.settings, ctx.profile.name,
                                                           ctx.seed)
    # every run sets the seed: None lets Hypothesis draw one
    made = Factory(machine, ctx)
    factory = seed(run_seed)(made)
    try:
        try:
            run_state_machine_as_test(factory, settings=run_settings)
        except Exception:
            if made.unsettled:                # however Hypothesis reports it
                raise CouldNotTest(made.unsettled) from None
            raise
    except FlakyFailure as err:
        # failed once and not when replayed (a real line's timing): the failure seen is
        # the finding, graded by its rule, with the replay noted
        broken = [e for e in _leaves(err) if isinstance(e, AssertionError)]
        if not broken:
            raise
        _failed(ctx, machine, broken[0])
        ctx.note("the failing example did not fail again when Hypothesis replayed it")
    except Flaky as err:
        # Hypothesis could not replay its own drawing (a rule's precondition saw another
        # state in real time): nothing about the target follows from that
        raise CouldNotTest(f"{machine.__name__}: the example could not be replayed "
                           f"({type(err).__name__}: {str(err).splitlines()[0][:200]})"
                           ) from None
    except (AssertionError, ExceptionGroup) as err:
        if isinstance(err, ExceptionGroup) and not all(
                isinstance(e, AssertionError) for e in _leaves(err)):
            raise
        _failed(ctx, machine, err if isinstance(err, AssertionError) else _leaves(err)[0])
    else:
        ctx.expect(True, f"{machine.__name__}: every example kept the invariants",
                   rule=ctx.case.rules[0] if ctx.case.rules else None)


def _failed(ctx: CaseContext, machine: type, err: BaseException) -> None:
    """The failed invariant as a check graded by the rule it names: what it says, and
    what the unit did and the rule wants where the machine said (never the whole error:
    the example's steps are in the wire log and its transcript); bytes of the unit that
    cannot be read are the response grammar's, whatever the tag."""
    rule = getattr(err, "rule", None)
    what = f"{machine.__name__}: {err}".splitlines()[0][:300]
    seen = {"observed": getattr(err, "observed", ""), "expected": getattr(err, "expected", "")}
    if isinstance(err, UnitDataError):
        # bytes no rule's reading allows where a value belongs, as the runner grades them
        ctx.expect(False, f"{machine.__name__}: the unit's answer cannot be read: "
                   f"{str(err).splitlines()[0][:300]}",
                   observed=seen["observed"] or str(err)[-500:],
                   expected=seen["expected"] or "an answer",
                   tag=ALWAYS, rule=UNREADABLE, machinery=True)
    elif rule is not None and rule not in ctx.case.rules:
        # a rule of the machinery the case does not list (the index, PF): its own tag
        ctx.expect(False, f"{what} [{rule}]", **seen, rule=rule, machinery=True)
    else:
        ctx.expect(False, what, **seen, rule=rule)
    if len(str(err).strip().splitlines()) > 1:
        ctx.note(f"{machine.__name__}: {err}")         # the rest of what it said
    link = ctx.links[-1] if ctx.links else None
    if link is not None:
        ctx.artifact("failing-example.gvt", "# gve-transcript 1\n# title: failing "
                     f"example of {machine.__name__}\n" + "\n".join(
                         link.transcript_lines()) + "\n")


def _leaves(group: BaseExceptionGroup) -> list[BaseException]:
    out: list[BaseException] = []
    for e in group.exceptions:
        out.extend(_leaves(e) if isinstance(e, BaseExceptionGroup) else [e])
    return out
