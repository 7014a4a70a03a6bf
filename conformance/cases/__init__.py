"""The case catalogue: importing this package registers every case."""

from conformance.cases import (  # noqa: F401
    checksum,
    counters,
    eeprom,
    errors,
    families,
    frame,
    golden,
    independence,
    index,
    interactions,
    keep,
    measured,
    motion,
    packet,
    params,
    ports,
    reference,
    refusals,
    status,
    units,
)
from conformance.machines import register as _machines  # noqa: F401  (machine cases)
