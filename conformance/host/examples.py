"""The spec's worked examples a host's frames can be held to (spec 11): every golden
transcript whose rule has the host role gives the exact bytes of its checksummed frames,
so a host sending the same command in checksum mode must send the same bytes."""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache

from conformance.protocol.wire import HEX_BYTE
from gve_fixtures import golden_transcripts
from gve_fixtures.rules import load_rules
from gve_fixtures.transcript import HOST, load

_CHECKSUMMED = re.compile(rb"^(!.*),%b\r?$" % HEX_BYTE.encode())
_GOLDEN = re.compile(r"\b11 G(\d+)")


@dataclass(frozen=True)
class WorkedFrame:
    rule: str                        # 11.golden.gN
    frame: bytes                     # the example's frame, CR left out
    families: tuple[str, ...]        # profiles or families it applies to (): every one


@cache
def worked_frames() -> dict[bytes, WorkedFrame]:
    """The frame without its checksum -> the worked example that sums it."""
    rules = load_rules()
    out: dict[bytes, WorkedFrame] = {}
    for path in golden_transcripts():
        t = load(path)
        m = _GOLDEN.search(t.meta.get("spec", ""))
        rule = rules.get(f"11.golden.g{m.group(1)}") if m else None
        if rule is None or "host" not in rule.roles:
            continue
        for r in t.records:
            hit = _CHECKSUMMED.match(r.data) if r.direction == HOST else None
            if hit:
                out[hit.group(1)] = WorkedFrame(rule.id, r.data.rstrip(b"\r"), rule.profiles)
    return out
