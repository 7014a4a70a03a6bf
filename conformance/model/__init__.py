"""The suite's own abstract model of a unit (written from the spec, never from the
emulator): what the machines predict answers from."""
