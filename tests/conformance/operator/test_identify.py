"""--profile auto over a pty: every emulated profile is recognised from its answers to
? and Q (the variant from --variant where the answer does not say it, or asked on a
terminal); gve-conformance ports lists and probes a pty-backed port (`?` alone)."""

from __future__ import annotations

import pytest

from conformance.cli import main, ports
from conformance.cli.preflight import resolve
from conformance.operator.console import Console
from conformance.targets.identify import candidates, variant_of
from gve_fixtures.profile import available_profiles, load_profile
from tests.conformance.operator.terminal import EmulatedUnit, Terminal, suite

pytestmark = pytest.mark.pty


@pytest.fixture
def unit(request):
    u = EmulatedUnit(request.param)
    yield u
    u.close()


@pytest.fixture(scope="module")
def every_unit():
    """One emulated unit per profile, started side by side."""
    units = [EmulatedUnit(name) for name in available_profiles()]
    yield units
    for u in units:
        u.close()


def test_auto_recognises_every_emulated_profile(every_unit, capsys):
    for unit in every_unit:
        name = unit.model
        several = len(candidates(load_profile(name).version)) > 1
        spec, profile, how = resolve(f"serial:{unit.path}", "auto",
                                     variant_of(name) if several else None,
                                     Console(interactive=False))
        assert profile == name and spec == f"serial:{unit.path}?baud=115200"
        assert ("--variant" in how) == several
        assert f"-> profile {name}" in capsys.readouterr().out


@pytest.mark.parametrize("unit", ["GVE114-200"], indirect=True)
def test_a_variant_the_answer_does_not_say_is_asked_or_refused(unit):
    with pytest.raises(ValueError, match=r"give --variant \(50, 125, 200, 500\)"):
        resolve(f"serial:{unit.path}", "auto", None, Console(interactive=False))
    term = Terminal(suite("--target", f"serial:{unit.path}", "--profile", "auto", "--yes",
                          "--cases", "1.profile.version", "--no-reports"))
    term.expect("Which GVE114 is this unit?")
    term.answer("250")                                   # not one of them: asked again
    term.expect("please answer one of: 50, 125, 200, 500")
    term.answer("200")
    term.expect("-> profile GVE114-200 (auto:")
    term.expect("PASSED")
    assert term.finish() == 0


class _Listed:
    """What pyserial's list_ports gives for a port."""
    device, description, hwid = "/dev/ttyUSB7", "FT232R USB UART", "USB VID:PID=0403:6001"

    def __lt__(self, other: object) -> bool:
        return False


def test_ports_lists_the_system_ports(monkeypatch, capsys):
    monkeypatch.setattr(ports.list_ports, "comports", lambda include_links: [_Listed()])
    assert main(["ports"]) == 0
    assert capsys.readouterr().out == ("/dev/ttyUSB7  FT232R USB UART  "
                                       "[USB VID:PID=0403:6001]\n"
                                       "1 port listed; none probed (--probe asks each "
                                       "who it is)\n")


@pytest.mark.parametrize("unit", ["GVE54"], indirect=True)
def test_ports_lists_and_probes_a_pty_backed_port(unit, capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(ports.list_ports, "comports", lambda include_links: [])
    link = tmp_path / "ttyUSB-bench"
    link.symlink_to(unit.path)                        # as udev names an adapter
    (tmp_path / "ttyUSB-nothing").write_text("")      # no device: nothing written to it
    # the symlink named: asked, though a pty is behind it; found by the glob: not asked
    assert main(["ports", "--glob", str(tmp_path / "tty*"), "--probe", str(link)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith('-> GVE54: ? "Ip54v3 21.12.2007" at 115200 baud, address 0')
    assert out[1].endswith("-> skipped: not a serial device")
    assert main(["ports", "--glob", str(tmp_path / "tty*"), "--probe"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert "-> skipped: a pseudo-terminal" in out[0]
    assert (tmp_path / "ttyUSB-nothing").read_text() == ""
