"""Every target setting is known or refused: a misspelled key in any scheme's URL is one
line naming it, the nearest valid key and every valid one, exit status 2, before anything
is sent (a unit on a pty, its wire logged, sees no frame; a TCP port, no connection).
Profiles refuse theirs likewise (tests/fixtures/test_profiles.py)."""

from __future__ import annotations

import socket
import subprocess
import sys

import pytest

from conformance.cli import main
from conformance.targets.emu import SETTINGS, url_settings
from conformance.targets.port import OURS, PYSERIAL_OPTIONS
from gve_fixtures.transcript import load
from tests.processes import stop

pytest_plugins = ["pytester"]


def _misspelt(key: str) -> str:
    """The key with its second letter dropped (``adress``, ``bud``, ``mutnt``...)."""
    return key[0] + key[2:]


@pytest.fixture(scope="module")
def logged_unit(tmp_path_factory):
    """The emulator on a pty, writing every byte it gets to its wire log."""
    log = tmp_path_factory.mktemp("unit") / "wire.gvt"
    unit = subprocess.Popen([sys.executable, "-m", "emulator", "--model", "GVE84-100",
                             "--pty", "--log", str(log)], stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    yield unit.stdout.readline().strip(), log
    stop(unit)


@pytest.fixture(scope="module")
def listening():
    """A TCP port nothing may connect to: (HOST:PORT, whether something connected)."""
    server = socket.create_server(("127.0.0.1", 0))
    server.setblocking(False)

    def connected() -> bool:
        try:
            server.accept()[0].close()
            return True
        except BlockingIOError:
            return False
    yield f"127.0.0.1:{server.getsockname()[1]}", connected
    server.close()


#: scheme -> (the target text with a setting KEY=VALUE, the valid keys, a value for each)
SCHEMES = {
    "emu": ("emu:GVE84-100?{}", SETTINGS),
    "gve": ("serial:gve://?model=GVE84-100&{}", tuple(url_settings()) + OURS),
    "serial": ("serial:{path}?{}", OURS),
    "tcp": ("tcp:{where}?{}", OURS),
    **{scheme: (f"serial:{scheme}://{{where}}?{{}}", OURS + options)
       for scheme, options in PYSERIAL_OPTIONS.items()},
}
MISSPELT = [(scheme, key) for scheme, (_, keys) in SCHEMES.items() for key in keys
            if _misspelt(key) not in keys]


@pytest.mark.parametrize(("scheme", "key"), MISSPELT,
                         ids=[f"{s}-{_misspelt(k)}" for s, k in MISSPELT])
def test_a_misspelt_setting_is_refused_before_anything_is_sent(scheme, key, logged_unit,
                                                               listening, capsys):
    path, log = logged_unit
    where, connected = listening
    form, valid = SCHEMES[scheme]
    wrong = _misspelt(key)
    spec = form.format(f"{wrong}=1", path=path, where=where)
    status = main(["--target", spec, "--profile", "GVE84-100", "--yes", "--no-reports",
                   "--cases", "5.errors.ok"])
    err = capsys.readouterr().err
    assert status == 2, err
    assert err.count("\n") == 1, err
    assert f"unknown setting {wrong!r}" in err and f"valid: {', '.join(sorted(set(valid)))}" \
        in err, err
    assert not connected()
    assert not log.exists() or load(log).records == []


def test_exec_takes_no_settings_of_its_own():
    """Everything after ``exec:`` is the command: a ``?`` is the program's to read."""
    from conformance.targets import parse_target
    target = parse_target("exec:./clone-sim --pty?adress=1", profile="GVE84-100")
    assert target.command == ("./clone-sim", "--pty?adress=1")


def test_emu_all_takes_the_settings_to_every_profile(capsys):
    assert main(["--target", "emu:all?mutnt=halt-without-ramp", "--no-reports",
                 "--cases", "5.errors.ok"]) == 2
    assert "unknown setting 'mutnt' (did you mean 'mutant'?)" in capsys.readouterr().err


def test_the_plugin_refuses_a_misspelt_setting(pytester):
    result = pytester.runpytest("--gve-target", "emu:GVE84-100?mutnt=halt-without-ramp")
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    result.stderr.fnmatch_lines(["*unknown setting 'mutnt' (did you mean 'mutant'?)*"])

