"""The case catalogue: importing this package registers every case."""

from conformance.cases import (  # noqa: F401
    checksum,
    errors,
    frame,
    golden,
    index,
    keep,
    measured,
    motion,
    packet,
    status,
    units,
)
from conformance.machines import register as _machines  # noqa: F401  (machine cases)
