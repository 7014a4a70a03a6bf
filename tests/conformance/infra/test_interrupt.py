"""Ctrl-C: the run stops, real units get H then D, and the reports of what ran are written."""

from __future__ import annotations

import json

from conformance.case import Case, TargetInfo
from conformance.reports import write_reports
from conformance.runner import run
from conformance.targets import Target, parse_target
from gve_fixtures.profile import load_profile


def _ok(ctx) -> None:
    ctx.expect(ctx.link.send("?") is not None, "answered")


def _interrupt(ctx) -> None:
    raise KeyboardInterrupt


def test_ctrl_c_keeps_what_ran(tmp_path):
    cases = [Case("1.test.before", _ok, "r", "M", "test"),
             Case("1.test.ctrl-c", _interrupt, "r", "M", "test"),
             Case("1.test.after", _ok, "r", "M", "test")]
    result = run([parse_target("emu:GVE84-100")], cases, run_id="ctrl-c")
    assert result.interrupted
    assert [r.id for r in result.results] == ["1.test.before"]
    folder = write_reports(result, tmp_path)
    assert json.loads((folder / "results.json").read_text())["interrupted"] is True


class FakePort:
    def __init__(self) -> None:
        self.written: list[bytes] = []
        self.timeout = 0.0

    def write(self, data: bytes) -> int:
        self.written.append(data)
        return len(data)

    def read_until(self, terminator: bytes) -> bytes:
        return b"0\r"

    def close(self) -> None:
        pass


def test_emergency_stop_sends_halt_then_delete():
    info = TargetInfo("serial", "serial:/dev/fake", False, False, False, 2000)
    target = Target(info, load_profile("GVE84-100"), 0, 115200, "/dev/fake")
    port = FakePort()
    target._port = port
    target.emergency_stop()
    assert port.written == [b"!0H\r", b"!0D\r"]
