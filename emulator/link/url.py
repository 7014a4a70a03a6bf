"""`gve://` URLs: which units a line carries, and how (docs/architecture.md, Ways in).

``gve://?model=GVE84-100&address=0`` or ``gve://?unit=GVE54@1&unit=GVE84-100@0``, with
``baud``, ``watchdog_ms``, ``eeprom``, ``mutant``, ``reading`` (``A,B``: readings of
emulator/readings.py), ``stepper``, ``log``, and
``realtime=1`` (the line runs on the wall clock instead of virtual time).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from urllib.parse import parse_qs, urlsplit

from emulator.link.words import decimal
from emulator.protocol.unit import Unit
from emulator.readings import parse_readings
from gve_fixtures.profile import load_profile

DEFAULT_MODEL = "GVE84-100"
#: the parameters a gve:// URL takes
PARAMETERS = ("model", "address", "unit", "baud", "watchdog_ms", "eeprom", "mutant",
              "reading", "stepper", "log", "realtime")


@dataclass
class LineSpec:
    units: list[tuple[str, int | None]] = field(default_factory=list)
    baud: int | None = None
    watchdog_ms: int | None = None
    eeprom: str | None = None
    mutant: str | None = None
    readings: tuple[str, ...] = ()
    stepper: str | None = None
    log: str | None = None
    realtime: bool = False

    def build_units(self) -> list[Unit]:
        """The units of the line; two units that would answer one address are refused."""
        units: list[Unit] = []
        taken: dict[int, str] = {}
        for model, address in self.units or [(DEFAULT_MODEL, None)]:
            unit = Unit(load_profile(model), address, eeprom_path=self.eeprom,
                        mutant=self.mutant, watchdog_ms=self.watchdog_ms, stepper=self.stepper,
                        readings=self.readings)
            for a in sorted(unit.addresses):
                if a in taken:
                    raise ValueError(f"two units answer address {a}: {taken[a]} and "
                                     f"{unit.profile.name}@{unit.address}")
                taken[a] = f"{unit.profile.name}@{unit.address}"
            units.append(unit)
        return units

    def line_baud(self, units: list[Unit]) -> int:
        return self.baud or units[0].profile.default_baud


def positive(name: str, text: str) -> int:
    """A whole number above 0 (a baud rate, a watchdog time)."""
    try:
        value = decimal(text, name)
    except ValueError:
        value = 0
    if value <= 0:
        raise ValueError(f"{name} must be a whole number above 0, not {text[:40]!r}")
    return value


def parse_address(text: str) -> int:
    """A unit's address: one digit 0..7."""
    if len(text) != 1 or text not in "01234567":
        raise ValueError(f"an address is 0..7, not {text!r}")
    return int(text)


def parse_unit(text: str) -> tuple[str, int | None]:
    """``MODEL@ADDRESS`` (or just ``MODEL``)."""
    model, at, address = text.partition("@")
    if not model:
        raise ValueError(f"a unit is MODEL@ADDRESS, not {text!r}")
    return model, (parse_address(address) if at else None)


def parse_url(url: str) -> LineSpec:
    parts = urlsplit(url)
    if parts.scheme != "gve":
        raise ValueError(f"not a gve:// URL: {url!r}")
    q = parse_qs(parts.query)
    unknown = set(q) - set(PARAMETERS)
    if unknown:
        raise ValueError(f"unknown gve:// parameter(s): {', '.join(sorted(unknown))}")

    def one(key: str) -> str | None:
        return q[key][-1] if key in q else None

    spec = LineSpec(units=[parse_unit(u) for u in q.get("unit", [])])
    if not spec.units:
        model = one("model") or parts.netloc or DEFAULT_MODEL
        address = one("address")
        spec.units = [(model, parse_address(address) if address is not None else None)]
    for key in ("baud", "watchdog_ms"):
        value = one(key)
        if value is not None:
            setattr(spec, key, positive(key, value))
    for key in ("eeprom", "mutant", "stepper", "log"):
        setattr(spec, key, one(key))
    spec.readings = parse_readings(",".join(q.get("reading", [])))
    spec.realtime = one("realtime") in ("1", "true", "yes")
    return spec
