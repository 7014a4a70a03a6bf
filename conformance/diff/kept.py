"""A search's findings on disk as they come, so that a `diff` killed at any instant
keeps what it found: a disagreement's transcript (`diff-NN.gvt`) as soon as it is seen,
rewritten once it is shrunk (or taken away when it turns out to be one already kept, or
not seen again in real time), one JSON line per event in `findings.jsonl` (flushed to the
disk), and the reports rewritten after every finding kept. A file that cannot be written
(a full disk) is said in one line on standard error, and nothing more is written: the
findings stay in the run's results, which its end reports as any run's."""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Callable
from pathlib import Path

from conformance.diff.compare import delays
from conformance.diff.engine import Finding
from conformance.diff.gvt import transcript, write
from conformance.diff.results import finding_result
from conformance.link.framing import readable
from conformance.reports import write_reports
from conformance.reports.files import ReportNotWritten
from conformance.run.runner import RunResult

#: the file of events, one JSON object a line
EVENTS = "findings.jsonl"


class Kept:
    """Keeps a search's findings in ``folder`` (None: printed only)."""

    def __init__(self, run: RunResult, folder: Path | None, *, profile: str, target: str,
                 reference: str, seed: int, say: Callable[[str], None],
                 verbose: bool = False, prog: str = "gve-conformance diff") -> None:
        self.run = run
        self.folder = folder
        self.profile, self.target, self.reference, self.seed = profile, target, reference, seed
        self.say = say
        self.verbose = verbose
        self.paths: dict[int, Path] = {}
        self.count = 0                 # findings kept: their transcripts are numbered so
        self.prog = prog
        self.lost = False              # a write failed: said once, nothing written after

    def _disk(self, write: Callable[[], object]) -> bool:
        """``write()`` unless a write failed before; False (after one line naming the file
        and why, the first time) when it cannot be done."""
        if self.lost:
            return False
        try:
            write()
            return True
        except (ReportNotWritten, OSError) as err:
            self.lost = True
            print(f"{self.prog}: {err}", file=sys.stderr, flush=True)
            return False

    def _transcript(self, f: Finding):
        return transcript(f, profile=self.profile, target=self.target,
                          reference=self.reference, seed=self.seed)

    def _path(self, f: Finding) -> Path | None:
        if self.folder is None or self.lost:
            return None
        self._disk(lambda: self.folder.mkdir(parents=True, exist_ok=True))
        return self.paths.setdefault(f.number, self.folder / f"diff-{f.number:02d}.gvt")

    def _event(self, event: str, f: Finding, path: Path | None) -> None:
        if self.folder is None:
            return
        d = f.disagreement
        line = {"event": event, "number": f.number, "rule": d.rule, "kind": d.kind,
                "verdict": d.verdict, "tag": d.tag, "command": d.command,
                "sent": readable(d.target.sent), "target": readable(d.target.answer),
                "reference": readable(d.reference.answer), "frames": f.frames,
                # when each answer came after its frame (what differs in a timing kind)
                "after": dict(zip(("target", "reference"), delays(d.target, d.reference),
                                  strict=True)),
                "steps": [str(s) for s in f.steps],
                "transcript": str(path) if path is not None else None}

        def append() -> None:
            with (self.folder / EVENTS).open("a", encoding="utf-8") as out:
                out.write(json.dumps(line) + "\n")
                out.flush()
                os.fsync(out.fileno())
        self._disk(append)

    # -- what the engine tells -------------------------------------------------------------------
    def seen(self, f: Finding) -> None:
        """A disagreement seen, not yet shrunk: its transcript as it ran."""
        path = self._path(f)
        if path is not None:
            t = self._transcript(f)
            t.meta["shrunk"] = "not yet: the sequence as it ran"
            if not self._disk(lambda: write(path, t)):
                path = None
        self._event("seen", f, path)
        if self.verbose:
            d = f.disagreement
            self.say(f"seen: {d.rule or '(no known rule)'} at {readable(d.target.sent)} "
                     f"({d.kind}; {f.frames} frame(s)), shrinking it"
                     + (f"  -> {path}" if path else ""))

    def kept(self, f: Finding) -> None:
        """A finding kept: its shrunk transcript, its result, its line, the reports."""
        path = self._path(f)
        t = self._transcript(f)
        if path is not None and not self._disk(lambda: write(path, t)):
            path = None
        r = finding_result(f, profile=self.profile, target=self.target,
                           transcript=list(t.lines()), path=str(path or ""))
        self.run.results.append(r)
        self.count += 1
        self._event("kept", f, path)
        if self.folder is not None:
            self._disk(lambda: write_reports(self.run, self.folder.parent))
        # said once it is on disk: whoever reads the line finds the files
        d = f.disagreement
        self.say(f"{d.verdict:11} {d.rule or '(no known rule)'}: {readable(d.target.sent)} "
                 f"target {readable(d.target.answer) or '(none)'} / reference "
                 f"{readable(d.reference.answer) or '(none)'} ({d.kind}; {f.frames} frame(s))"
                 + (f"  -> {path}" if path else ""))
        if self.folder is None or self.verbose:
            self.say("\n".join("    " + line for line in t.lines()))

    def dropped(self, f: Finding) -> None:
        """A disagreement seen that is not kept: its early transcript taken away."""
        path = self.paths.pop(f.number, None)
        if path is not None and path.exists():
            self._disk(path.unlink)
        self._event("dropped", f, None)
