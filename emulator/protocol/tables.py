"""The command tables: every command of spec 10 with what the unit needs to know about
it besides its handler, and the table each address of a unit answers from.

A table is built per address from the profile: address 0 (or the unit's own) from the
profile's command set; the GVE114's spindle address 7 from its own set, where `V` is
the spindle (spec 12). A name outside the table answers 3.
"""

from __future__ import annotations

from dataclasses import dataclass

from emulator.protocol import cmd_io as io
from emulator.protocol import cmd_motion as mo
from emulator.protocol import cmd_session as se
from emulator.protocol.cmd_motion import Handler
from gve_fixtures.profile import Profile

MEMBER = "member"      # inside an open packet: a member (spec 7)
DISCARD = "discard"    # runs at once and discards the open packet
CLOSE = "close"        # runs at once with the open packet (*E)


@dataclass(frozen=True)
class Command:
    run: Handler
    bare: bool = False          # takes no parameters: any given → 4 (spec 3)
    counted: bool = True        # advances the index (spec 8)
    remembered: bool = True     # the last answered frame for > (spec 8)
    packet: str = MEMBER        # what it does inside an open packet (spec 7)
    while_pending: bool = False  # answered while an H or W answer is due


def _bare(run: Handler, **flags: object) -> Command:
    return Command(run, bare=True, **flags)  # type: ignore[arg-type]


#: every command by the name it has on the wire
COMMANDS: dict[str, Command] = {
    "?": _bare(io.cmd_version), "Q": _bare(io.cmd_processor),
    "L": Command(mo.cmd_line), "C": Command(mo.cmd_cont),
    "T": Command(mo.modal("T", "T")), "$": Command(mo.modal("$", "dollar")),
    "A": Command(mo.modal("A", "A")), "V": Command(mo.modal("V", "V")),
    "B": Command(mo.modal("B", "B")), "VL": Command(mo.cmd_axis_limits),
    "VK": _bare(mo.path_speed(True)), "VN": _bare(mo.path_speed(False)),
    "XA": _bare(mo.cmd_xa), "XU": _bare(mo.scale(17, 16)), "XD": _bare(mo.scale(15, 16)),
    "XM": Command(mo.cmd_xm),
    "P": _bare(mo.positions(2)), "PF": _bare(mo.positions(3)),
    "N": _bare(mo.cmd_zero), "NX": Command(mo.set_axis(0)), "NY": Command(mo.set_axis(1)),
    "NZ": Command(mo.set_axis(2)), "NA": Command(mo.set_axis(3)),
    "W": Command(mo.cmd_reference),
    "H": _bare(mo.cmd_halt, packet=DISCARD, while_pending=True),
    "G": _bare(mo.cmd_go), "D": _bare(mo.cmd_delete),
    "K": _bare(mo.cmd_keep), "R": _bare(mo.cmd_restore),
    "M": Command(mo.cmd_motor), "Y": Command(mo.cmd_mpg),
    "ER": Command(io.cmd_eeprom_read), "EW": Command(io.cmd_eeprom_write),
    "EFR": Command(io.cmd_float_read), "EFW": Command(io.cmd_float_write),
    "EUR": Command(io.cmd_uint_read), "EUW": Command(io.cmd_uint_write),
    "O": Command(io.cmd_output),
    "I0": _bare(io.read_input(0)), "I1": _bare(io.read_input(1)), "I2": _bare(io.read_input(2)),
    "SR": Command(io.cmd_status_read), "SW": Command(io.cmd_status_write),
    "F": _bare(io.cmd_flags),
    "@": _bare(se.cmd_index, counted=False, remembered=False, packet=DISCARD),
    ">": _bare(se.cmd_repeat, counted=False, remembered=False, packet=DISCARD),
    "J": _bare(se.cmd_restart, packet=DISCARD),
    "%": Command(se.cmd_checksum_mode),
    "*S": _bare(se.cmd_packet_start, remembered=False, packet=DISCARD),
    "*E": Command(se.cmd_packet_end, packet=CLOSE),
}

#: the spindle's V at the GVE114's address 7 (spec 12)
SPINDLE_V = Command(io.cmd_spindle)

# profiles name the output command by its only port (`O0`); on the wire it is `O p,x`
_WIRE = {"O0": "O"}


def main_table(profile: Profile) -> dict[str, Command]:
    """The commands of the unit's own address: the profile's command set."""
    return {_WIRE.get(n, n): COMMANDS[_WIRE.get(n, n)] for n in profile.commands}


def spindle_table(profile: Profile) -> dict[str, Command]:
    """The GVE114's address 7: the spindle's V and the few commands shared with 0."""
    assert profile.spindle is not None
    table = {_WIRE.get(n, n): COMMANDS[_WIRE.get(n, n)] for n in profile.spindle.commands}
    table["V"] = SPINDLE_V
    return table


def split(body: str) -> tuple[str | None, str]:
    """The command name at the start of ``body`` (the longest of the protocol's names
    that matches) and its parameter text."""
    for k in (3, 2, 1):
        name = body[:k]
        if len(name) == k and name in COMMANDS:
            return name, body[k:]
    return None, body
