"""``serial:PATH?baud=&address=`` and ``tcp:HOST:PORT``: a real unit or a clone's
simulator in real time, one port shared by every link of the run. ``serial:`` also takes
any pyserial URL (``serial:rfc2217://host:port``, ``serial:socket://host:port``,
``serial:loop://``), its own options kept."""

from __future__ import annotations

from urllib.parse import parse_qs, urlencode, urlsplit

import serial

from conformance.link.exclusive import open_serial
from conformance.targets.emu import register_url_scheme, url_settings
from conformance.targets.info import TargetInfo
from conformance.targets.target import Target, TargetError, known_settings
from conformance.targets.targetport import TargetPort
from conformance.verdicts.verdict import CouldNotTest
from gve_fixtures.profile import Profile, available_profiles, load_profile

#: the suite's own query parameters on a serial/tcp target
OURS = ("baud", "address")
#: the options pyserial's URL handlers take, by scheme (pyserial refuses the others, yet
#: with a message that names none of them); a scheme not here goes to pyserial as given
PYSERIAL_OPTIONS = {"socket": ("logging",), "loop": ("logging",),
                    "rfc2217": ("logging", "ign_set_control", "poll_modem", "timeout")}
#: the emulator's pyserial URL scheme (README, "The emulator")
EMULATOR_SCHEME = "gve"


def locate(kind: str, rest: str) -> tuple[str, dict[str, list[str]]]:
    """The pyserial URL of a serial/tcp target and the suite's own parameters."""
    if kind == "serial" and "://" in rest:
        parts = urlsplit(rest)
        q = parse_qs(parts.query, keep_blank_values=True)
        ours = {k: q.pop(k) for k in OURS if k in q}
        if parts.scheme == EMULATOR_SCHEME:
            known_settings(f"{kind}:{rest}", q, url_settings())
            _emulator_url(q, ours)
        elif parts.scheme in PYSERIAL_OPTIONS:
            known_settings(f"{kind}:{rest}", q, OURS + PYSERIAL_OPTIONS[parts.scheme])
        query = urlencode(q, doseq=True)
        return f"{parts.scheme}://{parts.netloc}{parts.path}{'?' * bool(query)}{query}", ours
    if kind == "serial":
        parts = urlsplit("x://h" + (rest if rest.startswith("/") else "/" + rest))
        q = parse_qs(parts.query, keep_blank_values=True)
        known_settings(f"{kind}:{rest}", q, OURS)
        # a path as given: /dev/ttyUSB0, or COM3 on Windows
        return parts.path if rest.startswith("/") else parts.path[1:], q
    where, _, q_text = rest.partition("?")
    q = parse_qs(q_text, keep_blank_values=True)
    known_settings(f"{kind}:{rest}", q, OURS)
    return f"socket://{_host_port(where)}", q


def _emulator_url(q: dict[str, list[str]], ours: dict[str, list[str]]) -> None:
    """``gve://``, the emulator's pyserial URL, judged as any unit on a port: in real time
    (the emulator registers the scheme when it is imported, as for ``emu:``), its unit at
    the address the suite talks to."""
    if "address" in ours:
        q["address"] = ours["address"]
    if q.setdefault("realtime", ["1"]) != ["1"]:
        raise TargetError("serial:gve:// is the emulator judged as a unit on a port, in real "
                          "time: leave out realtime (for virtual time: --target emu:MODEL, or "
                          "exec:'python -m emulator --model MODEL --cosim')")
    register_url_scheme()


def _host_port(where: str) -> str:
    """``HOST:PORT`` checked before anything is opened: pyserial would take an empty host
    for this machine and report a missing or bad port only when connecting."""
    try:
        parts = urlsplit("//" + where)
        host, port = parts.hostname, parts.port
    except ValueError:
        host, port = None, None
    if not host or port is None or not 1 <= port <= 65535 or parts.path or parts.username:
        raise TargetError(f"tcp:{where}: give the simulator's address as tcp:HOST:PORT "
                          "(a port 1..65535)")
    return where


def open_port(url: str, baud: int, spec: str) -> serial.SerialBase:
    """The pyserial port at ``url`` (a path, held alone while the run has it open, or a
    URL such as ``socket://host:port``); TargetError with one line when it cannot be
    opened (another program holds it, among others)."""
    try:
        return open_serial(url, baudrate=baud, timeout=0.5)
    except (serial.SerialException, OSError, ValueError) as err:
        raise TargetError(f"{spec}: cannot open {url}: {_reason(err)}") from None


class PortTarget(Target):
    def __post_init__(self) -> None:
        super().__post_init__()
        self._port: TargetPort | None = None

    def preflight(self) -> None:
        self._open()

    def _open(self) -> serial.SerialBase:
        if self._port is None:
            self._port = TargetPort(open_port(self.url, self.baud, self.info.spec))
        return self._port

    def connect(self, address: int | None):
        if address is not None and address != self.address:
            raise CouldNotTest(f"needs a unit at address {address}")
        return self._open(), self.baud, False, None

    def close(self) -> None:
        if self._port is not None:
            self._port.close()
            self._port = None


def _reason(err: Exception) -> str:
    text = str(err).splitlines()[0] if str(err) else type(err).__name__
    return text.split("] ", 1)[-1] if text.startswith("[Errno") else text


def _number(q: dict, key: str, default: int, spec: str, lo: int, hi: int) -> int:
    text = q.get(key, [str(default)])[-1]
    try:
        value = int(text)
    except ValueError:
        value = None
    if value is None or not lo <= value <= hi:
        raise TargetError(f"{spec}: bad {key} {text!r}: a whole number {lo}..{hi}")
    return value


def real_profile(spec: str, profile: str | None, mutant: str | None,
                 mutant_hint: str = "") -> Profile:
    """The profile a unit in real time is judged as, once the options make sense for it
    (TargetError with one line otherwise)."""
    if profile is None:
        raise TargetError(f"{spec}: say which profile the unit should behave as "
                          f"(--profile, one of {', '.join(available_profiles())})")
    if mutant is not None:
        raise TargetError(f"--mutant plants a bug in the embedded emulator; {spec} is not one"
                          + (f" ({mutant_hint})" if mutant_hint else ""))
    return load_profile(profile)


def parse(kind: str, rest: str, *, spec: str, profile: str | None, allow_destructive: bool,
          max_travel: int, mutant: str | None, strict: bool = False) -> Target:
    url, q = locate(kind, rest)
    p = real_profile(spec, profile, mutant)
    baud = _number(q, "baud", p.default_baud, spec, 1, 10_000_000)
    address = _number(q, "address", p.address, spec, 0, 7)
    info = TargetInfo(kind, spec, False, False, allow_destructive, max_travel, strict)
    return PortTarget(info, p, address, baud, url)
