"""What a session gives with a link: work handed to ``open_link`` is done once, while a
co-simulator runs the known state's frames told ahead where it takes them in a batch,
else once the link is open."""

from __future__ import annotations

import shlex
import sys

import pytest

from conformance.targets import parse_target


def _opened_with_work(spec: str, extensions: frozenset[str] | None = None
                      ) -> list[bool]:
    """For each run of the work given to ``open_link``: whether frames of the known
    state told to a co-simulator were unread then."""
    target = parse_target(spec, profile="GVE84-100")
    target.preflight()
    try:
        session = target.begin()
        line = target.connect(None)[0].line
        if extensions is not None:
            line.extensions = extensions
        seen: list[bool] = []
        link = session.open_link(meanwhile=lambda: seen.append(
            getattr(line, "_told", None) is not None))
        assert link.send("SR6").ok, "the link in the known state, usable"
        session.finish()
        return seen
    finally:
        target.close()


COSIM = "exec:" + shlex.join([sys.executable, "-m", "emulator", "--cosim"])


@pytest.mark.parametrize(("spec", "extensions", "while_told"), [
    ("emu:GVE84-100", None, False),
    (COSIM, None, True),                                  # while the simulator runs them
    (COSIM, frozenset(), False),                          # no batch: once the link is open
])
def test_work_given_with_a_link_is_done_once(spec, extensions, while_told):
    assert _opened_with_work(spec, extensions) == [while_told]
