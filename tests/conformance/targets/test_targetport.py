"""A port that fails mid-run (a USB adapter pulled out: here the pseudo-terminal's other
side gone with its emulator) ends the run for its target with the target's failure, at
once: never an ERROR of the suite, never a wait for frames nobody answers."""

from __future__ import annotations

import os
import pty
import time

import pytest
import serial

from conformance.link.exclusive import open_serial
from conformance.link.link import Link
from conformance.link.liveness import TargetNotResponding
from conformance.link.safety import EmulatorGuard
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.targets.targetport import TargetPort
from conformance.verdicts.verdict import COULD_NOT_TEST, ERROR, FAIL, PASS
from gve_fixtures.profile import load_profile
from tests.emulator.process import Emulator


class Unplugged:
    """A pyserial port whose every use fails as a pulled-out adapter's does."""

    def _fail(self, *args, **kwargs):
        raise serial.SerialException("device reports readiness to read but returned no "
                                     "data (device disconnected or multiple access on port?)")

    read = read_until = write = reset_input_buffer = _fail

    @property
    def in_waiting(self):
        raise OSError(5, "Input/output error")

    def close(self):
        raise OSError(5, "Input/output error")


@pytest.mark.parametrize("use", [lambda p: p.read(1), lambda p: p.read_until(b"\r"),
                                 lambda p: p.write(b"!0?\r"), lambda p: p.in_waiting,
                                 lambda p: p.reset_input_buffer()])
def test_every_use_of_a_failed_port_is_the_target_gone(use):
    with pytest.raises(TargetNotResponding, match=r"the target's port failed: .*(disconnected"
                       r"|Input/output error)"):
        use(TargetPort(Unplugged()))
    TargetPort(Unplugged()).close()           # closing what is gone is no error


class Ended:
    """A program that was killed: what TargetPort asks of the program behind it."""

    alive = False

    def wait(self, seconds: float) -> bool:
        return True

    def ended(self) -> str:
        return "clone-sim --pty was killed by signal 9"


@pytest.mark.pty
@pytest.mark.parametrize("use", [
    lambda p: p.read(1), lambda p: p.read_until(b"\r"), lambda p: p.write(b"!0?\r"),
    lambda p: p.in_waiting, lambda p: p.reset_input_buffer(), lambda p: p.flush(),
    lambda p: setattr(p, "timeout", 0.3)], ids=[
    "read", "read_until", "write", "in_waiting", "reset_input_buffer", "flush", "timeout"])
@pytest.mark.parametrize("program", [None, Ended()], ids=["port", "program"])
def test_every_use_of_a_hung_up_pty_is_the_target_gone(use, program):
    """The pseudo-terminal of a program that ended is hung up: every ioctl on it fails
    (termios' as termios.error, which is no OSError), also the one pyserial makes when a
    link sets the port's timeout between a frame and its answer."""
    master, slave = pty.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    port = TargetPort(open_serial(path, baudrate=115200, timeout=0.5), program)
    os.close(master)                         # the program's end: its side of the pty closed
    why = (r"the target's program ended: clone-sim --pty was killed by signal 9"
           if program else r"the target's port failed: .*(disconnected|Input/output error)")
    with pytest.raises(TargetNotResponding, match=why):
        use(port)
    port.close()


class DiesOnTheFrame:
    """A program killed the instant a frame reaches it: its pty hung up once the frame
    is written, before the link asks for the answer."""

    def __init__(self, master: int) -> None:
        self.master = master
        self.alive = True

    def written(self) -> None:
        os.close(self.master)
        self.alive = False

    def wait(self, seconds: float) -> bool:
        return True

    def ended(self) -> str:
        return "" if self.alive else "clone-sim --pty was killed by signal 9"


@pytest.mark.pty
def test_a_program_killed_as_its_frame_is_written_ends_the_frame_with_the_target_gone():
    """Between the frame's write and the answer's read the link sets the port's timeout:
    the program dead by then is the target gone there too (it was an ERROR)."""
    master, slave = pty.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    program = DiesOnTheFrame(master)
    serial_port = open_serial(path, baudrate=115200, timeout=0.5)
    write = serial_port.write

    def write_then_die(data: bytes) -> int | None:
        n = write(data)
        program.written()
        return n

    serial_port.write = write_then_die
    link = Link(TargetPort(serial_port, program), EmulatorGuard(load_profile("GVE84-100"), 0))
    with pytest.raises(TargetNotResponding, match="program ended: clone-sim --pty was killed"):
        link.send("?")
    serial_port.close()


@pytest.mark.pty
def test_a_unit_unplugged_mid_run_ends_the_run_with_the_target_s_failure():
    emulator = Emulator("--model", "GVE84-100", "--pty")
    target = parse_target(f"serial:{emulator.first}", profile="GVE84-100")
    target.preflight()

    def unplug_after_the_first(result) -> None:
        if emulator.proc.poll() is None:
            emulator.stop()

    try:
        start = time.monotonic()
        result = run([target], select(["5.errors.ok", "5.errors.unknown", "6.*"]),
                     on_result=unplug_after_the_first)
        took = time.monotonic() - start
    finally:
        emulator.stop()
    got = [r.verdict for r in result.results]
    assert ERROR not in got, [(r.id, r.notes) for r in result.results if r.verdict == ERROR]
    assert got[0] == PASS and got[1] == FAIL and set(got[2:]) == {COULD_NOT_TEST}, got
    assert "port failed" in result.results[1].failed_checks[0]["what"]
    assert took < 20, f"{took:.1f} s"
