"""Importing this registers every machine's case."""

from conformance.machines import checksum, errors, index, keep, packet, queue  # noqa: F401
