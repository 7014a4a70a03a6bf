"""Importing this registers every machine's case."""

from conformance.machines import (  # noqa: F401
    checksum,
    errors,
    interrupts,
    keep,
    packet,
    queue,
    readback,
    recovery,
)
