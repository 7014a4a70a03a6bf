"""Job files: one command a line, `wait`, `position X,Y,Z`; errors name the line."""

from __future__ import annotations

from pathlib import Path

import pytest

import gve_host
from gve_host.job import JobError, Step, load, parse

JOBS = Path(gve_host.__file__).parent / "jobs"


def test_the_sample_jobs():
    job = load(JOBS / "square.job")
    assert job.steps[0] == Step("command", "SW2,00")
    assert job.steps[-1] == Step("position", position=(1000, 0, 0))
    assert any(s.continuous for s in job.steps) and not job.checksums and not job.packets
    fast = load(JOBS / "square-packets.job")
    assert fast.checksums and fast.packets == 4 and fast.steps == job.steps


def test_steps():
    job = parse("use packets 3\nV1000  # speed\n\nC10,0,0\nB500\nwait\nposition 1, 2, 3\n")
    steps = job.steps
    assert job.packets == 3 and not job.checksums
    assert [s.kind for s in steps] == ["command", "command", "command", "wait", "position"]
    assert [s.continuous for s in steps] == [False, True, True, False, False]
    assert steps[-1].position == (1, 2, 3)


@pytest.mark.parametrize("text", ["v1000", "position 1,x", "wait now", "L1 0 0",
                                  "use packets", "use turbo", "V1\nuse checksums"])
def test_bad_lines_are_named(text):
    with pytest.raises(JobError, match=r"job:\d"):
        parse(text)
