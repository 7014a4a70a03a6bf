"""The steps of a differential sequence: what the host does to both sides alike.

A step is a frame (one command, as the grammar drew it: its body, how its checksum is
written, its address, whether an answer is due), a wait, an input set by the test rig,
what the test rig sees of the unit (its `state`: outputs, spindle, where the axes are),
another act of the rig's hands (its `power-on`, a reference switch placed or taken off:
the rig's own words as the body), or a queue filled to the brim (one frame sent until
the unit answers anything but 0).
The bytes of a frame are made when it is sent, from the checksum mode the host believes
in then, so a sequence means the same on any unit.
"""

from __future__ import annotations

from dataclasses import dataclass

from conformance.link.framing import byte_sum, frame

FRAME, WAIT, INPUT, FILL, STATE, RIG = "frame", "wait", "input", "fill", "state", "rig"


@dataclass(frozen=True)
class Step:
    kind: str
    body: str = ""
    checksum: str = "auto"             # auto | bad | none (how the checksum is written)
    address: int | None = None         # None: the unit's own
    answer: bool = True                # an answer is due (False: `*S`, another address)
    lines: int = 1                     # lines of the answer (`>`: 2)
    stall: tuple[int, float] | None = None   # (byte, seconds): a pause inside the frame
    seconds: float = 0.0               # WAIT
    port: int = 0                      # INPUT
    value: int = 0                     # INPUT
    times: int = 0                     # FILL: at most this many frames
    raw: bytes = b""                   # a replayed frame: these bytes exactly

    def frame_bytes(self, address: int, summed: bool) -> bytes:
        """The frame on the wire, the host believing the checksum mode is ``summed``."""
        if self.raw:
            return self.raw
        to = address if self.address is None else self.address
        if self.checksum == "none" or not summed:
            return frame(self.body, to, False)
        if self.checksum == "bad":
            right = byte_sum(f"!{to}{self.body},".encode("latin-1"))
            return frame(self.body, to, "%02X" % (right ^ 0x01))
        return frame(self.body, to, True)

    def __str__(self) -> str:
        if self.kind == WAIT:
            return f"wait {self.seconds:g}"
        if self.kind == INPUT:
            return f"input {self.port} {self.value:02X}"
        if self.kind == FILL:
            return f"fill {self.times} {self.body}"
        if self.kind == STATE:
            return "state"
        if self.kind == RIG:
            return self.body
        extra = [w for w, on in (("bad checksum", self.checksum == "bad"),
                                 ("no checksum", self.checksum == "none"),
                                 (f"to {self.address}", self.address is not None),
                                 ("stalled", self.stall is not None)) if on]
        return self.body + (f" ({', '.join(extra)})" if extra else "")


def frames_in(steps: list[Step]) -> int:
    """How many frames a sequence sends at most."""
    return sum(s.times if s.kind == FILL else 1 for s in steps if s.kind in (FRAME, FILL))
