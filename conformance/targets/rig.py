"""The test rig of an ``exec:`` target: docs/rig.md's control channel, spoken over the
program's standard input (commands) and standard output (one reply a line), or as part
of the co-simulation protocol (docs/cosim.md), whose client asks the commands for it.

It offers what the suite uses of a rig (``link.rig``): ``set_input``, ``set_switch``,
``set_rate_switch``, ``power_on``, ``outputs``, ``spindle``, ``state``. What the channel
cannot give is not there: no ``pulses`` (the reports show no step train) and no clock.
Every command waits for its reply, so that what the rig's hands did has happened before
the next frame.

A rig that does not answer in time or refuses a command makes the case COULD-NOT-TEST
(saying which command); a program that has ended makes the target not responding.
"""

from __future__ import annotations

from collections.abc import Callable

from conformance.link.liveness import TargetNotResponding
from conformance.protocol.bounded import decimal, hexadecimal, json_object
from conformance.targets.program import Program
from conformance.verdicts.quoting import shown
from conformance.verdicts.verdict import CouldNotTest

#: asks one command and gives its reply line (raising when there is none)
Ask = Callable[[str], str]

#: how long `state` may take to answer when the suite asks whether there is a rig
DETECT_SECONDS = 1.0
#: how long any later command may take to answer
REPLY_SECONDS = 5.0
#: an input port the rig's hands do not touch reads all ones (nothing grounded)
RELEASED = 0xFF


def over_program(program: Program) -> Ask:
    """Commands on a program's standard input, its reply the next line it prints (lines
    that arrived before are not a reply): no reply in time makes the case COULD-NOT-TEST,
    a program that ended makes the target not responding."""
    def ask(command: str) -> str:
        program.discard()
        reply = program.line(REPLY_SECONDS) if program.send(command) else None
        if reply is None:
            if not program.alive or program.wait(0.5):
                raise TargetNotResponding(program.ended())
            raise CouldNotTest(f"the rig did not answer {command!r} within {REPLY_SECONDS:g} s")
        return reply
    return ask


class ControlRig:
    """The rig over a running program's control channel (see the module's docstring)."""

    def __init__(self, ask: Ask, found: dict, address: int,
                 on_power_on: Callable[[], None] = lambda: None) -> None:
        self.ask = ask
        self.address = address
        self.on_power_on = on_power_on
        # a simulator of several units answers `state` per address: then every command
        # names the target's unit (a simulator of one needs no @ADDRESS)
        self.several = "position" not in found and isinstance(found.get(str(address)), dict)
        self.found = self._unit(found)             # the first `state`, as found
        self._touched: dict[int, int] = {}         # input ports set since the hands were off
        self._switches: set[str] = set()           # axes with a switch the suite placed

    @classmethod
    def detect(cls, program: Program, address: int,
               on_power_on: Callable[[], None] = lambda: None) -> ControlRig | None:
        """The rig, when the program answers `state` with a JSON object within
        DETECT_SECONDS; else None (it has no rig)."""
        program.discard()
        if not program.send("state"):
            return None
        found = json_object(program.line(DETECT_SECONDS))
        return None if found is None else cls(over_program(program), found, address,
                                               on_power_on)

    @classmethod
    def found_in(cls, reply: str, ask: Ask, address: int,
                 on_power_on: Callable[[], None] = lambda: None) -> ControlRig | None:
        """The rig, when ``reply`` (to `state`) is a JSON object; else None (no rig)."""
        found = json_object(reply)
        return None if found is None else cls(ask, found, address, on_power_on)

    # -- the channel ---------------------------------------------------------------------------
    def _ask(self, command: str) -> str:
        reply = self.ask(command)
        if reply.startswith("error"):
            raise CouldNotTest(f"the rig refused {command!r}: {shown(reply)}")
        return reply

    def _do(self, command: str) -> None:
        reply = self._ask(command)
        if reply.strip().lower() != "ok":
            raise CouldNotTest(f"the rig answered {command!r} with {shown(reply)}, not ok")

    def _unit(self, state: dict) -> dict:
        """One unit's state (a simulator of several units answers one per address)."""
        if "position" not in state and isinstance(state.get(str(self.address)), dict):
            return state[str(self.address)]
        return state

    def _at(self, address: int | None) -> str:
        """`` @ADDRESS`` for a command to one unit, when it must say which."""
        if address is None and self.several:
            address = self.address
        return "" if address is None else f" @{address}"

    # -- what the suite uses ---------------------------------------------------------------------
    def set_input(self, port: int, value: int, address: int | None = None) -> None:
        self._do(f"in {port} {value:02X}{self._at(address)}")
        self._touched[port] = value

    def set_switch(self, axis: str, position: int | None, address: int | None = None) -> None:
        where = "none" if position is None else position
        self._do(f"switch {axis} {where}{self._at(address)}")
        self._switches.add(axis)

    def set_rate_switch(self, position: int | None, address: int | None = None) -> None:
        """The unit's rate switch (jumpers) to ``position`` (None: as found), read at the
        next power-on."""
        self._do(f"rate {'none' if position is None else position}{self._at(address)}")

    def power_on(self, address: int | None = None) -> None:
        self._do("power-on" + ("" if address is None else f" @{address}"))   # None: all
        self.on_power_on()

    def state_command(self, address: int | None = None) -> str:
        """The words of :meth:`state`'s command."""
        return f"state{self._at(address)}"

    def state(self, address: int | None = None) -> dict:
        reply = self._ask(self.state_command(address))
        state = json_object(reply)
        if state is None:
            raise CouldNotTest(f"the rig's state is not one JSON object: {shown(reply)}")
        return self._unit(state)

    def _number(self, key: str, read: Callable[[str], int | None]) -> int:
        value = self.state().get(key)
        # a JSON number or its text, read as the rig writes it (bool is no number)
        number = None if isinstance(value, bool) else read(str(value))
        if number is None:
            raise CouldNotTest(f"the rig's state gives no readable {key!r}: "
                               f"{shown(str(value))}")
        return number

    def outputs(self, address: int | None = None) -> int:
        return self._number("outputs", hexadecimal)

    def spindle(self, address: int | None = None) -> int:
        return self._number("spindle", decimal)

    def forget_hands(self) -> None:
        """The simulator was restored to a state kept with the hands off (docs/cosim.md,
        `restore`): nothing the suite set since is set any more."""
        self._touched.clear()
        self._switches.clear()

    def hands_off(self) -> None:
        """The rig as found: the inputs the suite set back to their levels then, the
        switches it placed removed (part of a real unit's known state)."""
        inputs = self.found.get("inputs")
        for port in sorted(self._touched):
            level = inputs.get(str(port), "FF") if isinstance(inputs, dict) else "FF"
            value = hexadecimal(str(level))
            value = RELEASED if value is None or value > 0xFF else value
            if self._touched[port] != value:
                self._do(f"in {port} {value:02X}{self._at(None)}")
        for axis in sorted(self._switches):
            self._do(f"switch {axis} none{self._at(None)}")
        self._touched.clear()
        self._switches.clear()
