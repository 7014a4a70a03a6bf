"""`gve-conformance replay FILE --target ...`: replay a transcript `diff` wrote (or any
transcript) on a target and its reference alike, frame by frame, and say whether the
disagreement is still there: each frame with the target's answer, the reference's now
and the one recorded, then one verdict line (``PASSED — PASS: ...``, ``FAILED — FAIL
...``, ``FAILED — COULD-NOT-TEST: ...``, as every job ends). Exit status 0 when the
sides agree on every frame, 1 while they disagree or when the transcript
could not be replayed whole, 2 for a usage error, 130 when a signal stopped it."""

from __future__ import annotations

import sys
from dataclasses import replace

from conformance.cli.diff import ask_first, common, targets
from conformance.cli.usage import (
    INTERRUPTED,
    Parser,
    UsageError,
    job_options,
    one_line,
    summary,
)
from conformance.diff.engine import Pair
from conformance.diff.gvt import expected_of, steps_of
from conformance.diff.replayed import Verdict, frame_lines, header, verdict
from conformance.diff.sides import Side
from conformance.link.liveness import TargetNotResponding
from conformance.link.signals import StopSignals
from conformance.targets import SessionError, TargetError
from conformance.verdicts.verdict import FAIL, FAILED, PASSED
from gve_fixtures.transcript import TranscriptError, load

PROG = "gve-conformance replay"
EXAMPLES = (
    "gve-conformance replay reports/RUN/diff-01.gvt --target emu:GVE84-100",
    "gve-conformance replay diff-01.gvt --target 'exec:./clone-sim --pty' --yes",
    "gve-conformance replay diff-01.gvt --target serial:/dev/ttyUSB0 --profile GVE84-100",
)


def main(argv: list[str] | None = None) -> int:
    ap = Parser(prog=PROG, description=summary(__doc__), targets=True, examples=EXAMPLES,
                parents=[job_options("print every frame (the default)", reports=False,
                                     seed=None)])
    ap.add_argument("file", help="a .gvt transcript")
    common(ap)
    try:
        args = ap.parse_args(argv)
        t = load(args.file)
        if args.profile is None and args.target.startswith(("serial:", "tcp:", "exec:")):
            args.profile = t.meta.get("profiles", "").split()[0] if t.meta.get("profiles") \
                else None
        target, reference = targets(args)
        steps = steps_of(t)
        if not steps:
            raise UsageError(f"{args.file}: no frames to replay")
    except (UsageError, TargetError, TranscriptError, LookupError, ValueError,
            OSError) as err:
        print(f"{PROG}: {one_line(err)}", file=sys.stderr)
        return 2
    expected = expected_of(t)
    interrupts = StopSignals()
    session = target.begin(interrupts)
    ask_first(args, target)
    for line in [] if args.quiet else header(args.file, target.info.spec, reference.info.spec,
                                             target.profile.name, t.meta):
        print(line, flush=True)
    # the reference counts the run's signals too: its writes ask a flag, not swap handlers
    pair = Pair(Side(target, session), Side(reference, reference.begin(interrupts)),
                target.profile)
    outcome = None
    try:
        with interrupts.catching():
            outcome = pair.run(steps)
        result = verdict(outcome, steps, t.meta)
    except TargetNotResponding as err:
        result = Verdict(FAIL, f"{FAIL}: the target stopped answering ({err}); nothing "
                         "after it was compared", 1)
    except SessionError as err:
        result = Verdict.could_not_test(f"the session on the target could not go on ({err})")
    except KeyboardInterrupt:
        session.emergency_stop()
        result = replace(Verdict.could_not_test("interrupted by a signal: H and D sent, the "
                                                "replay not finished"), status=INTERRUPTED)
    finally:
        if session.real:
            session.finish()
        target.close()
    if outcome is not None and not args.quiet:
        for line in frame_lines(outcome, steps, expected):
            print(line)
    # the last line as every job's: PASSED only when the sides agreed on every frame
    print(f"{PASSED if result.status == 0 else FAILED} — {result.line}", flush=True)
    return result.status
