"""`gve-conformance corpus`: the independent implementations gate — the catalogue and
`diff` against every unit of `corpus/` (simulators written from one manual alone by
people who never saw this project), and host certification of every host program there,
each run as a user runs it (the CLI, an `exec:` target, a results.json). An
implementation is fair when every FAIL it gets is one of its documented departures from
the manual (`corpus/corpus.toml`), and the suite keeps its power when every documented
departure is still FAILed; CI fails otherwise.

Unlike `fairness`, whose readings are the project's own, nobody here wrote these: a FAIL
outside the documented departures is a defect of the suite (fixed in the suite, never in
the implementation to please it).

``--jobs`` units are judged at a time, and as many hosts beside them: a host's
certification spends its time waiting on its real-time line (a few per cent of a core),
a unit's catalogue and diff run in virtual time on a core."""

from __future__ import annotations

import json
import shlex
import subprocess
import sys
import tempfile
import time
import tomllib
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from conformance.cli.gate import Gate, GateItem
from conformance.cli.pool import workers
from conformance.cli.progress import HEARTBEAT, Progress
from conformance.cli.usage import (
    TIME_LIMIT_HELP,
    Parser,
    UsageError,
    job_options,
    positive,
    summary,
)
from conformance.verdicts.verdict import CHECK_TAGS, FAIL
from conformance.verdicts.verdict import grade as grade_of

PROG = "gve-conformance corpus"
#: the corpus's manifest, from a checkout's top
MANIFEST = Path("corpus") / "corpus.toml"
#: how the catalogue is graded: a FAIL is a verdict no reading allows, an ERROR a crash
UNFAIR = ("FAIL", "ERROR")
#: the verdicts of a case that judged the target
JUDGED = ("PASS", "FAIL", "NON-STRICT", "INFO")


@dataclass(frozen=True)
class Implementation:
    """One implementation of the corpus: a unit simulator (`kind` "unit": its command
    starts it in co-simulation) or a host program (`kind` "host": its command has
    `{port}`), with the departures from its manual it is known to have (rule -> what it
    does)."""

    name: str
    kind: str
    folder: Path
    command: str
    profiles: tuple[str, ...]
    departures: dict[str, str]
    written_from: str
    #: FAILs on these rules are defects of the suite found and not yet mended (rule -> what
    #: the suite gets wrong): listed at every run as open, not counted unfair, so that a new
    #: defect still fails the gate while a known one is being fixed
    open: dict[str, str] = field(default_factory=dict)
    diff_examples: int = 0
    #: the suite's options a user gives for this implementation, as its comment says why
    options: tuple[str, ...] = ()

    def argv(self) -> list[str]:
        """The command's words, `{python}` and `{dir}` filled in."""
        return [w.replace("{python}", sys.executable).replace("{dir}", str(self.folder))
                for w in shlex.split(self.command)]


@dataclass
class Trial:
    """What one implementation got: FAILs outside its departures, departures no longer
    FAILed, and what each job said."""

    name: str
    unfair: list[str] = field(default_factory=list)
    departures_missed: list[str] = field(default_factory=list)
    open: list[str] = field(default_factory=list)       # FAILs of the suite's open defects
    said: list[str] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def fair(self) -> bool:
        return not self.unfair and not self.departures_missed


def load_manifest(path: Path = MANIFEST) -> list[Implementation]:
    """The implementations `path` lists (a TOML of `[[implementation]]` tables); raises
    UsageError with one line for a manifest that is missing or says nonsense."""
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as err:
        raise UsageError(f"{path}: {err}") from None
    known = {"name", "kind", "folder", "command", "profiles", "departures", "written-from",
             "diff-examples", "open", "options"}
    out = []
    for table in data.get("implementation", []):
        wrong = sorted(set(table) - known)
        if wrong:
            raise UsageError(f"{path}: unknown key(s) {', '.join(wrong)} in "
                             f"{table.get('name', '?')} (known: {', '.join(sorted(known))})")
        if table.get("kind") not in ("unit", "host"):
            raise UsageError(f"{path}: {table.get('name', '?')}: kind is unit or host")
        out.append(Implementation(
            name=table["name"], kind=table["kind"], folder=path.parent / table["folder"],
            command=table["command"], profiles=tuple(table["profiles"]),
            departures=dict(table.get("departures", {})),
            open=dict(table.get("open", {})),
            written_from=table.get("written-from", ""),
            diff_examples=int(table.get("diff-examples", 0)),
            options=tuple(table.get("options", ()))))
    return out


