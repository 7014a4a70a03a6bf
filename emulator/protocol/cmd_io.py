"""The commands of spec 10 that read and write the unit's words: identification, EEPROM,
output and input ports, status words and flags, and the GVE114's spindle (spec 12).

Handlers parse every field before they check ranges or state (spec 3), like those of
cmd_motion.py.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable

from emulator.protocol.device import Device
from emulator.protocol.params import CommandError, dec, decfloat, fields, hexa, within
from emulator.protocol.reply import Reply
from emulator.protocol.session import Session
from emulator.protocol.state import QUEUE_FULL
from gve_fixtures.protocol import ErrorCode

Handler = Callable[[Device, Session, str, int], Reply]


def cmd_version(dev: Device, ses: Session, p: str, t: int) -> Reply:
    return [dev.profile.version]


def cmd_processor(dev: Device, ses: Session, p: str, t: int) -> Reply:
    return [dev.profile.processor_id]


# -- EEPROM (spec 10.6) ----------------------------------------------------------------

def cmd_eeprom_read(dev: Device, ses: Session, p: str, t: int) -> Reply:
    address = dev.eeprom_cell(within(hexa(p), 0, 0xFF))
    return ["%02X" % dev.eeprom.read(address)[0]]


def cmd_eeprom_write(dev: Device, ses: Session, p: str, t: int) -> Reply:
    a, x = (hexa(f) for f in fields(p, (2,)))
    data = bytes([within(x, 0, 0xFF)])
    dev.write_eeprom(dev.eeprom_cell(within(a, 0, 0xFF)), data, t)
    return []


def _word_address(address: int) -> int:
    """A 4-byte word's first address: the word must end by FF."""
    return within(address, 0, 0xFF - 3)


def cmd_float_read(dev: Device, ses: Session, p: str, t: int) -> Reply:
    (value,) = struct.unpack("<f", dev.eeprom.read(_word_address(hexa(p)), 4))
    return ["%.7g" % value]


def cmd_float_write(dev: Device, ses: Session, p: str, t: int) -> Reply:
    a, x = fields(p, (2,))
    address, value = hexa(a), decfloat(x)
    address = _word_address(address)
    try:
        data = struct.pack("<f", value)
    except OverflowError as err:
        raise CommandError(ErrorCode.RANGE, "not a float32") from err
    if not math.isfinite(struct.unpack("<f", data)[0]):
        raise CommandError(ErrorCode.RANGE, "not a finite float32")
    dev.write_eeprom(address, data, t)
    return []


def cmd_uint_read(dev: Device, ses: Session, p: str, t: int) -> Reply:
    (value,) = struct.unpack("<I", dev.eeprom.read(_word_address(hexa(p)), 4))
    return [str(value)]


def cmd_uint_write(dev: Device, ses: Session, p: str, t: int) -> Reply:
    a, x = fields(p, (2,))
    address, value = hexa(a), dec(x)
    data = struct.pack("<I", within(value, 0, 0xFFFFFFFF))
    dev.write_eeprom(_word_address(address), data, t)
    return []


# -- ports ----------------------------------------------------------------------------------

def cmd_output(dev: Device, ses: Session, p: str, t: int) -> Reply:
    """O p,x: output port p (only 0 exists), byte x, active low (spec 10 O [D])."""
    port, byte = fields(p, (2,))
    port_n, value = dec(port), hexa(byte)
    within(port_n, 0, 0)
    within(value, 0, 0xFF)
    if dev.mutant.active("output-ignored-while-busy") and dev.motion.queued(t):
        return []
    dev.state.outputs = value
    return []


def read_input(port: int) -> Handler:
    def handler(dev: Device, ses: Session, p: str, t: int) -> Reply:
        value = dev.inputs[port]
        if dev.mutant.active("input-bits-swapped"):
            value = value & 0xF9 | (value & 2) << 1 | (value & 4) >> 1
        return ["%02X" % value]
    handler.__name__ = f"cmd_input_{port}"
    return handler


# -- status words (spec 10.3) -----------------------------------------------------------------

def cmd_status_read(dev: Device, ses: Session, p: str, t: int) -> Reply:
    n = within(dec(p), 0, 6)
    return ["%02X" % (dev.st6(t) if n == 6 else dev.state.status[n])]


def cmd_status_write(dev: Device, ses: Session, p: str, t: int) -> Reply:
    a, x = fields(p, (2,))
    n, value = dec(a), hexa(x)
    if value > 0xFF and 0 <= n <= 5 and dev.mutant.active("refused-status-write-stored"):
        dev.write_status(n, value & 0xFF, t)
    dev.write_status(within(n, 0, 6), within(value, 0, 0xFF), t)
    return []


def cmd_flags(dev: Device, ses: Session, p: str, t: int) -> Reply:
    full = dev.motion.queued(t) >= dev.capacity()
    return ["%02X" % (dev.st6(t) | (QUEUE_FULL if full else 0))]


# -- the GVE114's spindle at address 7 (spec 12) ----------------------------------------------

def cmd_spindle(dev: Device, ses: Session, p: str, t: int) -> Reply:
    sp = dev.profile.spindle
    assert sp is not None
    value = dec(p)
    if not sp.range.lo <= value <= sp.range.hi and dev.mutant.active("spindle-refused-stored"):
        stored = min(max(value, sp.range.lo), sp.range.hi)
        dev.state.spindle = stored
        dev.state.outputs = dev.state.outputs & 0xFE if stored else dev.state.outputs | 0x01
    within(value, sp.range.lo, sp.range.hi)
    dev.state.spindle = value
    if value and dev.mutant.active("spindle-sets-feed-rate"):
        dev.state.modal.V = value
    on = value >= 10 if dev.mutant.active("spindle-low-end-off") else value > 0
    dev.state.outputs = dev.state.outputs & 0xFE if on else dev.state.outputs | 0x01
    return []
