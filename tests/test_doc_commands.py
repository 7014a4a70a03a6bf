"""Every command the README and docs/ show in a shell block parses as written: the
suite's subcommands, the emulator's, the reference host's and the benchmarks' (each
parser is stopped as soon as it has read the words, so nothing runs), and the pytest
plugin's options. A renamed option or subcommand fails here before a reader trips on it.

docs/ci.md's recipes run whole in tests/conformance/fleet/test_ci_recipe.py; their
lines with shell variables are left to it."""

from __future__ import annotations

import argparse
import importlib
import re
import shlex
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
    from conformance import plugin

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
