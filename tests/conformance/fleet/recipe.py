"""The recipes of the docs as their tests run them (docs/ci.md's CI job, docs/acceptance.md's
install): the blocks are read from the page (each follows a ``<!-- recipe: NAME -->``
line), never written again here."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

DOCS = Path(__file__).resolve().parents[3] / "docs"
DOC = DOCS / "ci.md"


def blocks(doc: Path = DOC) -> dict[str, str]:
    """The page's recipe blocks by name."""
    found = re.findall(r"<!-- recipe: (\S+) -->\n```\w*\n(.*?)```", doc.read_text(), re.S)
    return dict(found)


def commands(block: str) -> list[str]:
    """A block's command lines, continuation lines joined, comments dropped."""
    text = re.sub(r"\\\n\s*", "", block)
    return [line.split("  #")[0].strip() for line in text.splitlines()
            if line.strip() and not line.strip().startswith("#")]


def run_recipe(steps: list[str], cwd: Path, env: dict[str, str],
               timeout: float = 300, doc: Path = DOC) -> subprocess.CompletedProcess:
    """The named blocks of ``doc``, in order, as one bash script in ``cwd``."""
    recipe = blocks(doc)
    script = "\n".join(recipe[name] for name in steps)
    return subprocess.run(["bash", "-c", script], cwd=cwd, env={**os.environ, **env},
                          capture_output=True, text=True, timeout=timeout, check=False)
