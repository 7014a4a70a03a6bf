"""Running a RuleBasedStateMachine as a case: the machine gets the case context, every
example starts from a fresh link, a failing example's wire log is saved as a transcript."""

from __future__ import annotations

from hypothesis import seed
from hypothesis.errors import Flaky
from hypothesis.stateful import RuleBasedStateMachine, run_state_machine_as_test

from conformance import settings as settings_profiles
from conformance.case import CaseContext


def run_machine(ctx: CaseContext, machine: type[RuleBasedStateMachine]) -> None:
    """Run ``machine`` with ctx.settings, the run's seed and its example database (the
    failing examples found before are tried first); a failure becomes a failed check."""
    machine.ctx = ctx  # type: ignore[attr-defined]
    run_settings, run_seed = settings_profiles.machine_run(ctx.settings, ctx.profile.name,
                                                           ctx.seed)
    # every run sets the seed: None lets Hypothesis draw one
    seed(run_seed)(machine)
    try:
        run_state_machine_as_test(machine, settings=run_settings)
    except Flaky as err:
        # a real target answered differently when Hypothesis replayed an example
        ctx.expect(False, f"{machine.__name__}: the target is not deterministic on replay",
                   observed=str(err)[-300:], expected="the same answers to the same frames")
    except (AssertionError, ExceptionGroup) as err:
        if isinstance(err, ExceptionGroup) and not all(
                isinstance(e, AssertionError) for e in _leaves(err)):
            raise
        link = ctx.links[-1] if ctx.links else None
        ctx.expect(False, f"{machine.__name__}: {err}".splitlines()[0][:300],
                   observed=str(err)[-500:], expected="every invariant holds")
        if link is not None:
            ctx.artifact("failing-example.gvt", "# gve-transcript 1\n# title: failing "
                         f"example of {machine.__name__}\n" + "\n".join(
                             link.transcript_lines()) + "\n")
    else:
        ctx.expect(True, f"{machine.__name__}: every example kept the invariants")


def _leaves(group: BaseExceptionGroup) -> list[BaseException]:
    out: list[BaseException] = []
    for e in group.exceptions:
        out.extend(_leaves(e) if isinstance(e, BaseExceptionGroup) else [e])
    return out
