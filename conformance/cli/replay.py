"""`gve-conformance replay FILE --target ...`: replay a transcript `diff` wrote (or any
transcript) on a target and its reference alike, frame by frame, and say whether the
disagreement is still there: each frame with the target's answer, the reference's now
and the one recorded. Exit status 1 while the sides disagree, 0 when they agree."""

from __future__ import annotations

import sys

from conformance.cli.diff import ask_first, common, targets
from conformance.cli.usage import Parser, UsageError, one_line
from conformance.diff.engine import Pair
from conformance.diff.gvt import steps_of
from conformance.diff.sides import Side
from conformance.diff.steps import FILL, FRAME
from conformance.link.framing import readable
from conformance.link.interrupts import Interrupts
from conformance.link.safety import TargetNotResponding
from conformance.targets import SessionError, TargetError
from gve_fixtures.transcript import UNIT, TranscriptError, load

PROG = "gve-conformance replay"


def main(argv: list[str] | None = None) -> int:
    ap = Parser(prog=PROG, description=__doc__.splitlines()[0])
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
    recorded = [r for r in t.records if r.direction == UNIT]
    interrupts = Interrupts()
    session = target.begin(interrupts)
    ask_first(args, target)
    pair = Pair(Side(target, session), Side(reference), target.profile)
    try:
        with interrupts.catching():
            outcome = pair.run(steps)
    except (TargetNotResponding, SessionError) as err:
        print(f"{PROG}: {err}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        session.emergency_stop()
        print(f"{PROG}: interrupted by a signal: H and D sent, the replay not finished",
              file=sys.stderr)
        return 1
    finally:
        if session.real:
            session.finish()
        target.close()
    print(f"replay {args.file}: {target.info.spec} against {reference.info.spec}")
    answers = iter(recorded)
    for rec in outcome.records:
        if rec.step.kind not in (FRAME, FILL) or rec.target is None:
            print(f"  = {rec.step}")
            continue
        # a transcript may record fewer answers than the reference gives (a fill's)
        was = b"".join(r.data for _, r in zip(range(rec.reference.answer.count(b"\r")),
                                             answers, strict=False)) if rec.step.answer else b""
        print(f"  > {readable(rec.target.sent):28} target {readable(rec.target.answer) or '-':16}"
              f" reference {readable(rec.reference.answer) or '-':16}"
              f" recorded {readable(was) or '-'}")
    d = outcome.disagreement
    for note in outcome.refused:
        print(f"  not sent (the guard): {note}")
    if d is None:
        print("no disagreement: the target answers as the reference does")
        return 0
    print(f"the disagreement is still there: {readable(d.target.sent)} target "
          f"{readable(d.target.answer) or '(none)'}, reference "
          f"{readable(d.reference.answer) or '(none)'} ({d.kind}); "
          f"{d.verdict} {d.rule or '(no known rule)'}")
    return 1
