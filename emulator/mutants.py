"""Deliberate bugs the emulator can plant, one at a time, to prove the suite's power.

A unit created with ``mutant=NAME`` (``gve://?model=...&mutant=NAME``,
``--mutant NAME``, ``--target emu:GVE84-100?mutant=NAME``) deviates from the spec in
exactly the way described here and nowhere else. The project's tests assert that the
conformance suite FAILs every mutant, naming the case that caught it, and PASSes the
clean emulator on every profile; the emulator's own tests show each mutant answering a
transcript of its rule differently from the clean emulator.

Each entry names the spec sections it touches, what it gets wrong, and the rule area it
breaks (the spec section whose rules a case must check to catch it). Most mutants are
planted in the unit (`device.mutant.active(NAME)` where the behaviour lives); those whose
behaviour lives in the motion model are deviations of the stepper core
(:data:`CORE_DEVIATIONS`), planted alike in both cores.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from emulator.motion.interface import Deviation


class MutantSpec(NamedTuple):
    section: str          # the spec sections it touches
    description: str      # what it gets wrong
    area: str             # the rule area (spec section) a case must check to catch it


#: name -> (spec sections, what the mutant gets wrong, rule area)
MUTANTS: dict[str, MutantSpec] = {name: MutantSpec(*spec) for name, spec in {
    # framing, checksums, index, packets
    "checksum-no-comma": ("6", "the checksum is summed without the comma that precedes it", "6"),
    "checksum-unchecked": ("6", "in checksum mode a frame with a wrong checksum is executed",
                           "6"),
    "checksum-lower-case": ("4, 6", "response checksums are written in lower-case hex", "6"),
    "wrong-address-answers": ("2, 3", "frames for another address are answered too", "3"),
    "lower-case-command": ("3", "lower-case command letters are accepted as upper case", "3"),
    "watchdog-never": ("3", "an unfinished frame is never dropped: no error 2", "3"),
    "inta-bit-missing": ("4", "responses lack bit 3 while INTA = 1", "4"),
    "range-error-code": ("5", "a parameter out of range is answered 4 instead of 5", "5"),
    "go-without-inta": ("5, 10.4", "G with INTA = 0 answers 0 instead of 6", "10.4"),
    "line-while-busy": ("10.1", "L is accepted while vectors are queued or running", "10.1"),
    "queue-one-short": ("10.1", "the CONT buffer refuses one vector before it is full", "10.1"),
    "refused-status-write-stored": ("4, 5, 10.3", "SW n,x with x beyond FF answers 5 but "
                                    "stores the low byte of x", "4"),
    "refused-vector-queued": ("10.1", "a C answered 1 (no room) still enters the queue",
                              "10.1"),
    "packet-partial-commit": ("7", "a failing packet still commits its valid members", "7"),
    "packet-count-ignored": ("7", "*E commits although the member count differs", "7"),
    "failed-packet-keeps-b": ("7", "a packet that fails still sets the B of its B members",
                              "7"),
    "index-skips-refused": ("8", "frames answered with an error do not advance the index",
                            "8"),
    "index-counts-queries": ("8", "@ and > advance the index", "8"),
    "repeat-reexecutes": ("8", "> executes the last command again", "8"),
    "halt-answers-early": ("10.4", "H answers at once instead of when the motion has stopped",
                           "10.4"),
    "go-loses-step": ("10.4", "G resumes one step past where the vector stopped", "10.4"),
    "delete-while-moving": ("5, 10.4", "D is accepted while the motion is running", "10.4"),
    "keep-forgets-st6": ("10.5", "K does not save ST6, so R does not bring INTA back", "10.5"),
    "restore-drops-partial": ("10.5", "R loses the remainder of the interrupted vector",
                              "10.5"),
    "status-word-masked": ("10.3", "SW stores only the bits with an input behind them", "10.3"),
    "interrupt-ignored": ("10.3", "an enabled active input does not stop the motion", "10.3"),
    "eeprom-write-lost": ("10.6", "EW answers 0 but does not change the byte", "10.6"),
    "eeprom-7-bit-address": ("10.6", "ER and EW decode 7 address bits: 80..FF are 00..7F "
                             "again", "10.6"),
    "narrow-counters": ("10", "the position counters are 24 bits wide: P and PF wrap "
                        "beyond ±8388607", "10"),
    "position-ignores-microstep": ("10.7", "GVE54 positions are reported in commanded steps",
                                   "10.7"),
    # the eleven interaction errors of the emulator issue
    "inputs-forgotten-after-delete": (
        "10.3, 10.4, 10.5", "D, K and R clear the cause bits and INTA although an enabled "
        "input is still active (the level is not looked at again)", "10.3"),
    "restore-keeps-save": ("10.5", "R does not empty the save: a second R restores it again",
                           "10.5"),
    "zero-c-keeps-junction": ("10.2", "a zero-length C between two C passes the junction rate "
                              "on: the next C starts at speed instead of from rest", "10.2"),
    "sw6-inert": ("10.3", "writing ST6 stores the bits but acts on nothing: setting INTA does "
                  "not stop, clearing it does not resume", "10.3"),
    "mpg-not-moving": ("5, 9", "the GVE114's MPG holding RUN = 1 does not count as moving "
                       "(D, K, R, EW, EFW, EUW are accepted)", "5"),
    "dwell-between-continuous": ("10.2", "a C whose braking takes less than a step cannot be "
                                 "joined once planned: it stops at the junction, and the next "
                                 "C waits out T", "10.2"),
    "restart-resets-inputs": ("10.3", "J and power-on set the input ports back to FF", "10.3"),
    "flags-ignore-keep-capacity": ("10, 10.5", "F's queue-full bit counts the whole CONT "
                                   "buffer after K instead of the one vector", "10"),
    "halt-short-of-target": ("10.4", "H during the final deceleration lays a ramp of its own "
                             "and stops a step short, RUN staying 1", "10.4"),
    "params-ignored-on-bare-commands": ("3", "a command that takes no parameters ignores "
                                        "given ones (@1 answers the index)", "3"),
    "long-decimal-syntax-error": ("3", "a field of more than 12 digits is a syntax error (4) "
                                  "instead of being range-checked", "3"),
    # the motion, parameter by parameter
    "velocity-ignored": ("10.2", "V has no effect on the motion: the reset V is used", "10.2"),
    "path-speed-ignored": ("10.2", "VK behaves as VN", "10.2"),
    "axis-limit-ignored": ("10.2", "VL caps no axis", "10.2"),
    "override-late": ("10", "XM reaches only vectors accepted after it, not the running and "
                      "queued ones", "10"),
    "xa-ignored": ("10", "XA changes nothing", "10"),
    "xu-xd-swapped": ("10", "XU slows by 15/16 and XD speeds up by 17/16", "10"),
    "accel-ignored": ("10.2", "A has no effect on the motion: the reset A is used", "10.2"),
    "dwell-ignored": ("10.2", "no T dwell before a vector that starts from rest", "10.2"),
    "junction-stops": ("10.2", "B ignored: every C brakes to rest at its end", "10.2"),
    # settings that share nothing
    "spindle-sets-feed-rate": ("12, 10", "the GVE114's !7V n also sets the feed rate V of "
                               "address 0", "12"),
    "axis-limit-x-for-all": ("10, 10.2", "VL caps every axis at its X value", "10.2"),
    "override-rewrites-velocity": ("10", "XM n also sets the modal V to V·n/100: XM100 no "
                                   "longer returns to the V last set", "10"),
    "junction-brake-ignored": ("10.2", "B caps no junction: a C runs into the next C at the "
                               "highest rate the next allows", "10.2"),
    "short-vector-ignored": ("10.2", "the $ rule does not cap short vectors to B", "10.2"),
    "halt-without-ramp": ("10.4", "H stops dead instead of braking on the ramp", "10.4"),
    "go-at-speed": ("10.4", "G resumes at the cruise rate instead of from rest", "10.4"),
    "microstep-modes-swapped": ("10.7", "GVE54: M2 and M8 are swapped (M2 moves 2 sixteenths "
                                "a step, M8 moves 8)", "10.7"),
    "microstep-rates-unscaled": ("10.7", "GVE54: V and B are not scaled by the micro-step "
                                 "factor", "10.7"),
}.items()}

#: mutants whose behaviour lives in the stepper core
CORE_DEVIATIONS: dict[str, Deviation] = {
    "zero-c-keeps-junction": Deviation.ZERO_LENGTH_JUNCTION,
    "dwell-between-continuous": Deviation.CONTINUOUS_DWELL,
    "halt-short-of-target": Deviation.HALT_SHORT,
    "junction-stops": Deviation.JUNCTION_STOPS,
    "junction-brake-ignored": Deviation.JUNCTION_UNBRAKED,
    "halt-without-ramp": Deviation.HALT_DEAD,
    "go-at-speed": Deviation.GO_AT_SPEED,
}


class UnknownMutant(ValueError):
    pass


@dataclass(frozen=True)
class Mutant:
    """The mutant a unit carries (or none). ``active(name)`` is the only question the
    emulator asks; on a unit with a mutant it raises for a name not in :data:`MUTANTS`
    so that a typo cannot silently plant nothing (the tests run every mutant)."""

    name: str | None = None

    def __post_init__(self) -> None:
        if self.name is not None and self.name not in MUTANTS:
            known = ", ".join(sorted(MUTANTS))
            raise UnknownMutant(f"unknown mutant {self.name!r} (known: {known})")

    def active(self, name: str) -> bool:
        if self.name is None:          # the clean unit asks on every frame: answer fast
            return False
        if name not in MUTANTS:
            raise UnknownMutant(f"the emulator asks for an unknown mutant {name!r}")
        return self.name == name

    @property
    def deviations(self) -> Deviation:
        """The stepper core's deviations this mutant plants."""
        return CORE_DEVIATIONS.get(self.name or "", Deviation.NONE)


NONE = Mutant()
