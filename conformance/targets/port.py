"""``serial:PATH?baud=&address=`` and ``tcp:HOST:PORT``: a real unit or a clone's
simulator in real time, one shared port put into a known state before each case."""

from __future__ import annotations

from urllib.parse import parse_qs, urlsplit

from conformance.case import TargetInfo
from conformance.targets.base import Target
from gve_fixtures.profile import available_profiles, load_profile


def parse(kind: str, rest: str, *, spec: str, profile: str | None, allow_destructive: bool,
          max_travel: int, mutant: str | None) -> Target:
    if kind == "serial":
        parts = urlsplit("x://h" + (rest if rest.startswith("/") else "/" + rest))
        q = parse_qs(parts.query)
        url = parts.path
    else:
        host, _, q_text = rest.partition("?")
        q = parse_qs(q_text)
        url = f"socket://{host}"
    if profile is None:
        raise ValueError(f"{spec}: say which profile the unit should behave as "
                         f"(--profile, one of {', '.join(available_profiles())})")
    p = load_profile(profile)
    baud = int(q.get("baud", [p.default_baud])[-1])
    address = int(q.get("address", [p.address])[-1])
    info = TargetInfo(kind, spec, False, False, allow_destructive, max_travel)
    return Target(info, p, address, baud, url)