def _failing(check: dict) -> bool:
    """Whether a failed check is one that FAILs a third party: graded by its tag as
    every target outside --strict is (a [D] check beside an [M] one in the same case
    is NON-STRICT, not a FAIL of its rule); a check without a known tag counts."""
    tag = check.get("tag", "")
    return not check.get("ok") and (tag not in CHECK_TAGS or grade_of(tag, False) == FAIL)


def failed_rules(results: dict) -> list[tuple[str, str, list[str]]]:
    """Each case of a results.json that FAILed or ERRed: (case, verdict, the rules of its
    checks that FAIL a third party)."""
    out = []
    for r in results.get("results", []):
        if r.get("verdict") in UNFAIR:
            rules = sorted({c.get("rule") or "(no rule)" for c in r.get("checks", [])
                            if _failing(c)}) or ["(no rule)"]
            out.append((f"{r.get('id')} [{r.get('profile')}]", r["verdict"], rules))
    return out


def _job(argv: list[str], folder: Path, timeout: float) -> tuple[dict | None, str]:
    """Run one CLI job writing its reports under ``folder``: its results.json (None when
    it wrote none) and the last line it printed."""
    try:
        done = subprocess.run(argv, capture_output=True, text=True, timeout=timeout,
                              stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        return None, f"did not end within {timeout:.0f} s"
    lines = (done.stdout + done.stderr).strip().splitlines()
    last = lines[-1] if lines else f"exit {done.returncode}, nothing printed"
    found = sorted(folder.glob("*/results.json"))
    if not found:
        return None, last
    return json.loads(found[-1].read_text(encoding="utf-8")), last


def jobs_of(impl: Implementation, reports: Path, seed: int) -> list[tuple[str, list[str]]]:
    """The CLI jobs that judge ``impl``: (what, argv)."""
    cli = [sys.executable, "-m", "conformance"]
    out = []
    for profile in impl.profiles:
        common = ["--profile", profile, "--report-dir", str(reports / f"{profile}-{len(out)}"),
                  "-q", *impl.options]
        if impl.kind == "unit":
            target = "exec:" + shlex.join(impl.argv())
            out.append((f"catalogue {profile}",
                        [*cli, "run", "--target", target, *common, "--yes",
                         "--allow-destructive"]))
            if impl.diff_examples:
                common = ["--profile", profile,
                          "--report-dir", str(reports / f"{profile}-{len(out)}"), "-q",
                          *impl.options]
                out.append((f"diff {profile}",
                            [*cli, "diff", "--target", target, *common, "--yes",
                             "--allow-destructive", "--examples", str(impl.diff_examples),
                             "--seed", str(seed)]))
        else:
            out.append((f"host {profile}", [*cli, "host", *common, "--", *impl.argv()]))
    return out


#: what one job gave: (what it was, its results.json or None, the last line it printed)
Outcome = tuple[str, "dict | None", str]


def run_jobs(impl: Implementation, seed: int, timeout: float) -> list[Outcome]:
    """Every job that judges ``impl``, run as a user runs it."""
    out = []
    with tempfile.TemporaryDirectory(prefix="gve-corpus-") as tmp:
        for what, argv in jobs_of(impl, Path(tmp), seed):
            folder = Path(argv[argv.index("--report-dir") + 1])
            out.append((what, *_job(argv, folder, timeout)))
    return out


def grade(impl: Implementation, outcomes: list[Outcome]) -> Trial:
    """``impl``'s jobs against its departures: a FAIL or ERROR naming a rule outside them
    is unfair, a departure that no job FAILed is power lost."""
    result = Trial(impl.name)
    caught: set[str] = set()
    for what, results, last in outcomes:
        if results is None:
            result.unfair.append(f"{what}: no results ({last})")
            continue
        result.said.append(f"{what}: {results.get('verdict')} — {results.get('reason')}")
        if not any(results.get("counts", {}).get(v) for v in JUDGED):
            result.unfair.append(f"{what}: nothing judged ({results.get('reason')})")
        for case, verdict, rules in failed_rules(results):
            outside = [r for r in rules if r not in impl.departures]
            caught.update(r for r in rules if r in impl.departures)
            if verdict == "ERROR" and not outside:
                # a crash of the suite is never a departure of the implementation
                outside = ["a defect of the suite"]
            known = [r for r in outside if r in impl.open]
            if known:
                result.open.append(f"{what}: {verdict} {case}: {', '.join(known)} (open: "
                                   f"{'; '.join(impl.open[r] for r in known)})")
            outside = [r for r in outside if r not in impl.open]
            if outside:
                result.unfair.append(f"{what}: {verdict} {case}: {', '.join(outside)}")
    result.departures_missed = [f"departure no longer FAILed: {rule} ({why})"
                                for rule, why in impl.departures.items() if rule not in caught]
    return result


def trial(impl: Implementation, seed: int, timeout: float) -> Trial:
    """Every job of ``impl``, graded against its departures."""
    start = time.perf_counter()
    result = grade(impl, run_jobs(impl, seed, timeout))
    result.seconds = time.perf_counter() - start
    return result


def _trial(args: tuple[Implementation, int, float]) -> Trial:
    return trial(*args)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    ap = Parser(prog=PROG, description=summary(__doc__), examples=(
        "gve-conformance corpus --jobs 2",
        "gve-conformance corpus --implementation gve84-a -v"),
        parents=[job_options("also list what every job said",
                             seed="diff's seed (default 0: the same sequences every run)",
                             jobs="units judged in parallel, and as many hosts "
                                  "beside them (a host mostly waits on its line)",
                             time_limit=TIME_LIMIT_HELP)])
    ap.add_argument("--implementation", action="append", default=[], metavar="NAME",
                    help="only this implementation (repeatable; default: every one)")
    ap.add_argument("--manifest", type=Path, default=MANIFEST,
                    help="the corpus's manifest (default %(default)s)")
    ap.add_argument("--timeout", type=positive, default=900,
                    help="seconds one job may take before it counts as unfair (default 900)")
    try:
        args = ap.parse_args(argv)
        corpus = load_manifest(args.manifest)
        names = {i.name for i in corpus}
        wrong = [n for n in args.implementation if n not in names]
        if wrong:
            raise UsageError(f"unknown implementation(s) {', '.join(wrong)} "
                             f"(known: {', '.join(sorted(names))})")
        gate = Gate("corpus", args, argv)
    except UsageError as err:
        print(f"{PROG}: {err}", file=sys.stderr)
        return 2
    chosen = [i for i in corpus if not args.implementation or i.name in args.implementation]
    seed = 0 if args.seed is None else args.seed
    trials: list[Trial] = []
    with workers(args.jobs, args.seconds) as pool, Progress(
            len(chosen), unit="implementation", quiet=args.quiet, verbose=args.verbose,
            every_step=True, heartbeat=HEARTBEAT) as shown:
        for t in pool.map(_trial, [(i, seed, float(args.timeout)) for i in chosen],
                          lane=lambda job: job[0].kind):
            trials.append(t)
            shown.step("\n".join(_lines(t, args.verbose)), routine=t.fair)
    rest = chosen[len(trials):]
    fair = sum(t.fair for t in trials)
    still_open = sum(len(t.open) for t in trials)
    items = [GateItem(t.name, t.fair, t.seconds, _lines(t, False)) for t in trials]
    return gate.end(
        items, [i.name for i in chosen[len(trials):]], "implementation",
        f"corpus: {fair}/{len(trials)} implementations fair (every FAIL a documented "
        f"departure, every departure still FAILed) in "
        f"{time.perf_counter() - gate.start:.1f} s"
        + (f"; {still_open} FAIL(s) of the suite's open defects listed" if still_open
           else ""),
        interrupted=pool.interrupted, timed_out=pool.timed_out, failed_word="unfair",
        under_way=sum(min(args.jobs, n) for n in Counter(i.kind for i in rest).values()))


def _lines(t: Trial, verbose: bool) -> list[str]:
    head = "fair  " if t.fair else "UNFAIR"
    return [f"{head}  {t.name:16} in {t.seconds:.1f} s",
            *(f"        {line}" for line in (t.said if verbose or not t.fair else [])),
            *(f"        {line}" for line in t.unfair + t.departures_missed),
            *(f"        open defect of the suite: {line}" for line in t.open)]


if __name__ == "__main__":
    sys.exit(main())
