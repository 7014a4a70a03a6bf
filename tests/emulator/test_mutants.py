"""Every mutant of emulator/mutants.py really deviates: on a transcript of the rule it
breaks (tests/emulator/transcripts or a golden one), which the clean emulator passes
(test_revised_spec.py, test_golden.py), the mutant answers differently. And every name
the emulator asks ``active()`` about is a registered mutant. The clean emulator playing a
mutant's probe reaches the mutant's code (``asked``): the mutation sweep leaves a case out
for a mutant only where its clean run did not."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from emulator.mutants import CORE_DEVIATIONS, MUTANTS, Mutant, UnknownMutant, asked
from gve_fixtures import TRANSCRIPTS_DIR
from gve_fixtures.transcript import load
from tests.emulator.replay import TRANSCRIPTS, open_line, play

EMULATOR = Path(__file__).resolve().parents[2] / "emulator"

#: mutant -> (the transcript of the rule it breaks, the profile it is played on)
PROBES: dict[str, tuple[str, str]] = {
    "checksum-no-comma": ("g1-checksum-mode", "GVE84-100"),
    "checksum-unchecked": ("d4-checksum-in-packet", "GVE84-100"),
    "checksum-lower-case": ("g1-checksum-mode", "GVE84-100"),
    "wrong-address-answers": ("p01-framing", "GVE84-100"),
    "lower-case-command": ("p01-framing", "GVE84-100"),
    "watchdog-never": ("p01-framing", "GVE54"),
    "inta-bit-missing": ("e04-sw6-acts", "GVE84-100"),
    "range-error-code": ("d1-fields", "GVE54"),
    "go-without-inta": ("e02-restore-empties-the-save", "GVE84-100"),
    "line-while-busy": ("g6-keep-restore", "GVE84-100"),
    "queue-one-short": ("p03-queue-size", "GVE84-15"),
    "packet-partial-commit": ("p02-packet-all-or-nothing", "GVE114-500"),
    "packet-count-ignored": ("d4-checksum-in-packet", "GVE114-500"),
    "failed-packet-keeps-b": ("p07-failed-packet-b", "GVE84-100"),
    "refused-vector-queued": ("p06-refused-vector", "GVE84-15"),
    "refused-vector-overwrites": ("p06-refused-vector", "GVE84-15"),
    "refused-line-queued": ("p12-refused-line", "GVE84-100"),
    "refused-status-write-stored": ("p08-refused-status-write", "GVE54"),
    "input-bits-swapped": ("p09-input-bits", "GVE84-100"),
    "velocity-refused-stored": ("p10-refused-velocity", "GVE84-100"),
    "accel-refused-stored": ("p13-refused-accel", "GVE114-500"),
    "velocity-syntax-refused-stored": ("p14-refused-velocity-syntax", "GVE84-100"),
    "brake-refused-stored": ("p15-refused-brake", "GVE54"),
    "dwell-refused-stored": ("p16-refused-dwell", "GVE114-500"),
    "microstep-refused-stored": ("p17-refused-microstep", "GVE54"),
    "spindle-refused-stored": ("p18-refused-spindle", "GVE114-500"),
    "failed-packet-applies-v": ("p11-failed-packet-v", "GVE114-500"),
    "narrow-counters": ("p04-counter-range-ends", "GVE114-500"),
    "eeprom-7-bit-address": ("p05-eeprom-every-address", "GVE54"),
    "index-skips-refused": ("e10-bare-commands", "GVE84-100"),
    "index-counts-queries": ("e10-bare-commands", "GVE54"),
    "repeat-reexecutes": ("d4-checksum-in-packet", "GVE84-100"),
    "halt-answers-early": ("m10-halt-ramp", "GVE84-100"),
    "go-loses-step": ("g6-keep-restore", "GVE84-100"),
    "go-keeps-intcom": ("e14-go-clears-intcom", "GVE54"),
    "delete-while-moving": ("e05-mpg-is-moving", "GVE114-500"),
    "delete-refused": ("e12-delete-after-halt", "GVE84-100"),
    "delete-ignored": ("e12-delete-after-halt", "GVE54"),
    "keep-forgets-st6": ("g6-keep-restore", "GVE114-500"),
    "restore-drops-partial": ("g6-keep-restore", "GVE84-100"),
    "status-word-masked": ("g4f-status-read", "GVE84-100"),
    "interrupt-ignored": ("e01-inputs-after-d-k-r", "GVE84-100"),
    "eeprom-write-lost": ("d1-fields", "GVE54"),
    "eeprom-forgotten-at-restart": ("e15-eeprom-kept-across-j", "GVE84-100"),
    "position-ignores-microstep": ("g5b-gve54-microstep", "GVE54"),
    "inputs-forgotten-after-delete": ("e01-inputs-after-d-k-r", "GVE84-100"),
    "restore-keeps-save": ("e02-restore-empties-the-save", "GVE114-500"),
    "zero-c-keeps-junction": ("e03-zero-length-c", "GVE84-100"),
    "sw6-inert": ("e04-sw6-acts", "GVE114-500"),
    "mpg-not-moving": ("e05-mpg-is-moving", "GVE114-500"),
    "dwell-between-continuous": ("e06-no-dwell-between-c", "GVE84-100"),
    "restart-resets-inputs": ("e07-j-keeps-inputs", "GVE54"),
    "flags-ignore-keep-capacity": ("e08-f-after-k", "GVE84-100"),
    "halt-short-of-target": ("e09-halt-in-final-ramp", "GVE114-500"),
    "params-ignored-on-bare-commands": ("e10-bare-commands", "GVE84-100"),
    "long-decimal-syntax-error": ("e11-long-decimals", "GVE84-100"),
    "velocity-ignored": ("m01-velocity", "GVE84-100"),
    "path-speed-ignored": ("m02-path-speed", "GVE114-500"),
    "axis-limit-ignored": ("m03-axis-limit", "GVE84-100"),
    "override-late": ("m04-override", "GVE84-100"),
    "xa-ignored": ("m05-exchange", "GVE84-100"),
    "xu-xd-swapped": ("m05-exchange", "GVE114-500"),
    "accel-ignored": ("m06-acceleration", "GVE84-100"),
    "dwell-ignored": ("m07-dwell", "GVE84-100"),
    "junction-stops": ("m08-junction", "GVE84-100"),
    "junction-brake-ignored": ("m12-junction-brake", "GVE114-500"),
    "spindle-sets-feed-rate": ("m13-spindle-apart-from-feed", "GVE114-500"),
    "axis-limit-x-for-all": ("m14-axis-limit-own-axis", "GVE84-100"),
    "override-rewrites-velocity": ("m15-override-leaves-v", "GVE114-500"),
    "short-vector-ignored": ("m09-short-vector", "GVE84-100"),
    "halt-without-ramp": ("m10-halt-ramp", "GVE84-100"),
    "go-at-speed": ("m10-halt-ramp", "GVE114-500"),
    "microstep-rates-unscaled": ("m11-microstep-rates", "GVE54"),
    "microstep-modes-swapped": ("m16-each-microstep-mode", "GVE54"),
    "mpg-enable-high-values-ignored": ("p19-mpg-enabling-values", "GVE114-500"),
    "spindle-low-end-off": ("p20-spindle-range-ends", "GVE114-500"),
    "slow-rates-floored": ("m17-slow-rates", "GVE84-100"),
    "microstep-continuous-unscaled": ("m18-microstep-continuous", "GVE54"),
    "a-axis-alone-ignored": ("e12-a-axis-alone", "GVE114-500"),
    "cause-lowest-only": ("e13-cause-several", "GVE84-100"),
    "cause-includes-disabled": ("e13-cause-several", "GVE54"),
    "reference-answers-early": ("d6-reference-answers-after-run", "GVE84-100"),
    "baud-range-ignored": ("p21-rate-read-at-power-on", "GVE114-500"),
    "baud-read-at-restart": ("p21-rate-read-at-power-on", "GVE114-200"),
    "baud-range-read-at-restart": ("p21-rate-read-at-power-on", "GVE114-50"),
    "baud-jumpers-ignored": ("p27-gve54-jumpers-select", "GVE54"),
    "output-ignored-while-busy": ("p22-output-while-busy", "GVE84-100"),
    "spindle-refuses-eeprom": ("p23-spindle-eeprom", "GVE114-500"),
    "short-read-ignores-microstep": ("p24-short-read-in-sixteenths", "GVE54"),
    "current-resets-mode": ("p25-current-apart-from-mode", "GVE54"),
    "input-stop-drops-queue": ("p26-input-stop-holds-queue", "GVE84-100"),
    "power-on-keeps-checksums": ("p28-power-on-checksums-off", "GVE84-100"),
}


def _transcript(name: str) -> Path:
    mine = TRANSCRIPTS / f"{name}.gvt"
    return mine if mine.exists() else TRANSCRIPTS_DIR / f"{name}.gvt"


def test_every_mutant_has_a_probe() -> None:
    assert sorted(PROBES) == sorted(MUTANTS)


@pytest.mark.parametrize("mutant", sorted(MUTANTS))
def test_the_mutant_answers_its_probe_differently(mutant: str, tmp_path: Path) -> None:
    name, profile = PROBES[mutant]
    transcript = load(_transcript(name))
    address = int(transcript.meta.get("address", "0"))
    port = open_line(profile, address, eeprom=str(tmp_path / "eeprom.bin"), mutant=mutant)
    problems = play(port, transcript)
    assert problems, f"{mutant} ({MUTANTS[mutant].description}) passes {name} on {profile}"
    print(f"{mutant}: {problems[0]}")


@pytest.mark.parametrize("mutant", sorted(MUTANTS))
def test_the_clean_unit_playing_the_probe_reaches_the_mutant(mutant: str, tmp_path: Path) -> None:
    name, profile = PROBES[mutant]
    transcript = load(_transcript(name))
    address = int(transcript.meta.get("address", "0"))
    with asked() as reached:
        port = open_line(profile, address, eeprom=str(tmp_path / "eeprom.bin"))
        assert play(port, transcript) == []
    assert mutant in reached


def test_nothing_is_recorded_outside_the_block_and_blocks_nest() -> None:
    Mutant().active("sw6-inert")
    with asked() as outer:
        with asked() as inner:
            Mutant().active("sw6-inert")
        Mutant().active("narrow-counters")
        Mutant("sw6-inert").active("narrow-counters")      # a mutant unit: not the clean one
    assert inner == {"sw6-inert"}
    assert outer == {"sw6-inert", "narrow-counters"}


def test_names_the_emulator_asks_about_are_registered() -> None:
    asked = {m for path in EMULATOR.rglob("*.py")
             for m in re.findall(r"""(?<!readings\.)\bact(?:ive)?\(\s*["']([a-z0-9-]+)["']""",
                                 path.read_text())}
    assert asked, "no active() calls found"
    assert asked <= set(MUTANTS), asked - set(MUTANTS)
    # every mutant is planted somewhere: asked by name, or a deviation of the core
    assert set(MUTANTS) <= asked | set(CORE_DEVIATIONS), set(MUTANTS) - asked


def test_an_unknown_name_is_refused() -> None:
    with pytest.raises(UnknownMutant):
        Mutant("no-such-bug")
    with pytest.raises(UnknownMutant):
        Mutant("sw6-inert").active("no-such-bug")
