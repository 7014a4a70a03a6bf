"""Every command the README and docs/ show in a shell block parses as written: the
suite's subcommands, the emulator's, the reference host's and the benchmarks' (each
parser is stopped as soon as it has read the words, so nothing runs), and the pytest
plugin's options. A renamed option or subcommand fails here before a reader trips on it.

Those that name the embedded emulator or a simulator (``emu:``, ``exec:``, with the
emulator standing in for a clone's ``./clone-sim``), and the examples of ``--help``, are
run too and must end as the text says; a ``$ gve-conformance`` session a document shows
must print what it shows.

docs/ci.md's recipes run whole in tests/conformance/fleet/test_ci_recipe.py; their
lines with shell variables are left to it."""

from __future__ import annotations

import argparse
import importlib
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: the first words of a command -> the module whose ``main(argv)`` reads the rest
PROGRAMS = {("gve-conformance",): "conformance.cli", ("python", "-m", "conformance"):
            "conformance.cli", ("python", "-m", "emulator"): "emulator.__main__",
            ("gve-emulator",): "emulator.__main__", ("python", "-m", "gve_host"):
            "gve_host.__main__"}
BENCH = re.compile(r"python -m (bench\.\w+)")
#: lines that install or run every benchmark: nothing of ours to parse
NOT_OURS = (("python", "-m", "venv"), ("python", "-m", "pip"), ("python", "-m", "bench"))


class Parsed(Exception):
    """The parser read every word: stop before anything runs."""


def _blocks(text: str) -> list[str]:
    return re.findall(r"```(?:sh|console|bash)\n(.*?)```", text, flags=re.S)


def _commands() -> list[tuple[str, str]]:
    """(where, command line) of every program line in a shell block, continuations joined,
    comments dropped, `<placeholders>` made one word."""
    found = []
    for doc in DOCUMENTS:
        for block in _blocks(doc.read_text()):
            for line in block.replace("\\\n", " ").splitlines():
                line = re.sub(r"<[^>]+>", "X", line.strip().removeprefix("$ "))
                # `[--option N]`: an optional part, tried as given (N a number)
                line = re.sub(r"\[([^\]]*)\]", r"\1", line).replace(" N ", " 1 ")
                words = line.split()
                if "$" in line or not words or words[0] not in ("gve-conformance", "python",
                                                                "gve-emulator", "python3"):
                    continue
                found.append((doc.name, line))
    return found


COMMANDS = _commands()


def test_the_documents_show_commands_of_every_program():
    programs = {words[2] if words[0] == "python" else words[0]
                for words in (line.split() for _, line in COMMANDS)}
    assert {"gve-conformance", "emulator", "pytest", "bench"} <= programs


def _stop_at_parse(monkeypatch: pytest.MonkeyPatch) -> None:
    original = argparse.ArgumentParser.parse_args

    def parse(self, args=None, namespace=None):
        original(self, args, namespace)
        raise Parsed

    monkeypatch.setattr(argparse.ArgumentParser, "parse_args", parse)


@pytest.mark.parametrize(("where", "line"), COMMANDS, ids=[f"{w}:{c[:60]}" for w, c in COMMANDS])
def test_a_documented_command_parses(where, line, monkeypatch, capsys):
    words = shlex.split(line, comments=True)
    words = ["python" if w == "python3" else w for w in words]
    if words[:3] == ["python", "-m", "pytest"]:
        _plugin_options_exist(words[3:])
        return
    if tuple(words[:3]) in NOT_OURS and not BENCH.match(" ".join(words[:3])):
        return
    bench = BENCH.match(" ".join(words[:3]))
    module = bench.group(1) if bench else next(
        (m for head, m in PROGRAMS.items() if tuple(words[:len(head)]) == head), None)
    assert module is not None, f"{where}: no program known for {line!r}"
    argv = words[len(next(h for h in PROGRAMS if tuple(words[:len(h)]) == h)):] \
        if not bench else words[3:]
    _stop_at_parse(monkeypatch)
    main = importlib.import_module(module).main
    try:
        status = main(argv)
    except Parsed:
        return
    except SystemExit as stop:
        status = stop.code
    err = capsys.readouterr().err
    # --help, --list, --version and the like end without parsing further: status 0
    assert status == 0, f"{where}: {line!r} did not parse: {err}"


def _plugin_options_exist(words: list[str]) -> None:
    """The plugin's options named in a `python -m pytest` line are the plugin's."""
    from conformance.pytest_plugin import plugin

    class Options:
        def __init__(self) -> None:
            self.names: set[str] = set()

        def getgroup(self, *args, **kwargs):
            return self

        def addoption(self, *names, **kwargs):
            self.names.update(names)

        def addini(self, *args, **kwargs):
            pass

    options = Options()
    plugin.pytest_addoption(options)
    named = {w.split("=")[0] for w in words if w.startswith("--gve")}
    assert named <= options.names, named - options.names


# -- the commands that name the emulator or a simulator, run ---------------------------------

