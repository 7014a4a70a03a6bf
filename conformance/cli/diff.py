"""`gve-conformance diff`: differential fuzzing. Sequences drawn from a grammar of spec 10
go to the target and to a reference (the embedded emulator) alike; every disagreement is
shrunk to a minimal transcript, kept once, labelled with the rule it touches and graded
by its tag, in the usual reports. docs/diff.md.

The command line of conformance/diff/ (one meaning under one name)."""

from __future__ import annotations

import argparse
import sys

from conformance.case.settings import fresh_seed
from conformance.cli.colour import wanted
from conformance.cli.ending import claimed, counted, end, new_run_id
from conformance.cli.preflight import consent, unattended
from conformance.cli.progress import HEARTBEAT, Progress
from conformance.cli.usage import (
    Parser,
    UsageError,
    job_options,
    one_line,
    positive,
    summary,
    writable_folder,
)
from conformance.diff.engine import Budget, KnownStateLost, Pair, search
from conformance.diff.grammar import Options
from conformance.diff.kept import Kept
from conformance.diff.reach import Reach
from conformance.diff.results import agreement_result, rig_lost_result
from conformance.diff.sides import Side
from conformance.link.framing import readable
from conformance.link.liveness import TargetNotResponding
from conformance.link.signals import StopSignals
from conformance.link.stops import SafetyStop
from conformance.operator.console import Console
from conformance.reports.files import release
from conformance.run.metadata import RunMeta, now_iso
from conformance.run.runner import RunResult, step_results
from conformance.targets import DEFAULT_MAX_TRAVEL, SessionError, Target, TargetError, parse_target
from conformance.verdicts.check import Check
from conformance.verdicts.verdict import ALWAYS, COULD_NOT_TEST, FAIL, SILENT, CouldNotTest

PROG = "gve-conformance diff"
#: sequences tried when neither --examples nor --seconds is given
DEFAULT_EXAMPLES = 2000
EXAMPLES = (
    "gve-conformance diff --target emu:GVE84-100?mutant=NAME --examples 500",
    "gve-conformance diff --target tcp:127.0.0.1:5114 --profile GVE114-500 --seconds 60",
    "gve-conformance diff --target 'exec:./clone-sim --pty' --profile GVE84-100 --yes",
    "gve-conformance diff --target serial:/dev/ttyUSB0?baud=115200 --profile GVE54",
)


def common(ap: argparse.ArgumentParser) -> None:
    """The options diff and replay share."""
    ap.add_argument("--target", required=True,
                    help="the target (forms below)")
    ap.add_argument("--profile", help="the behaviour expected of a serial/tcp/exec target")
    ap.add_argument("--against", help="the reference: emu:PROFILE (default: the profile's "
                    "embedded emulator)")
    ap.add_argument("--allow-destructive", action="store_true",
                    help="also J, W and EEPROM writes (real units: backed up and restored)")
    ap.add_argument("--max-travel", type=positive, default=DEFAULT_MAX_TRAVEL,
                    help="real units: the motion envelope in full steps per axis")
    ap.add_argument("--yes", action="store_true",
                    help="real units: move without asking first (unattended benches)")
    ap.add_argument("--strict", action="store_true",
                    help="grade the target by the project's decisions too: a [D] "
                         "difference FAILs instead of NON-STRICT")


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = Parser(prog=PROG, description=summary(__doc__), targets=True, examples=EXAMPLES,
                parents=[job_options(
                    "also print each disagreement's transcript (the reports keep it too)",
                    seed="the search's seed: the same N draws the same sequences "
                         "(default: a fresh one, printed and recorded in the reports)",
                    time_limit="search for S seconds (instead of a number of sequences)")])
    common(ap)
    ap.add_argument("--examples", type=positive, metavar="N",
                    help=f"sequences to try (default {DEFAULT_EXAMPLES} unless --seconds)")
    ap.add_argument("--no-probes", action="store_true",
                    help="draw sequences only (the written probes and the sweep of every "
                    "table value, run first by default, are left out)")
    args = ap.parse_args(argv)
    if not args.no_reports:
        writable_folder(args.report_dir)
    return args


