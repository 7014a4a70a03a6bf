"""Differential fuzzing (`gve-conformance diff`, docs/diff.md): the same sequences sent to
the target and to the reference emulator, every disagreement shrunk to a transcript."""
