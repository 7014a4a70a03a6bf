"""``tox`` passes on a fresh clone: lint, and its smoke subset of the tests on every
supported Python against the sdist installed there. Slow (minutes, and pip reaches the
package index); a file of its own, so that CI's slow step (``--dist loadfile``) runs it
beside the distributions' tests."""

from __future__ import annotations

import re
import sys

import pytest

from tests.packaging.test_distributions import PYTHONS, ROOT, _interpreter, run, tracked

pytestmark = pytest.mark.slow


def test_tox_passes_on_a_fresh_clone_on_every_supported_python(tmp_path):
    """tox's envlist (lint and a smoke subset per Python) passes; one invocation, so the
    sdist is built once."""
    tracked()
    for version in PYTHONS:
        _interpreter(version)
    clone = tmp_path / "clone"
    run(["git", "clone", "--quiet", str(ROOT), str(clone)], tmp_path)
    envs = ["lint", *(f"py{v.replace('.', '')}" for v in PYTHONS)]
    done = run([sys.executable, "-m", "tox", "-e", ",".join(envs), "--", "-q"], clone,
               timeout=3000)
    for env in envs:
        assert re.search(rf"^  {env}: OK", done.stdout, re.MULTILINE), done.stdout[-3000:]
