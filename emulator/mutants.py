"""Deliberate bugs the emulator can plant, one at a time, to prove the suite's power.

A unit created with ``mutant=NAME`` (``gve://?model=...&mutant=NAME``,
``--mutant NAME``, ``--target emu:GVE84-100?mutant=NAME``) deviates from the spec in
exactly the way described here and nowhere else. The project's tests assert that the
conformance suite FAILs every mutant, naming the case that caught it, and PASSes the
clean emulator on every profile.
"""

from __future__ import annotations

from dataclasses import dataclass

#: name -> (spec section, what the mutant gets wrong)
MUTANTS: dict[str, tuple[str, str]] = {
    "checksum-no-comma": ("6", "the checksum is summed without the comma that precedes it"),
    "checksum-unchecked": ("6", "in checksum mode a frame with a wrong checksum is executed"),
    "checksum-lower-case": ("4, 6", "response checksums are written in lower-case hex"),
    "wrong-address-answers": ("2, 3", "frames for another address are answered too"),
    "lower-case-command": ("3", "lower-case command letters are accepted as upper case"),
    "watchdog-never": ("3", "an unfinished frame is never dropped: no error 2"),
    "inta-bit-missing": ("4", "responses lack bit 3 while INTA = 1"),
    "range-error-code": ("5", "a parameter out of range is answered 4 instead of 5"),
    "go-without-inta": ("5, 10.4", "G with INTA = 0 answers 0 instead of 6"),
    "line-while-busy": ("10.1", "L is accepted while vectors are queued or running"),
    "queue-one-short": ("10.1", "the CONT buffer refuses one vector before it is full"),
    "packet-partial-commit": ("7", "a failing packet still commits its valid members"),
    "packet-count-ignored": ("7", "*E commits although the member count differs"),
    "index-skips-refused": ("8", "frames answered with an error do not advance the index"),
    "index-counts-queries": ("8", "@ and > advance the index"),
    "repeat-reexecutes": ("8", "> executes the last command again"),
    "halt-answers-early": ("10.4", "H answers at once instead of when the motion has stopped"),
    "go-loses-step": ("10.4", "G resumes one step past where the vector stopped"),
    "delete-while-moving": ("5, 10.4", "D is accepted while the motion is running"),
    "keep-forgets-st6": ("10.5", "K does not save ST6, so R does not bring INTA back"),
    "restore-drops-partial": ("10.5", "R loses the remainder of the interrupted vector"),
    "status-word-masked": ("10.3", "SW stores only the bits with an input behind them"),
    "interrupt-ignored": ("10.3", "an enabled active input does not stop the motion"),
    "eeprom-write-lost": ("10.6", "EW answers 0 but does not change the byte"),
    "position-ignores-microstep": ("10.7", "GVE54 positions are reported in commanded steps"),
}


class UnknownMutant(ValueError):
    pass


@dataclass(frozen=True)
class Mutant:
    """The mutant a unit carries (or none). ``active(name)`` is the only question the
    emulator asks; it raises for a name not in :data:`MUTANTS` so that a typo cannot
    silently plant nothing."""

    name: str | None = None

    def __post_init__(self) -> None:
        if self.name is not None and self.name not in MUTANTS:
            known = ", ".join(sorted(MUTANTS))
            raise UnknownMutant(f"unknown mutant {self.name!r} (known: {known})")

    def active(self, name: str) -> bool:
        if name not in MUTANTS:
            raise UnknownMutant(f"the emulator asks for an unknown mutant {name!r}")
        return self.name == name


NONE = Mutant()
