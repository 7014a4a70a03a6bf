"""A small transcript player for the emulator's own tests (the conformance suite has its
own, independent one): plays host records, checks unit records, performs actions."""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator
from pathlib import Path

import pytest
import serial

import emulator  # noqa: F401  (registers gve://)
from gve_fixtures.profile import available_profiles, load_profile
from gve_fixtures.transcript import ACTION, HOST, UNIT, UNIT_MATCH, Transcript, load, unescape

ANSWER_TIMEOUT = 30.0     # virtual seconds: H waits for the stop
#: the emulator's own transcripts: the interactions of the spec revision of 2026-11-25
TRANSCRIPTS = Path(__file__).parent / "transcripts"


def transcript_cases(paths: Iterable[Path]) -> Iterator:
    """pytest params (path, profile) for every profile a transcript names (its
    ``profiles`` header: families or profile names; none: every profile)."""
    for path in paths:
        names = load(path).meta.get("profiles", "").split()
        for profile in available_profiles():
            p = load_profile(profile)
            if names and p.family not in names and p.name not in names:
                continue
            yield pytest.param(Path(path), profile, id=f"{Path(path).stem}-{profile}")


def open_line(profile: str, address: int = 0, **params: str) -> serial.SerialBase:
    query = "&".join([f"model={profile}", f"address={address}",
                      *(f"{k}={v}" for k, v in params.items())])
    return serial.serial_for_url(f"gve://?{query}", timeout=ANSWER_TIMEOUT)


def _answer(port: serial.SerialBase, frame: bytes) -> bytes:
    port.write(frame)
    return port.read_until(b"\r")


def play(port: serial.SerialBase, transcript: Transcript, rig=None) -> list[str]:
    """Replay; returns the mismatches (empty when the unit answered as recorded).

    ``rig`` lets time pass and plays the test rig (default: the gve:// port's line)."""
    line = rig if rig is not None else port.line
    problems: list[str] = []
    for number, rec in enumerate(transcript.records, 1):
        where = f"record {number} ({rec.line()})"
        if rec.direction == HOST:
            port.write(rec.data)
        elif rec.direction == UNIT:
            got = port.read(len(rec.data))
            if got != rec.data:
                problems.append(f"{where}: got {got!r}")
        elif rec.direction == UNIT_MATCH:
            got = port.read_until(b"\r")
            if not rec.pattern().fullmatch(got):
                problems.append(f"{where}: got {got!r}")
        elif rec.direction == ACTION:
            words = rec.action
            verb, args = words[0], words[1:]
            if verb == "wait":
                line.advance(float(args[0]))
            elif verb == "silence":
                line.advance(float(args[0]))
                if port.in_waiting:
                    problems.append(f"{where}: unexpected {port.read(port.in_waiting)!r}")
            elif verb == "poll":
                limit = line.now + float(args[0]) * 1e9
                frame, pattern = unescape(args[1]), re.compile(unescape(args[2]), re.DOTALL)
                while not pattern.fullmatch(_answer(port, frame)):
                    if line.now > limit:
                        problems.append(f"{where}: never matched")
                        break
                    line.advance(0.05)
            elif verb == "fill":
                frame = unescape(args[1])
                for _ in range(int(args[0])):
                    if _answer(port, frame) != b"0\r":
                        break
            elif verb == "input":
                line.set_input(int(args[0]), int(args[1], 16))
            elif verb == "expect":
                got = (f"{line.outputs():02X}" if args[0] == "outputs"
                       else str(line.spindle()))
                if got != args[1]:
                    problems.append(f"{where}: {args[0]} is {got}")
            elif verb == "rate":
                line.set_rate_switch(None if args[0] == "none" else int(args[0]))
            elif verb == "baud":
                port.baudrate = int(args[0])
            elif verb == "power-on":
                line.power_on()
                line.advance(2.5)                   # every profile restarts in about 2 s
            else:
                problems.append(f"{where}: unknown action")
    return problems