def targets(args: argparse.Namespace) -> tuple[Target, Target]:
    """The target and its reference, checked before anything is sent (a real unit that
    would have to ask before moving where nobody can answer is refused here)."""
    target = parse_target(args.target, profile=args.profile,
                          allow_destructive=args.allow_destructive, max_travel=args.max_travel,
                          strict=args.strict)
    against = args.against or f"emu:{target.profile.name}"
    reference = parse_target(against)
    if reference.info.real:
        raise UsageError(f"--against {against}: the reference is the embedded emulator "
                         "(emu:PROFILE)")
    if reference.profile.name != target.profile.name:
        raise UsageError(f"--against {against} behaves as {reference.profile.name}, the "
                         f"target as {target.profile.name}")
    target.preflight()
    reference.preflight()
    unattended([target, reference], args.yes, Console())
    return target, reference


def ask_first(args: argparse.Namespace, target: Target, meta: RunMeta | None = None
              ) -> None:
    """Real units: the question before the first frame that can move an axis, as the
    suite's run asks it (no terminal and no --yes: nothing moves); the answer goes to
    ``meta``."""
    consent(args.yes, Console(), meta or RunMeta()).arm(target)


def meta_of(args: argparse.Namespace, argv: list[str], target: Target, reference: Target,
            seed: int) -> RunMeta:
    """What the reports say about the search, as a run's say about the run: when, the
    command as given, the seed, the target and the profile it is judged as, and diff's
    own options in force."""
    meta = RunMeta(started=now_iso(), command=["diff", *argv], settings="diff", seed=seed,
                   destructive=args.allow_destructive, max_travel=args.max_travel,
                   strict=args.strict)
    t = meta.target(target.info.spec)
    t.kind, t.profile = target.info.kind, target.profile.name
    t.profile_chosen = "emulated" if not target.info.real and args.profile is None \
        else "--profile"
    t.envelope = target.info.max_travel if target.info.real else None
    t.graded = "strict" if target.info.strict else "by the tags"
    meta.confirmed = consent(args.yes, Console(), meta).how([target])
    meta.job_flags = {
        "--against": reference.info.spec, "--seed": seed,
        "--examples": args.examples if args.examples is not None else (
            "none (--seconds)" if args.seconds else DEFAULT_EXAMPLES),
        "--seconds": args.seconds if args.seconds else "none",
        "--no-probes": args.no_probes, "--allow-destructive": args.allow_destructive,
        "--max-travel": args.max_travel, "--strict": args.strict,
        "motion confirmed": meta.confirmed or "not asked"}
    return meta


