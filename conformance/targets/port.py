"""``serial:PATH?baud=&address=`` and ``tcp:HOST:PORT``: a real unit or a clone's
simulator in real time, one shared port put into a known state before each case.
``serial:`` also takes any pyserial URL (``serial:rfc2217://host:port``,
``serial:socket://host:port``, ``serial:loop://``), its own options kept."""

from __future__ import annotations

from urllib.parse import parse_qs, urlencode, urlsplit

from conformance.case import TargetInfo
from conformance.targets.base import Target
from gve_fixtures.profile import available_profiles, load_profile

#: the suite's own query parameters on a serial/tcp target
OURS = ("baud", "address")


def locate(kind: str, rest: str) -> tuple[str, dict[str, list[str]]]:
    """The pyserial URL of a serial/tcp target and the suite's own parameters."""
    if kind == "serial" and "://" in rest:
        parts = urlsplit(rest)
        q = parse_qs(parts.query, keep_blank_values=True)
        ours = {k: q.pop(k) for k in OURS if k in q}
        query = urlencode(q, doseq=True)
        return f"{parts.scheme}://{parts.netloc}{parts.path}{'?' * bool(query)}{query}", ours
    if kind == "serial":
        parts = urlsplit("x://h" + (rest if rest.startswith("/") else "/" + rest))
        # a path as given: /dev/ttyUSB0, or COM3 on Windows
        return parts.path if rest.startswith("/") else parts.path[1:], parse_qs(parts.query)
    host, _, q_text = rest.partition("?")
    return f"socket://{host}", parse_qs(q_text)


def parse(kind: str, rest: str, *, spec: str, profile: str | None, allow_destructive: bool,
          max_travel: int, mutant: str | None) -> Target:
    url, q = locate(kind, rest)
    if profile is None:
        raise ValueError(f"{spec}: say which profile the unit should behave as "
                         f"(--profile, one of {', '.join(available_profiles())})")
    p = load_profile(profile)
    baud = int(q.get("baud", [p.default_baud])[-1])
    address = int(q.get("address", [p.address])[-1])
    info = TargetInfo(kind, spec, False, False, allow_destructive, max_travel)
    return Target(info, p, address, baud, url)
