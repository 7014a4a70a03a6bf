"""The reference emulator of GVE54, GVE84 and GVE114 serial interpolators."""
