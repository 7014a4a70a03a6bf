"""The CI recipe of docs/ci.md as its tests run it: the blocks are read from the page
(each follows a ``<!-- recipe: NAME -->`` line), never written again here."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

DOC = Path(__file__).resolve().parents[3] / "docs" / "ci.md"


def blocks() -> dict[str, str]:
    """The page's recipe blocks by name."""
    found = re.findall(r"<!-- recipe: (\S+) -->\n```\w*\n(.*?)```", DOC.read_text(), re.S)
    return dict(found)


def commands(block: str) -> list[str]:
    """A block's command lines, continuation lines joined, comments dropped."""
    text = re.sub(r"\\\n\s*", "", block)
    return [line.split("  #")[0].strip() for line in text.splitlines()
            if line.strip() and not line.strip().startswith("#")]


def run_recipe(steps: list[str], cwd: Path, env: dict[str, str],
               timeout: float = 300) -> subprocess.CompletedProcess:
    """The named blocks, in order, as one bash script in ``cwd``."""
    recipe = blocks()
    script = "\n".join(recipe[name] for name in steps)
    return subprocess.run(["bash", "-c", script], cwd=cwd, env={**os.environ, **env},
                          capture_output=True, text=True, timeout=timeout, check=False)
