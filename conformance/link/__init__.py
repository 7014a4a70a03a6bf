"""The suite's own host side of the serial link: framing, faults, safety, the Link."""
