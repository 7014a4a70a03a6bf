"""Readings: the other answers a careful reader of the manuals could give where they are
silent — the fairness twin of :mod:`emulator.mutants`.

A mutant breaks what a manual states and must FAIL; a reading takes another side of a
`[D]` point (or of a point the spec allows two ways) and must never FAIL a target graded
by the tags: its differences are NON-STRICT or INFO, each naming its rule. A unit created
with ``readings=(NAME, ...)`` (``gve://?reading=A,B``, ``--reading NAME`` repeatable,
``--target emu:GVE84-100?reading=A,B``) takes every reading named, several at once.
`gve-conformance fairness` runs the catalogue against each reading alone and all at once
and prints the fairness score (readings without a FAIL / readings).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from emulator.motion.interface import Deviation


class ReadingSpec(NamedTuple):
    rules: tuple[str, ...]   # the rules of fixtures/rules.toml whose silence it reads
    description: str         # what the unit does instead


#: name -> (the rules it reads otherwise, what the unit does)
READINGS: dict[str, ReadingSpec] = {name: ReadingSpec(*spec) for name, spec in {
    "plus-sign": (("3.params.decimal",),
                  "a leading + in a decimal field is taken as the sign it is"),
    "long-version": (("1.profile.version",),
                     "? answers the firmware string the manual prints in full, with its "
                     "copyright (`IP84 v3 27.1.2010 (c) Gravos (P.Borovsky)`)"),
    "go-nothing-queued": (("5.code.nothing-to-go", "10.4.go.without-inta"),
                          "G with INTA = 1 and nothing queued answers 6: for Go, nothing "
                          "to start (spec 5, both readings allowed)"),
    "go-clears-then-nothing": (("5.code.nothing-to-go", "10.4.go.empty"),
                               "G with INTA = 1 and nothing queued clears INTA, INTCOM, ST4 "
                               "and ST5 as the manual says, then answers 6: for Go, nothing "
                               "to start (an input still active sets INTA again)"),
    "missing-letter-range": (("5.code.unknown",),
                             "an axis, port or register letter the unit lacks (NA on a "
                             "GVE84, I2) answers 5 instead of 3 (spec 10.4, both allowed)"),
    "lone-bang-answered": (("3.frame.watchdog-lone-bang",),
                           "a lone ! left by the watchdog is answered 2, as any unfinished "
                           "frame"),
    "hex-upper-only": (("3.params.hex-digits",),
                       "hex fields take upper-case digits only: a-f is a syntax error (4)"),
    "hex-two-digits": (("3.params.hex-digits",),
                       "hex fields take one or two digits, as the manuals write them "
                       "(00..FF): three or more (`SW0,001`, `ER100`) are a syntax error "
                       "(4), not a value range-checked"),
    "set-axis-xyz-only": (("10.cmd.set-axis-a",),
                          "GVE114: N<axis> takes the axes its manual names (X, Y, Z): `NA` "
                          "is a syntax error (4)"),
    "mpg-on-when-sent": (("9.reset.mpg-held-at-reset",),
                         "GVE114: the MPG holds the axes only from a `Y&` or `Y+` sent: "
                         "after power-on and J its `&` mode is inert and ST6 = 00, as M114 "
                         "13.5 gives the reset state"),
    "queries-counted": (("8.index.queries-uncounted",),
                        "@ and > advance the index like every other command"),
    "refused-uncounted": (("8.index.refused-counted",),
                          "a frame answered with an error code does not advance the index: "
                          "it tells \"zda ho interpolátor přijal nebo ne\", read as taken"),
    "restore-nothing-kept-refused": (("10.5.restore.pops",),
                                     "R with nothing saved by K (or a second R) is refused "
                                     "with 4 and changes nothing: the manual's R restores "
                                     "what K saved and says nothing of an empty save"),
    "eeprom-write-while-moving": (("5.code.busy-eeprom",),
                                  "EW, EFW and EUW are accepted while the axes move (the "
                                  "manuals forbid only D, K, R, M, N and W while running)"),
    "packet-closed-only-by-end": (("7.packet.breakers",),
                                  "an open packet is closed only by *E: H, @, > and J "
                                  "inside it are members (failing it with 4, unanswered); "
                                  "a second *S still restarts it"),
    "packet-frames-uncounted": (("8.index.packet-frames-counted",),
                                "a packet's *S and *E do not advance the index: only its "
                                "members are commands (\"*E10 -konec (bylo 10 příkazů)\")"),
    "packet-open-through-queries": (("7.packet.breakers",),
                                    "@ and > inside an open packet are answered at once "
                                    "and leave it open: only *E, H and J end it"),
    "packet-committed-on-arrival": (("7.packet.all-or-nothing",),
                                    "each valid packet member takes effect as it arrives "
                                    "(B sets B, C is queued); *E still answers code,k, "
                                    "and a failed packet keeps what arrived before *E"),
    "longer-frames": (("3.frame.max-length", "3.frame.bounded-buffer"),
                      "frames up to 255 bytes (a byte-wide length counter) are taken whole "
                      "and run as any other; only longer ones answer 4"),
    "edge-triggered-inputs": (("10.3.inputs.level-triggered",),
                              "an enabled input interrupts when it becomes active, not "
                              "while it stays so: G, D, K, R or SW that clear the cause "
                              "or INTA with the input still active are not undone"),
    "slow-watchdog": (("3.frame.watchdog-time",),
                      "the watchdog drops an unfinished frame after 1 s without a byte, "
                      "not 100 ms"),
    "index-remembered": (("8.repeat.remembered",),
                         "@ is remembered for > like any received command: > after @ "
                         "answers !0@ and the index it gave (the manual's > repeats the "
                         "last received command and its answer)"),
    "second-keep-refused": (("10.5.keep.one-level-info",),
                            "GVE84/GVE114: a K while an earlier K's save is held (no R "
                            "since) is refused with 4 and changes nothing: their manuals "
                            "allow KEEP without its RESTORE only once (the GVE54's, whose "
                            "manual says the save is lost, is not read so)"),
    "cause-first-only": (("10.3.inputs.cause-accumulates",),
                         "ST4/ST5 keep the cause of the interrupt that stopped the unit: an "
                         "input interrupting while INTA is already set adds no bit (the "
                         "manual's cause is \"the interrupt\", not every one since)"),
    "next-vectors-B": (("10.2.motion.junction-own-b",),
                       "a junction of two C is passed at the B the next C captured, not the "
                       "one of the C that ends there"),
    "restore-nothing-kept-range": (("10.5.restore.pops",),
                                   "R with nothing saved by K (or a second R) is refused "
                                   "with 5 and changes nothing"),
    "keep-c-queue-full": (("10.5.keep.c-refused",),
                          "after K a C is refused with 1, as a vector the one place the "
                          "kept queue holds (for an L) has no room for"),
    "packet-failed-count-valid": (("7.packet.codes",),
                                  "a failed packet answers the first failing member's code "
                                  "before a count mismatch, with the count of its valid "
                                  "members (`*S`, `C`, `V100`, `C`, `*E3` → `4,2`)"),
    "packet-failed-count-zero": (("7.packet.codes", "7.packet.other-member"),
                                 "a failed packet answers `code,0` (no member taken), the "
                                 "first failing member's code before a count mismatch, and "
                                 "a command a packet cannot hold is unknown there (3): "
                                 "`*S`, `V10`, `C-300,0,0,0`, `*E1` → `3,0`"),
    "half-second-watchdog": (("3.frame.watchdog-time",),
                             "the watchdog drops an unfinished frame after 500 ms without "
                             "a byte"),
    "packet-watchdog": (("7.packet.open-until-end",),
                        "an open packet that receives nothing for 500 ms is dropped and "
                        "answered `2,k` (k members received), as a packet that did not "
                        "arrive whole in time"),
    "baud-unlisted-high": (("2.link.rate-range-unlisted",),
                           "GVE114: an EEPROM 0D byte the manual does not list (neither 01 "
                           "nor FF) selects the 01 range (921600..115200), as any byte but "
                           "the default"),
    "mpg-needs-parameters": (("9.reset.mpg-parameters",),
                             "the GVE114's MPG takes effect only when every MPG parameter "
                             "(limits, steps per mm, acceleration, speed: M114 12.4-12.6) "
                             "is in range; with one out of range (an erased FF) RUN stays 0 "
                             "and Y+, Y& are refused with 5"),
    "mpg-needs-every-parameter": (("9.reset.mpg-parameters",),
                                  "as mpg-needs-parameters, the sentence read for every "
                                  "parameter of M114 chapter 12 with a range: the MPG "
                                  "delay (48, 1..2000) and the default spindle speed (4C, "
                                  "1..1000) out of range keep the MPG off and Y+, Y& "
                                  "refused with 5 too"),
    "index-hex": (("8.index.decimal",),
                  "@ writes the index as two upper-case hex digits, as the manuals write "
                  "every other byte (`0,3B` for 59): no manual gives its number format"),
    "absent-command-syntax": (("1.profile.command-prefix",),
                              "a command the unit lacks whose first letters begin one it "
                              "has (`VL1000,1000,1000`, `NX0`, `XM100` on the GVE54) "
                              "answers 4: the letters after them read as parameters it "
                              "does not take (its manual never says where a command's "
                              "name ends)"),
    "vector-fewer-components": (("10.cmd.vector-components",),
                                "a vector takes one component or more, the missing ones "
                                "0 (the manuals' own `!0L1000,100`)"),
    "commands-any-case": (("3.frame.upper-case",),
                          "command letters are taken in either case (`!0v1000` is V)"),
    "eeprom-erased-zero": (("10.6.eeprom.erased",),
                           "the EEPROM as shipped reads 00 where it was never written "
                           "(the GVE114's tables: 00 means unused), its named defaults "
                           "apart"),
    "steps-a-period-late": (("10.2.motion.step-placement",),
                            "steps placed on a continuous trapezoid and counted rounded "
                            "down: a counter shows a step one step period after the suite's "
                            "arithmetic places it (up to one step behind on each axis while "
                            "moving), and H answers one step period after the last step"),
    "counters-a-tick-late": (("10.2.motion.trapezoid", "10.2.motion.step-placement"),
                             "the counters follow the axes on a 1 ms tick of the unit's own "
                             "(the manuals time the motion in whole milliseconds): while "
                             "the axes move P and PF read where they were a tick ago"),
    "zero-vector-dwells": (("10.2.motion.zero-length",),
                           "`L0,0,0` is a normal vector with no motion (\"program považuje za "
                           "normální vektor\"), so the T dwell between vectors that are not "
                           "continuous applies to it: answered 0 once everything before it "
                           "is done, it then holds RUN = 1 (moving: N, D, K, R, M, EW "
                           "refused with 7, L with 1) for T ms; H ends the dwell"),
    "dwell-outlives-halt": (("5.moving.after-halt", "10.2.motion.zero-length"),
                            "the T dwell after a vector counts as running (\"za chodu\") "
                            "and H does not end it: `L0,0,0` holds RUN for its T as under "
                            "zero-vector-dwells, and an H meanwhile sets INTA and leaves "
                            "the dwell to run out (ST6 RUN with INTA; D, K, R, M, N refused "
                            "with 7 and L with 1 until the T ms are over)"),
    "accel-along-path": (("10.2.motion.path-accel",),
                         "under VK, A is taken along the path |d| as V is (\"rychlosti jsou "
                         "určeny podle d\"): the dominant axis accelerates and brakes at "
                         "A·n/|d|"),
    "restore-refused-while-run": (("5.moving.after-halt",),
                                  "R is refused with 7 whenever RUN = 1, also while halted "
                                  "vectors hold it after H (\"Nelze použít za chodu\" read "
                                  "as RUN = 1, as the GVE54 manual words N's)"),
    "motor-mode-refused-while-run": (("5.moving.definition",),
                                     "GVE54: M, like N, is refused with 7 whenever RUN = 1, "
                                     "also while halted vectors hold it after H (\"Nelze "
                                     "použít za chodu\" read as RUN = 1)"),
    "rate-jumpers-reversed": (("2.link.rate-jumper-table",),
                              "GVE54: the jumper positions give the rates in the other "
                              "order (115200 first): the manual names the jumpers "
                              "\"volitelné\" and lists no rates"),
    "reversal-brakes-to-rest": (("10.2.motion.junction-reversal",),
                                "a C whose next C reverses an axis brakes to rest at their "
                                "junction, not to B (\"U pokračujícího vektoru se nesmí "
                                "příliš změnit úhel\": a reversal is no continuation)"),
    "sw6-stop-request": (("10.3.sw6.answer-inta",),
                         "SW6 writing STOP (bit 0, \"žádost o zastavení\") as 1 is a stop "
                         "request the unit accepts: INTA is set and a motion stops on its "
                         "ramp, as writing INTA does"),
    "cont-waits-for-line": (("10.1.queue.c-behind-line",),
                            "a C sent while an L is held (running or halted) answers 1, "
                            "the queue full, until the L has ended: the CONT buffer is for "
                            "CONT vectors and the L runs alone"),
    "mpg-refused-while-moving": (("10.cmd.mpg-while-moving",),
                                 "GVE114: `Y+` and `Y&` answer 7 while the axes move (`Y-` "
                                 "is taken)"),
    "accel-byte-range": (("10.cmd.accel-range",),
                         "A takes 1..255 (thousands of pulses/s², one byte) and answers "
                         "5 above: the manuals state A20 at reset and no range"),
}.items()}

#: readings whose behaviour lives in the stepper core
CORE_READINGS: dict[str, Deviation] = {
    "next-vectors-B": Deviation.NEXT_BRAKE,
    "reversal-brakes-to-rest": Deviation.REVERSAL_STOPS,
}


class UnknownReading(ValueError):
    pass


def parse_readings(text: str | None) -> tuple[str, ...]:
    """``A,B`` (or None) as reading names, each one known."""
    names = tuple(n for n in (text or "").split(",") if n)
    unknown = [n for n in names if n not in READINGS]
    if unknown:
        raise UnknownReading(f"unknown reading(s) {', '.join(map(repr, unknown))} "
                             f"(known: {', '.join(sorted(READINGS))})")
    return names


@dataclass(frozen=True)
class Readings:
    """The readings a unit takes (none: the project's decisions). ``active(name)`` is the
    only question the emulator asks; it raises for a name not in :data:`READINGS` so a
    typo cannot silently read nothing."""

    names: frozenset[str] = frozenset()

    def __post_init__(self) -> None:
        parse_readings(",".join(self.names))

    def active(self, name: str) -> bool:
        if not self.names:
            return False
        if name not in READINGS:
            raise UnknownReading(f"the emulator asks for an unknown reading {name!r}")
        return name in self.names

    @property
    def deviations(self) -> Deviation:
        """The stepper core's deviations these readings take."""
        flags = Deviation.NONE
        for name in self.names:
            flags |= CORE_READINGS.get(name, Deviation.NONE)
        return flags


NONE = Readings()
