"""A real unit as a side: its EEPROM holds its own bytes (the reference is given them
before every sequence) and what a sequence wrote is put back before the next."""

from conformance.case.context import CouldNotTest
from conformance.diff.engine import Pair
from conformance.diff.sides import Side
from conformance.diff.steps import FRAME, INPUT, Step
from conformance.targets import parse_target
from tests.emulator.process import Emulator

#: a unit that has been configured: none of its bytes is a fresh unit's FF
IMAGE = bytes((0x5A + 7 * i) % 0xFF for i in range(256))


def test_a_unit_with_its_own_eeprom_agrees_and_is_left_as_found(tmp_path):
    image = tmp_path / "eeprom.img"
    image.write_bytes(IMAGE)
    emu = Emulator("--model", "GVE84-100", "--pty", "--eeprom", str(image))
    try:
        target = parse_target(f"serial:{emu.first}", profile="GVE84-100",
                              allow_destructive=True)
        reference = parse_target("emu:GVE84-100")
        session = target.begin()
        p = Pair(Side(target, session), Side(reference), target.profile)
        writes = p.run([Step(FRAME, "ER00"), Step(FRAME, "EW00,12"), Step(FRAME, "ER00"),
                        Step(FRAME, "ERC3")])
        reads = p.run([Step(FRAME, "ER00"), Step(FRAME, "ER01")])
        report = session.finish()
        target.close()
    finally:
        emu.proc.terminate()
        emu.proc.wait(10)
    assert writes.disagreement is None and reads.disagreement is None
    answers = [r.target.answer for r in writes.records + reads.records]
    assert answers == [b"0,5A\r", b"0\r", b"0,12\r", b"0,%02X\r" % IMAGE[0xC3],
                       b"0,5A\r", b"0,%02X\r" % IMAGE[1]]
    assert image.read_bytes() == IMAGE and not report.problems


class _DeadRig:
    """A rig that does not answer."""

    def set_input(self, port: int, value: int) -> None:
        raise CouldNotTest(f"the rig did not answer 'in {port} {value:02X}' within 5 s")


def test_a_rig_that_does_not_answer_is_a_rig_that_is_not_there():
    side = Side(parse_target("emu:GVE84-100"))
    side.open()
    side.link.rig = _DeadRig()
    assert side.has_rig
    assert side.set_input(1, 0xFE) is False
    assert not side.has_rig and side.rig_lost == "the rig did not answer 'in 1 FE' within 5 s"
    # the example goes on without the input step, on both sides alike
    p = Pair(side, Side(parse_target("emu:GVE84-100")), side.target.profile)
    out = p.run([Step(INPUT, port=1, value=0xFE), Step(FRAME, "?")])
    assert out.disagreement is None
    assert [r.step.kind for r in out.records] == [FRAME]
