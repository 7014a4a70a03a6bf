"""The emulated units the relay plays to a host: the reference emulator, opened through its
public pyserial URL (``gve://...``); its ``.line`` is the test rig (inputs, power) and the
line's clock, which the relay keeps on the wall clock (relay.py). Nothing here looks
inside the emulator."""

from __future__ import annotations

import serial

from gve_fixtures.profile import Profile, load_profile


def load_units(specs: list[str]) -> list[tuple[Profile, int]]:
    """``MODEL@ADDRESS`` (or ``MODEL``: its profile's default address) -> (profile, address).
    Raises ValueError/LookupError naming the bad one."""
    units = []
    for spec in specs:
        model, _, address = spec.partition("@")
        profile = load_profile(model)
        if address and not (address.isdigit() and int(address) <= 7):
            raise ValueError(f"{spec!r}: the address is one digit 0..7")
        units.append((profile, int(address) if address else profile.address))
    seen = [a for _, a in units]
    if len(set(seen)) != len(seen):
        raise ValueError("two units on one address")
    return units


def open_line(units: list[tuple[Profile, int]], baud: int,
              readings: tuple[str, ...] = ()) -> serial.SerialBase:
    """A line with these units at ``baud``, its clock at 0, each unit taking ``readings``
    (none: the project's decisions)."""
    import emulator  # noqa: F401  (registers the gve:// scheme with pyserial)

    query = "&".join(f"unit={p.name}@{a}" for p, a in units)
    taken = f"&reading={','.join(readings)}" if readings else ""
    return serial.serial_for_url(f"gve://?{query}&baud={baud}{taken}", timeout=0)


def check_readings(names: list[str]) -> tuple[str, ...]:
    """The readings given to the played units, each one the emulator knows; raises
    ValueError naming the unknown ones."""
    from emulator.readings import parse_readings

    return parse_readings(",".join(names))
