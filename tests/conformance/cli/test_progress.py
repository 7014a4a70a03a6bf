"""Long jobs show they are moving: in a log (not a terminal) `mutation`, `fairness` and
a fleet print a numbered line per step (n/N), `diff` a line at every tenth of its
sequences with how many it ran; a terminal gets a bar instead. The jobs whose steps are
long (mutation, fairness, corpus, a launched host) show something at least every 5 s
while a step runs."""

from __future__ import annotations

import io
import re

import pytest

from conformance.cli import corpus, fairness, main, mutation
from conformance.cli.progress import HEARTBEAT, Progress

STEP = re.compile(r"\[(\d+)/(\d+)\] ")


def _steps(out: str) -> list[tuple[int, int, str]]:
    """The numbered lines of steps done (not the heartbeat's, which a loaded machine may
    add between them)."""
    return [(int(m.group(1)), int(m.group(2)), line[m.end():])
            for line in out.splitlines()
            if (m := STEP.match(line)) and not line.endswith(", still working")]


def test_mutation_numbers_each_mutant_in_a_log(capsys):
    mutants = ["range-error-code", "lower-case-command"]
    argv = ["mutation", "--no-reports",
            "--profile", "GVE84-100", "--cases", "1.*", "--cases", "3.*"]
    for m in mutants:
        argv += ["--mutant", m]
    assert main(argv) == 0
    steps = _steps(capsys.readouterr().out)
    assert [(n, total) for n, total, _ in steps] == [(1, 2), (2, 2)]
    assert all(m in text for m, (_, _, text) in zip(mutants, steps, strict=True))


def test_mutation_quiet_prints_its_score_only_when_nothing_failed(capsys):
    assert main(["mutation", "--no-reports", "--profile", "GVE84-100", "--cases", "1.*",
                 "--mutant", "range-error-code", "-q"]) == 0
    (line,) = capsys.readouterr().out.splitlines()
    assert line.startswith("PASSED — mutation score: 1/1")


def test_a_missed_mutant_is_listed_again_at_the_end(capsys):
    # `?` answers alike whatever the range code: that case alone misses the mutant
    assert main(["mutation", "--no-reports",
                 "--profile", "GVE84-100", "--cases", "1.profile.version",
                 "--mutant", "range-error-code", "-q"]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("what failed") and "range-error-code" in lines[1]
    assert lines[-1].startswith("FAILED — mutation score: 0/1")


def test_diff_says_how_far_it_is_at_every_tenth(capsys):
    assert main(["diff", "--target", "emu:GVE84-100", "--examples", "20", "--no-probes",
                 "--no-reports", "--seed", "3"]) == 0
    steps = _steps(capsys.readouterr().out)
    assert [n for n, _, _ in steps] == list(range(2, 21, 2))
    assert all(total == 20 for _, total, _ in steps)
    assert all(f"{n} sequences" in text for n, _, text in steps)


def test_a_fleet_numbers_each_target_as_it_ends(capsys):
    targets = ["emu:GVE54", "emu:GVE84-100"]
    argv = ["--jobs", "2", "--cases", "1.profile.version", "--no-reports"]
    for t in targets:
        argv += ["--target", t]
    assert main(argv) == 0
    steps = _steps(capsys.readouterr().out)
    assert sorted(n for n, _, _ in steps) == [1, 2]
    assert sorted(text.split(":", 1)[0] + ":" + text.split(":")[1] for _, _, text in steps) \
        == sorted(targets)
    assert all("PASSED" in text for _, _, text in steps)


def test_a_terminal_gets_a_bar_of_the_steps_and_the_lines_that_need_reading():
    out = io.StringIO()
    with Progress(3, unit="mutant", stream=out, terminal=True, refresh=0,
                  every_step=True) as shown:
        shown.step("caught  a", routine=True)
        shown.step("MISSED  b")
        shown.step("caught  c", routine=True)
    text = out.getvalue()
    assert "3/3" in text and "MISSED  b" in text and "caught" not in text



def test_a_long_step_still_shows_the_job_is_moving():
    """A log sees a line at least every heartbeat while a step takes long (a reading, a
    mutant), and none once the job has ended."""
    import io

    from tests.processes import wait_for
    log = io.StringIO()
    with Progress(3, unit="reading", stream=log, terminal=False, heartbeat=0.05,
                  every_step=True) as shown:
        wait_for(lambda: "still working" in log.getvalue(), 5.0, "a heartbeat line")
        shown.step("fair  a reading")
    lines = log.getvalue().splitlines()
    assert lines[0].startswith("[0/3] 0 % in ") and lines[0].endswith(" s, still working")
    ended = log.getvalue()
    assert shown._beat is None and log.getvalue() == ended


#: a long job -> (its step's function, a step done at once, its command line)
LONG = {"mutation": ("_hunt", lambda _: mutation.Hunt("m", "1", "a mutant", caught_by="c"),
                     ["--mutant", "range-error-code"]),
        "fairness": ("_trial", lambda _: fairness.Trial("plus-sign", ["GVE84-100"]),
                     ["--reading", "plus-sign"]),
        "corpus": ("_trial", lambda _: corpus.Trial("gve84-a"),
                   ["--implementation", "gve84-a"])}


@pytest.mark.parametrize("job", sorted(LONG))
def test_a_long_job_shows_it_is_moving_within_five_seconds(job, monkeypatch, capsys):
    step, done, argv = LONG[job]
    beats: list[float | None] = []
    made = Progress.__init__

    def spy(self, *args, **kw):
        beats.append(kw.get("heartbeat"))
        made(self, *args, **kw)
    monkeypatch.setattr(Progress, "__init__", spy)
    monkeypatch.setattr(f"conformance.cli.{job}.{step}", done)
    assert main([job, "--no-reports", *argv]) == 0, capsys.readouterr().out
    assert beats == [HEARTBEAT] and HEARTBEAT <= 5.0


def test_a_launched_host_shows_it_is_moving_too(capsys):
    import sys
    beats = []
    made = Progress.__init__

    def spy(self, *args, **kw):
        beats.append(kw.get("heartbeat"))
        made(self, *args, **kw)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Progress, "__init__", spy)
        main(["host", "--profile", "GVE84-100", "--no-reports", "--scenarios",
              "2.host.clean", "--", sys.executable, "-m", "gve_host", "{port}", "--job",
              "gve_host/jobs/square-packets.job"])
    out = capsys.readouterr().out
    assert beats == [HEARTBEAT], out
    assert re.search(r"^\[\s*1/\d+\] PASS\s+2.host.clean", out, re.M), out
