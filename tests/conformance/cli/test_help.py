"""What a newcomer learns from `--help` and `--version` of every program the project
installs: every subcommand listed with a whole sentence, each subcommand's help with the
target forms it takes and an example; the version with the C core's state and the
Python; colour off in a pipe and with NO_COLOR, on with `--color always`."""

from __future__ import annotations

import os
import platform
import re
import subprocess
import sys
import tomllib
from importlib.metadata import version
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.cli.commands import SUBCOMMANDS
from tests.conformance.operator.terminal import Terminal

ROOT = Path(__file__).resolve().parents[3]
SCRIPTS = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))["project"]["scripts"]
#: the subcommands that take a unit target (--target), and the forms it may take
TARGETED = ("run", "diff", "replay")
FORMS = ("emu:", "serial:", "tcp:", "exec:")
ESC = "\x1b["


def _help(argv: list[str], capsys) -> str:
    with pytest.raises(SystemExit) as done:
        main(argv)
    assert done.value.code == 0
    return capsys.readouterr().out


def _section(text: str, title: str) -> list[str]:
    """The lines of the help section that starts with ``title``, up to a blank line."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(title))
    out = []
    for line in lines[start + 1:]:
        if not line.strip():
            break
        out.append(line)
    return out


def test_the_top_help_lists_every_subcommand_with_a_whole_sentence(capsys):
    text = _help(["--help"], capsys)
    listed: dict[str, str] = {}
    name = ""
    for line in _section(text, "subcommands"):
        m = re.match(r"  (\S+)\s+(.*)", line)
        if m and not line.startswith("    "):
            name = m.group(1)
            listed[name] = m.group(2)
        else:
            listed[name] += " " + line.strip()
    assert set(listed) == set(SUBCOMMANDS)
    for name, sentence in listed.items():
        assert sentence[0].isupper() and sentence.endswith("."), (name, sentence)
        assert len(sentence.split()) >= 8, (name, sentence)    # a sentence, not a label
    assert "--version" in text and "examples:" in text


@pytest.mark.parametrize("sub", sorted(SUBCOMMANDS))
def test_each_subcommand_help_has_an_example(sub, capsys):
    text = _help([sub, "--help"], capsys)
    prog = "gve-conformance" if sub == "run" else f"gve-conformance {sub}"   # run: the default
    assert text.startswith(f"usage: {prog} ")
    examples = _section(text, "examples:")
    assert examples and all(e.strip().startswith(prog) for e in examples), examples
    assert "--version" in text


@pytest.mark.parametrize("sub", TARGETED)
def test_a_targeted_subcommand_shows_every_target_form(sub, capsys):
    text = _help([sub, "--help"], capsys)
    forms = _section(text, "targets (--target):")
    for form in FORMS:
        assert any(line.strip().startswith(form) for line in forms), (form, forms)
    examples = " ".join(_section(text, "examples:"))
    assert "exec:" in examples and ("serial:" in examples or "tcp:" in examples)


def test_host_help_shows_where_the_host_connects(capsys):
    ports = [line.split()[0] for line in _section(_help(["host", "--help"], capsys),
                                                  "ports (--port):")]
    assert "pty" in ports and "tcp:HOST:PORT" in ports and any(p.startswith("/dev/") for p in ports)


def _version_lines(text: str, prog: str, core: bool) -> None:
    lines = text.splitlines()
    assert lines[0] == f"{prog} {version('gve-conformance')}"
    assert any(platform.python_version() in line and line.startswith("Python")
               for line in lines)
    if core:
        assert any(line.startswith("C stepper core: ") for line in lines), lines


@pytest.mark.parametrize("sub", [None, *sorted(SUBCOMMANDS)])
def test_version_on_the_suite_and_every_subcommand(sub, capsys):
    text = _help(["--version"] if sub is None else [sub, "--version"], capsys)
    _version_lines(text, "gve-conformance" if sub in (None, "run") else f"gve-conformance {sub}",
                   core=True)


def _run(argv: list[str], env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(argv, capture_output=True, text=True, timeout=120,
                          env={**os.environ, **(env or {})})


@pytest.mark.parametrize("script", sorted(SCRIPTS))
def test_every_console_script_explains_itself(script):
    path = Path(sys.executable).parent / script
    assert path.exists(), f"{script} is not installed beside {sys.executable}"
    helped = _run([str(path), "--help"])
    assert helped.returncode == 0 and helped.stdout.startswith(f"usage: {script}")
    assert "--version" in helped.stdout
    shown = _run([str(path), "--version"])
    assert shown.returncode == 0, shown.stderr
    _version_lines(shown.stdout, script, core=True)


def test_the_reference_host_explains_itself():
    helped = _run([sys.executable, "-m", "gve_host", "--help"])
    assert helped.returncode == 0 and "Exit status" in helped.stdout
    assert "--job" in helped.stdout and "port" in helped.stdout
    shown = _run([sys.executable, "-m", "gve_host", "--version"])
    assert shown.returncode == 0
    _version_lines(shown.stdout, "gve_host", core=False)


# -- colour -----------------------------------------------------------------------------------
ONE_CASE = [sys.executable, "-m", "conformance", "--target", "emu:GVE84-100", "-v",
            "--cases", "1.profile.version", "--no-reports"]


def test_no_colour_in_a_pipe():
    done = _run(ONE_CASE, {"NO_COLOR": ""})
    assert done.returncode == 0 and "PASS" in done.stdout
    assert ESC not in done.stdout


def test_colour_always_colours_a_pipe_even_with_no_color():
    done = _run([*ONE_CASE, "--color", "always"], {"NO_COLOR": "1"})
    assert done.returncode == 0
    assert re.search(r"\x1b\[[0-9;]*mPASS", done.stdout), done.stdout


@pytest.mark.pty
def test_colour_never_and_no_color_leave_a_terminal_plain(monkeypatch):
    for extra, env in (([], {"NO_COLOR": "1"}), (["--color", "never"], {})):
        for key, value in {"NO_COLOR": "", **env}.items():
            monkeypatch.setenv(key, value)
        term = Terminal([*ONE_CASE, *extra])
        assert term.finish() == 0
        shown = re.sub(r"\x1b\[2K|\r", "", term.seen)      # the bar's line clearing
        assert "PASSED" in shown and not re.search(r"\x1b\[[0-9;]*m", shown), shown


@pytest.mark.pty
def test_a_terminal_is_coloured_by_default(monkeypatch):
    monkeypatch.setenv("NO_COLOR", "")
    monkeypatch.setenv("TERM", "xterm")
    term = Terminal(ONE_CASE)
    assert term.finish() == 0
    assert re.search(r"\x1b\[[0-9;]*mPASSED", term.seen), term.seen
