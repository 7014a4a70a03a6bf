"""`gve-conformance diff`: differential fuzzing. Sequences drawn from a grammar of spec 10
go to the target and to a reference (the embedded emulator) alike; every disagreement is
shrunk to a minimal transcript, kept once, labelled with the rule it touches and graded
by its tag, in the usual reports. docs/diff.md."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from conformance.cli.ending import counted, end, new_run_id
from conformance.cli.unit import ask_before_motion, unattended
from conformance.cli.usage import (
    Parser,
    UsageError,
    add_loudness,
    one_line,
    positive,
    seconds,
    summary,
    writable_folder,
)
from conformance.diff.engine import Budget, Pair, search
from conformance.diff.grammar import Options
from conformance.diff.kept import Kept
from conformance.diff.reach import Reach
from conformance.diff.results import agreement_result, rig_lost_result
from conformance.diff.sides import Side
from conformance.link.framing import readable
from conformance.link.interrupts import Interrupts
from conformance.link.safety import TargetNotResponding
from conformance.metadata import RunMeta
from conformance.operator import Console
from conformance.runner import RunResult
from conformance.targets import DEFAULT_MAX_TRAVEL, SessionError, Target, TargetError, parse_target
from conformance.verdict import COULD_NOT_TEST, FAIL, CouldNotTest

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
    add_loudness(ap, "print every line: for diff each disagreement's transcript too, "
                 "for replay every frame (its default)")


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = Parser(prog=PROG, description=summary(__doc__), targets=True, examples=EXAMPLES)
    common(ap)
    ap.add_argument("--examples", type=positive, metavar="N",
                    help=f"sequences to try (default {DEFAULT_EXAMPLES} unless --seconds)")
    ap.add_argument("--seconds", type=seconds, metavar="S", help="search for S seconds")
    ap.add_argument("--seed", type=int, default=0, help="the search's seed (default 0)")
    ap.add_argument("--no-probes", action="store_true",
                    help="draw sequences only (the written probes, run first by default, "
                    "are left out)")
    ap.add_argument("--report-dir", default="reports", help="where reports/<run id>/ go")
    ap.add_argument("--no-reports", action="store_true",
                    help="write no reports (the transcripts are printed instead)")
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


def ask_first(args: argparse.Namespace, target: Target) -> None:
    """Real units: the question before the first frame that can move an axis, as the
    suite's run asks it (no terminal and no --yes: nothing moves)."""
    if target.info.real and not args.yes:
        target.session.before_motion = ask_before_motion(target, Console(), RunMeta())


def main(argv: list[str] | None = None) -> int:
    try:
        args = parse_args(argv)
        target, reference = targets(args)
    except (UsageError, TargetError, LookupError, ValueError) as err:
        print(f"{PROG}: {one_line(err)}", file=sys.stderr)
        return 2
    run_id = new_run_id()
    folder = None if args.no_reports else Path(args.report_dir) / run_id
    interrupts = Interrupts()
    try:
        session = target.begin(interrupts)
    except (CouldNotTest, SessionError) as err:
        target.close()
        print(f"{PROG}: {COULD_NOT_TEST}: {one_line(err)}", file=sys.stderr)
        return 1
    ask_first(args, target)
    pair = Pair(Side(target, session), Side(reference), target.profile)
    options = Options(destructive=args.allow_destructive,
                      rig=target.info.has_rig and reference.info.has_rig)
    examples = args.examples if args.examples is not None or args.seconds else DEFAULT_EXAMPLES
    budget = Budget(examples=examples, seconds=args.seconds)
    run = RunResult(run_id, targets=[target.info.spec], settings="diff")
    say = _nothing if args.quiet else _say                 # -q: the last line only
    say(f"diff: {target.info.spec} against {reference.info.spec} "
        f"({target.profile.name}), seed {args.seed}, "
        + (f"{examples} sequences" if examples else f"{args.seconds:g} s"))

    kept = Kept(run, folder, profile=target.profile.name, target=target.info.spec,
                reference=reference.info.spec, seed=args.seed, say=say, verbose=args.verbose)
    reach = Reach(target.profile, options)
    try:
        with interrupts.catching():
            search(pair, options, budget, seed=args.seed, with_probes=not args.no_probes,
                   on_finding=kept.kept, on_seen=kept.seen, on_dropped=kept.dropped,
                   reach=reach)
    except (TargetNotResponding, SessionError, CouldNotTest) as err:
        r = agreement_result(profile=target.profile.name, target=target.info.spec,
                             examples=budget.used, frames=budget.frames, seconds=budget.elapsed)
        r.verdict, r.stopped = (FAIL if isinstance(err, TargetNotResponding)
                                else COULD_NOT_TEST), str(err)
        r.checks = [{"ok": False, "what": str(err), "observed": "", "expected": "",
                     "tag": "always", "rule": ""}]
        run.results.append(r)
        print(f"{r.verdict}: {err}", file=sys.stderr)
    except KeyboardInterrupt:
        run.interrupted = True
        session.emergency_stop()
    finally:
        try:
            report = session.finish() if session.real else None
        except CouldNotTest as err:         # an ending that could not be done: said
            report = None
            run.problems.append(f"the unit could not be left as it should: {err}")
        target.close()
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
    return end(run, None if args.no_reports else args.report_dir, quiet=args.quiet)


def _say(text: str) -> None:
    print(text, flush=True)


def _nothing(text: str) -> None:
    """-q: only the last line is printed."""
