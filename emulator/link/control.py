"""The control channel: one command a line, for what a test rig's hands would do.

    in PORT HEX        set an input port's byte (in 1 7F)
    switch AXIS POS    place a virtual reference switch (switch Y -1500; switch Y none)
    power-on           power-cycle the unit(s)
    state              print the state as one JSON line
    quit | exit        stop the emulator
    help               list these

Unknown or malformed lines answer ``error: ...``; nothing here can crash the server.
"""

from __future__ import annotations

import json

from emulator.link.line import Line

HELP = "commands: in PORT HEX | switch AXIS POS|none [@ADDR] | power-on | state | quit"


class Quit(Exception):
    pass


def _address(words: list[str]) -> tuple[list[str], int | None]:
    if words and words[-1].startswith("@"):
        return words[:-1], int(words[-1][1:])
    return words, None


def handle(line: Line, text: str) -> str | None:
    """Run one control line; returns the text to print (or None)."""
    try:
        words, address = _address(text.split())
        if not words:
            return None
        cmd, args = words[0].lower(), words[1:]
        if cmd in ("quit", "exit"):
            raise Quit
        if cmd == "help":
            return HELP
        if cmd == "in" and len(args) == 2:
            port, value = int(args[0]), int(args[1], 16)
            if port not in (0, 1, 2) or not 0 <= value <= 0xFF:
                return "error: in PORT HEX with PORT 0..2 and HEX 00..FF"
            line.set_input(port, value, address)
            return "ok"
        if cmd == "switch" and len(args) == 2:
            pos = None if args[1].lower() == "none" else int(args[1])
            line.set_switch(args[0].upper(), pos, address)
            return "ok"
        if cmd == "power-on" and not args:
            line.power_on(address)
            return "ok"
        if cmd == "state" and not args:
            if address is None and len(line.units) > 1:
                return json.dumps({str(u.address): u.snapshot(line.now) for u in line.units})
            return json.dumps(line.state(address))
    except Quit:
        raise
    except (ValueError, KeyError) as err:
        return f"error: {err}"
    return f"error: unknown control command {text.strip()!r} ({HELP})"
