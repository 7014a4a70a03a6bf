"""Importing this registers every machine's case."""

from conformance.machines import checksum, index, keep, packet  # noqa: F401
