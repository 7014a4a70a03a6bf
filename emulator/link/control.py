"""The control channel: one command a line, for what a test rig's hands would do
(the protocol is documented for clones' simulators in docs/rig.md).

    in PORT HEX        set an input port's byte (in 1 7F)
    switch AXIS POS    place a virtual reference switch (switch Y -1500; switch Y none)
    rate POS           set the rate switch (jumpers) to position POS, 0-based in the
                       profile's list, read at the next power-on (rate none: as found)
    power-on           power-cycle the unit(s)
    state              print the state as one JSON line
    quit | exit        stop the emulator
    help               list these

``@ADDRESS`` at the end of a line picks one unit. Every line gets one reply: ``ok``,
one JSON line, or ``error: ...``; nothing here can crash the server.
"""

from __future__ import annotations

import json
from collections.abc import Callable

from emulator.link.line import Line
from emulator.link.url import parse_address
from emulator.link.words import decimal, hex_byte

HELP = ("commands: in PORT HEX | switch AXIS POS|none | rate POS|none | power-on | state "
        "| quit  [@ADDRESS]")


class Quit(Exception):
    pass


def _input(line: Line, args: list[str], address: int | None) -> str:
    if args[0] not in ("0", "1", "2"):
        return f"error: in PORT HEX: PORT is 0, 1 or 2, not {args[0][:40]!r}"
    line.set_input(int(args[0]), hex_byte(args[1], "in PORT HEX: HEX"), address)
    return "ok"


def _switch(line: Line, args: list[str], address: int | None) -> str:
    axis = args[0].upper()
    if axis not in ("X", "Y", "Z", "A"):
        return f"error: switch AXIS POS: AXIS is X, Y, Z or A, not {args[0][:40]!r}"
    position = (None if args[1].lower() == "none" else
                decimal(args[1], "switch AXIS POS: POS", signed=True))
    line.set_switch(axis, position, address)
    return "ok"


def _rate(line: Line, args: list[str], address: int | None) -> str:
    position = None if args[0].lower() == "none" else decimal(args[0], "rate POS: POS")
    line.set_rate_switch(position, address)
    return "ok"


def _power_on(line: Line, args: list[str], address: int | None) -> str:
    line.power_on(address)
    return "ok"


def _state(line: Line, args: list[str], address: int | None) -> str:
    if address is None and len(line.units) > 1:
        return json.dumps({str(u.address): u.snapshot(line.now) for u in line.units})
    return json.dumps(line.state(address))


def _quit(line: Line, args: list[str], address: int | None) -> str:
    if address is not None:
        return "error: quit takes no arguments"
    raise Quit


def _help(line: Line, args: list[str], address: int | None) -> str:
    return HELP


#: command -> (number of arguments, what it does)
COMMANDS: dict[str, tuple[int, Callable[[Line, list[str], int | None], str]]] = {
    "in": (2, _input), "switch": (2, _switch), "rate": (1, _rate), "power-on": (0, _power_on),
    "state": (0, _state), "quit": (0, _quit), "exit": (0, _quit), "help": (0, _help),
}


def handle(line: Line, text: str) -> str | None:
    """Run one control line; returns its reply (None for an empty line)."""
    words = text.split()
    if not words:
        return None
    address = None
    try:
        if words[-1].startswith("@"):
            address = parse_address(words.pop()[1:])
        if not words:
            raise ValueError("no command before the address")
        arity, run = COMMANDS.get(words[0].lower(), (-1, _help))
        if arity != len(words) - 1:
            raise ValueError(f"unknown control command {text.strip()!r} ({HELP})")
        return run(line, words[1:], address)
    except (ValueError, KeyError, IndexError) as err:
        return f"error: {err}"
