"""Pictures from a real run on the emulator: the step train of a motion case, read
through the emulator's rig, and the motion traces the measured cases record."""

from __future__ import annotations

from conformance.reports.html import render_html
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target


def test_the_step_train_of_a_motion_case_is_drawn():
    result = run([parse_target("emu:GVE84-100")], select(["10.2.motion.targets-reached"]))
    (case,) = result.results
    (train,) = [t for t in case.traces if "pulses" in t]
    # the vectors (100,-37,5), (-250,40,0), (3,3,-3): X dominates, one pulse per X step
    x_steps = [m for _, m in train["pulses"] if m & 1]
    assert train["total"] == len(x_steps) == 100 + 250 + 3
    assert sum(1 for m in x_steps if m & 0x10) == 250                # X backwards
    assert sum(1 for _, m in train["pulses"] if m & 2) == 37 + 40 + 3  # Y's steps
    times = [t for t, _ in train["pulses"]]
    assert times == sorted(times) and times[0] > 0
    page = render_html(result)
    assert "step train: the first 120 of 353 pulses" in page


def test_measured_motion_cases_draw_their_traces():
    result = run([parse_target("emu:GVE84-100")], select(["10.2.measured.cruise-at-v"]))
    (case,) = result.results
    assert case.traces and case.verdict == "PASS"
    page = render_html(result)
    figure = page[page.index("<figure>", page.index("id='cases'")):]
    assert figure.startswith("<figure><svg") and "10.2.measured.cruise-at-v" in figure
