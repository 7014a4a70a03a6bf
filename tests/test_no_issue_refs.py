"""Comments, docstrings and data say why a thing is so, never which tracker entry it came
from: a number in a tracker means nothing to a reader of the code and goes stale when the
entry is closed. Every source, data and documentation file of the tree is read."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("conformance", "emulator", "fixtures", "gve_host", "bench", "tests", "examples",
           "docs")
TOP = ("README.md", "pyproject.toml", "setup.py", "tox.ini")
SUFFIXES = {".py", ".toml", ".c", ".h", ".md", ".gvt", ".txt", ".cfg", ".ini"}
#: the word, an optional "#", a number; in any case, also broken across a line
NAMES_AN_ISSUE = re.compile(r"\bissues?\s*#?\s*\d+", re.IGNORECASE)


def _files() -> list[Path]:
    found = [ROOT / name for name in TOP if (ROOT / name).is_file()]
    for folder in FOLDERS:
        found += [p for p in sorted((ROOT / folder).rglob("*"))
                  if p.is_file() and p.suffix in SUFFIXES and "__pycache__" not in p.parts
                  and not any(part.endswith(".egg-info") for part in p.parts)]
    return found


def _offences(text: str) -> list[tuple[int, str]]:
    return [(text.count("\n", 0, m.start()) + 1, m.group(0).replace("\n", " "))
            for m in NAMES_AN_ISSUE.finditer(text)]


def test_the_pattern_finds_what_it_must_and_nothing_else() -> None:
    word = "issue"  # spelt apart so that this file does not name one itself
    said = (f"a\n({word} 11 item 3)\nsource='{word.title()} 8; spec 2'\n#: {word}s 12, 13\n"
            f"see {word}\n#4\n")
    assert [line for line, _ in _offences(said)] == [2, 3, 4, 5]
    assert _offences("issue a command; the issuer; 11 issues; tissue 3") == []


def test_no_file_of_the_tree_names_an_issue() -> None:
    files = _files()
    assert len(files) > 100, "the tree was not found"
    found = [f"{p.relative_to(ROOT)}:{line}: {what}"
             for p in files for line, what in _offences(p.read_text(errors="replace"))]
    assert found == [], "say why, not which issue:\n" + "\n".join(found)