#: the clone's simulator the documents name, and the emulator standing in for it
CLONE_SIM = "./clone-sim"
STAND_IN = "python -m emulator --model GVE84-100"
#: commands that read what another command wrote (a placeholder path): run elsewhere
#: (tests/conformance/cli/test_replay.py replays diff's transcripts)
WRITTEN_BY_ANOTHER = ("reports/X/",)
#: a documented search runs here for a number of sequences drawn from a known seed instead
#: of its --seconds (the same end every time): (virtual time, real time)
SEARCH = {True: ["--examples", "300", "--seed", "1"], False: ["--examples", "20", "--seed", "1"]}
#: the cases a run through a program runs here when it names none (the whole catalogue
#: through a program takes minutes: tests/conformance/test_serial_target.py and the
#: co-simulation's tests run it)
PROGRAM_CASES = "5.errors.*"
#: what the documents show that does not yet end as they say, and why (strict: a fix
#: makes the test fail until the mark goes)
NOT_YET: dict[str, str] = {}


def _running() -> list[tuple[str, str]]:
    """The documented commands of the suite and its pytest plugin that name an ``emu:``
    or ``exec:`` target."""
    return [(where, line) for where, line in COMMANDS
            if ("emu:" in line or "exec:" in line)
            and line.split()[0] in ("gve-conformance", "python")
            and (line.startswith("gve-conformance") or " pytest " in f" {line} ")
            and not any(p in line for p in WRITTEN_BY_ANOTHER)]


def _helped() -> list[tuple[str, str]]:
    """The examples `gve-conformance --help` closes with that name a target."""
    from conformance.cli.run import EXAMPLES
    return [("--help", line) for line in EXAMPLES if "emu:" in line or "exec:" in line]




def _argv(line: str) -> list[str]:
    """The command as a test runs it: the stand-in for the clone's simulator, this
    interpreter, a search's time capped, a real-time run narrowed to a few cases."""
    words = shlex.split(line.replace(CLONE_SIM, STAND_IN), comments=True)
    words = [w.replace("python -m", f"{sys.executable} -m") for w in words]
    if words[0] == "gve-conformance":
        words[:1] = [sys.executable, "-m", "conformance"]
    elif words[:1] in (["python"], ["python3"]):
        words[0] = sys.executable
    if "--seconds" in words:
        at = words.index("--seconds")
        virtual = any("--cosim" in w or w.startswith("emu:") for w in words)
        words[at:at + 2] = SEARCH[virtual]
    program = any(w.startswith("exec:") for w in words)
    pytest_run = "pytest" in words
    a_run = pytest_run or words[3:4] == [] or words[3].startswith("-")   # not a subcommand
    option = "--gve-cases" if pytest_run else "--cases"
    if program and a_run and option not in words:
        words += [option, PROGRAM_CASES]
    return words


def _once_each(commands: list[tuple[str, str]]) -> list[tuple[str, str]]:
    """The commands, one of each that runs alike (the same command in several places:
    where they all are, the first one's text)."""
    places: dict[tuple[str, ...], tuple[list[str], str]] = {}
    for where, line in commands:
        places.setdefault(tuple(_argv(line)), ([], line))[0].append(where)
    return [("+".join(dict.fromkeys(wheres)), line) for wheres, line in places.values()]


RUNNING = _once_each(_running() + _helped())


def _expected_status(line: str) -> int:
    """What the text says the command ends with: a planted mutant FAILs (1), anything
    else passes (0)."""
    return 1 if "mutant=" in line else 0


@pytest.mark.parametrize(("where", "line"), [
    pytest.param(w, c, marks=pytest.mark.xfail(reason=NOT_YET[c], strict=True))
    if c in NOT_YET else (w, c) for w, c in RUNNING], ids=[f"{w}:{c[:60]}" for w, c in RUNNING])
def test_a_documented_command_ends_as_the_text_says(where, line, tmp_path):
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    done = subprocess.run(_argv(line), cwd=tmp_path, stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=600,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    out = done.stdout + done.stderr
    assert done.returncode == _expected_status(line), f"{where}: {line}\n{out[-3000:]}"
    assert "Traceback" not in out


def _sessions() -> list[tuple[str, str, list[str]]]:
    """(document, command, the output it shows) of every ``$ gve-conformance`` in a
    text block."""
    found = []
    for doc in DOCUMENTS:
        for block in re.findall(r"```text\n(.*?)```", doc.read_text(), flags=re.S):
            lines = block.replace("\\\n", " ").splitlines()
            if lines and lines[0].startswith("$ gve-conformance"):
                found.append((doc.name, lines[0][2:], lines[1:]))
    return found


SESSIONS = _sessions()


def test_the_documents_show_a_session():
    assert SESSIONS


@pytest.mark.parametrize(("where", "line", "shown"), SESSIONS,
                         ids=[f"{w}:{c[:60]}" for w, c, _ in SESSIONS])
def test_a_documented_session_prints_what_the_text_shows(where, line, shown, tmp_path):
    done = subprocess.run(_argv(line), cwd=tmp_path, stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=600,
                          env={**os.environ, "PYTHONPATH": str(ROOT), "NO_COLOR": "1"})
    assert done.stdout.splitlines() == shown, done.stdout + done.stderr
