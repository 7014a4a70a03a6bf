"""What the session says it put back (conformance/targets/session.py, the restorations)
is what it did and what the unit then showed, read back; what it did not bring back is a
problem, never a "restored" line. The unit is the emulator in process in virtual time,
judged as a real unit; its `state` tells the truth."""

from __future__ import annotations

from conformance.known_state.rest import ToRest
from tests.conformance.safety.units import virtual_unit


def _moved_out(unit, body: str = "L394,0,0"):
    session = unit.begin()
    link = session.open_link()
    assert link.send(body).ok
    link.wait(2.0)
    assert link.send("SR6").values == ["00"]
    return session


def test_after_ctrl_c_the_axes_left_out_are_a_problem_and_the_counters_say_what_was_set():
    unit = virtual_unit(max_travel=500)
    session = _moved_out(unit)
    session.interrupts.signal()
    report = session.finish()
    state = unit.state()
    assert state["physical"] == [394, 0, 0] and state["position"] == [394, 0, 0]
    assert ("axes not brought back where the run began (no motion after a signal): X 394, "
            "Y 0, Z 0 full steps from there") in report.problems
    assert not [line for line in report.restored if line.startswith("axes")]
    # the counters count as found (0,0,0 then) from where the run began: X reads 394
    (counters,) = [line for line in report.restored if line.startswith("position counters")]
    assert counters == ("position counters count from where they did before the run (found "
                        "0,0,0, the axes now X 394, Y 0, Z 0 full steps from there): NX394, "
                        "NY0, NZ0; PF reads 394,0,0")


def test_axes_brought_back_and_counters_as_found_say_the_frames_and_the_reads():
    unit = virtual_unit(max_travel=500)
    unit.line.units[0].device.motion.set_position(0, 1234, unit.line.now)   # found at 1234
    session = _moved_out(unit, "L-250,100,0")
    report = session.finish()
    state = unit.state()
    assert state["physical"] == [0, 0, 0] and state["position"] == [1234, 0, 0]
    assert report.problems == []
    assert report.restored[:2] == [
        "axes back where the run began (moved back with L250,-100,0 at V1000); PF then read "
        "0,0,0, where the frames put them",
        "position counters as found: PF reads 1234,0,0 (set with NX1234, NY0, NZ0)"]


def test_a_reset_frame_the_unit_refuses_is_a_problem_not_a_reset_line(monkeypatch):
    frames = ToRest.reset_frames
    monkeypatch.setattr(ToRest, "reset_frames", lambda s: [*frames(s), "T99999"])
    unit = virtual_unit(max_travel=500)
    session = unit.begin()
    session.open_link()
    report = session.finish()
    assert "not set to the reset state: T99999 answered 5" in report.problems
    assert "T99999" not in " ".join(report.reset)
    assert report.reset[0].startswith("set to the reset state, each answered 0 (they cannot "
                                      "be read back): O0,FF, XM100")


def test_the_checksum_mode_found_on_is_read_back_on():
    unit = virtual_unit(max_travel=500)
    unit.line.units[0].session.checksums = True
    session = unit.begin()
    session.start()
    report = session.finish()
    assert unit.state()["checksums"] is True
    assert "checksum mode back on: %+ answered, then ? without a checksum was refused (4)" \
        in report.restored


def test_restorations_that_stop_early_say_where_the_axes_were_left():
    unit = virtual_unit(max_travel=500)
    session = _moved_out(unit)
    unit.line.units[0].device.deaf_until = unit.line.now + 10**15       # gone quiet
    report = session.finish()
    assert any(p.startswith("restorations stopped") for p in report.problems)
    assert any(p.startswith("axes not brought back where the run began (the restorations "
                            "stopped before): X 394") for p in report.problems)