class _Watched(Budget):
    """The search's budget, which tells ``progress`` how far the search is each time
    the search asks whether it is spent (before every sequence)."""

    def __init__(self, progress: Progress, **kw: object) -> None:
        super().__init__(**kw)
        self.progress = progress

    def spent(self) -> bool:
        self.progress.advance_to(self.used if self.examples is not None
                                 else int(self.elapsed))
        return super().spent()


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    folder = None
    try:
        args = parse_args(argv)
        folder = None if args.no_reports else claimed(args.report_dir, args.run_id)
        target, reference = targets(args)
    except (UsageError, TargetError, LookupError, ValueError, KeyboardInterrupt) as err:
        if folder is not None:
            release(folder)
        if isinstance(err, KeyboardInterrupt):
            raise
        print(f"{PROG}: {one_line(err)}", file=sys.stderr)
        return 2
    seed = args.seed if args.seed is not None else fresh_seed()
    run_id = (args.run_id or new_run_id()) if folder is None else folder.name
    meta = meta_of(args, argv, target, reference, seed)
    interrupts = StopSignals()
    try:
        session = target.begin(interrupts)
    except (CouldNotTest, SessionError) as err:
        target.close()
        print(f"{PROG}: {COULD_NOT_TEST}: {one_line(err)}", file=sys.stderr)
        return 1
    ask_first(args, target, meta)
    # the reference counts the run's signals too: its writes ask a flag, not swap handlers
    pair = Pair(Side(target, session), Side(reference, reference.begin(interrupts)),
                target.profile)
    options = Options(destructive=args.allow_destructive,
                      rig=target.info.has_rig and reference.info.has_rig)
    examples = args.examples if args.examples is not None or args.seconds else DEFAULT_EXAMPLES
    run = RunResult(run_id, targets=[target.info.spec], settings="diff", meta=meta)
    say = _nothing if args.quiet else _say                 # -q: the recap and last line
    say(f"diff: {target.info.spec} against {reference.info.spec} "
        f"({target.profile.name}), seed {seed} (the same sequences again: --seed {seed}), "
        + (f"{examples} sequences" if examples else f"{args.seconds:g} s"))
    # a sequence on a real unit may take seconds: the heartbeat shows the search moving
    progress = Progress(examples or int(args.seconds), unit="seq" if examples else "s",
                        quiet=args.quiet, verbose=args.verbose, heartbeat=HEARTBEAT,
                        status=lambda: (f"{budget.used} sequences, {budget.frames} frames, "
                                        f"{len(run.results)} disagreement(s)"))
    budget = _Watched(progress, examples=examples, seconds=args.seconds)

    kept = Kept(run, folder, profile=target.profile.name, target=target.info.spec,
                reference=reference.info.spec, seed=seed, prog=PROG,
                say=_nothing if args.quiet else progress.print, verbose=args.verbose)
    reach = Reach(target.profile, options)
    try:
        with interrupts.catching():
            search(pair, options, budget, seed=seed, with_probes=not args.no_probes,
                   on_finding=kept.kept, on_seen=kept.seen, on_dropped=kept.dropped,
                   reach=reach)
    except TargetNotResponding as err:
        r = agreement_result(profile=target.profile.name, target=target.info.spec,
                             examples=budget.used, frames=budget.frames, seconds=budget.elapsed)
        r.verdict, r.stopped = FAIL, str(err)
        r.checks = [Check(False, str(err), tag=ALWAYS, rule=SILENT).to_dict()]
        run.results.append(r)
        print(f"{r.verdict}: {err}", file=sys.stderr)
    except (SafetyStop, SessionError, CouldNotTest) as err:
        # the guard's stop outside a sequence's frames (each frame's is the sequence's), or
        # an example that could not start from the known state
        r = agreement_result(profile=target.profile.name, target=target.info.spec,
                             examples=budget.used, frames=budget.frames, seconds=budget.elapsed)
        r.verdict, r.stopped, r.checks = COULD_NOT_TEST, str(err), []
        r.notes = [f"the search stopped after {budget.used} sequences: {err}"]
        if isinstance(err, KnownStateLost) and err.after:
            r.notes.append("the sequence after which the known state could not be had: "
                           + " | ".join(str(s) for s in err.after))
        run.results.append(r)
        print(f"{r.verdict}: {err}", file=sys.stderr)
    except KeyboardInterrupt:
        run.interrupted = True
        session.emergency_stop()
    finally:
        progress.close()
        try:
            report = session.finish() if session.real else None
        except CouldNotTest as err:         # an ending that could not be done: said
            report = None
            run.problems.append(f"the unit could not be left as it should: {err}")
        target.close()
    meta.finished = now_iso()
    for r in step_results(session, target):   # a known-state step the target broke
        run.results.append(r)
        check = r.checks[0]
        say(f"{r.verdict:11} {check['rule']}: the known state: {check['what']}: "
            f"{check['observed']}")
    if report is not None:
        run.sessions[target.info.spec] = report.to_dict()
        run.problems += report.problems
    for f in pair.unconfirmed:
        d = f.disagreement
        say(f"not confirmed (seen once, not when replayed): {readable(d.target.sent)} "
            f"target {readable(d.target.answer) or '(none)'} / reference "
            f"{readable(d.reference.answer) or '(none)'} ({d.kind}): not counted")
    agreed = not run.results
    if pair.target.rig_lost:
        run.results.append(rig_lost_result(profile=target.profile.name,
                                           target=target.info.spec, why=pair.target.rig_lost))
        say(f"{COULD_NOT_TEST}: input steps: {pair.target.rig_lost}")
    if agreed:
        r = agreement_result(profile=target.profile.name, target=target.info.spec,
                             examples=budget.used, frames=budget.frames,
                             seconds=budget.elapsed)
        if run.interrupted:
            # a search cut short by a signal has not shown that the target agrees
            r.verdict, r.interrupted = COULD_NOT_TEST, True
            r.notes = [f"interrupted by a signal after {budget.used} sequences: H and D "
                       "sent, the search not finished"]
        run.results.append(r)
    run.frames, run.seconds = budget.frames, budget.elapsed
    say(reach.line())
    if args.verbose:
        say("\n".join("  not reached: " + line for line in reach.not_reached()))
    for r in run.results:
        if r.id == "diff.search.agreement":
            r.notes.append(reach.line())
    say(f"{budget.used} sequences, {budget.frames} frames in {budget.elapsed:.1f} s: "
        f"{counted(run)}" + (" (interrupted by a signal: H and D sent)" if run.interrupted
                             else ""))
    return end(run, None if args.no_reports else args.report_dir, junitxml=args.junitxml,
               accept_incomplete=args.accept_incomplete,
               colour=wanted(args.color, sys.stdout))


def _say(text: str) -> None:
    print(text, flush=True)


def _nothing(text: str) -> None:
    """-q: only the last line is printed."""
