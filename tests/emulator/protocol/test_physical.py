"""The rig's view of where the axes physically are (docs/rig.md: `physical`, `excursion`):
N, N<axis>, J and power-on move the counters, not the axes; a W reference run moves the
axis; the excursion covers every position an axis has been at, also on a halted ramp."""

from __future__ import annotations

from tests.emulator.replay import open_line


def ask(port, body: str, address: int = 0) -> bytes:
    port.write(f"!{address}{body}\r".encode())
    return port.read_until(b"\r")


def test_counter_resets_leave_the_physical_position() -> None:
    port = open_line("GVE84-100")
    assert ask(port, "L300,-200,50") == b"0\r"
    port.line.advance(2.0)
    assert ask(port, "N") == b"0\r"
    assert ask(port, "NY1000") == b"0\r"
    state = port.line.state()
    assert state["position"] == [0, 1000, 0]
    assert state["physical"] == [300, -200, 50]
    assert ask(port, "J") == b"0\r"
    port.line.advance(2.5)
    port.line.power_on()
    port.line.advance(2.5)
    state = port.line.state()
    assert state["position"] == [0, 0, 0]
    assert state["physical"] == [300, -200, 50]
    assert state["excursion"] == [[0, 300], [-200, 0], [0, 50]]


def test_excursion_covers_the_way_there_and_back() -> None:
    port = open_line("GVE114-500")
    assert ask(port, "C-400,0,0,100") == b"0\r"
    assert ask(port, "C600,0,0,0") == b"0\r"
    port.line.advance(5.0)
    assert ask(port, "N") == b"0\r"
    assert ask(port, "L-50,0,0") == b"0\r"
    port.line.advance(1.0)
    state = port.line.state()
    assert state["physical"] == [150, 0, 0, 100]
    assert state["excursion"] == [[-400, 200], [0, 0], [0, 0], [0, 100]]


def test_a_halted_vector_counts_only_as_far_as_it_went() -> None:
    port = open_line("GVE84-100")
    assert ask(port, "L5000,0,0") == b"0\r"
    port.line.advance(0.5)
    assert ask(port, "H") == b"8\r"
    stopped = int(ask(port, "PF")[2:].split(b",")[0])
    assert 0 < stopped < 5000
    assert ask(port, "D") == b"0\r"
    assert port.line.state()["excursion"][0] == [0, stopped]


def test_reference_run_moves_the_axis_to_the_switch_and_back_one_step() -> None:
    port = open_line("GVE84-100")
    assert ask(port, "NY500") == b"0\r"                 # counters only: the axis is at 0
    port.line.set_switch("Y", -1500)                   # a place on the machine
    assert ask(port, "WY,-20000,1000,2000,500") == b"0\r"
    state = port.line.state()
    assert state["position"] == [0, 0, 0]
    assert state["physical"] == [0, -1499, 0]
    assert state["excursion"][1] == [-1500, 0]


def test_gve54_reports_sixteenths() -> None:
    port = open_line("GVE54", 1)
    assert ask(port, "M4", 1) == b"0\r"
    assert ask(port, "L10,0,-10", 1) == b"0\r"
    port.line.advance(1.0)
    assert ask(port, "N", 1) == b"0\r"
    state = port.line.state()
    assert state["position"] == [0, 0, 0]
    assert state["physical"] == [40, 0, -40]
    assert state["excursion"] == [[0, 40], [0, 0], [-40, 0]]
