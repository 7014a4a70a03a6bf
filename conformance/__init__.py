"""The GVE protocol conformance suite."""
