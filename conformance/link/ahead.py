"""Raw frames told a co-simulator ahead of their sending, in one exchange (its `batch`,
docs/cosim.md), each judged first on a copy of the run's guard (Guard.ahead) under every
answer the frames told before it could get.

A frame told is on the target's line at once: the simulator runs it before the suite
has read a single answer. So a frame is told only when the guard's judgement of it
cannot depend on those answers: on the copy, every frame let through is booked as
though it got any answer (Guard.book_any), and after a position read (a read that
contradicts the bookkeeping moves it anywhere, or shows the unit restarted, which ends
the case) only frames that set nothing moving are told, as the guard tells its own
(Guard.told_ahead). The first frame the copy refuses ends the frames told; it goes
out, judged with the answers before it, when its turn comes. Each told frame is still
judged and booked by the run's guard as it is sent.
"""

from __future__ import annotations

from conformance.link.body import Body
from conformance.link.link import Link
from conformance.link.liveness import TargetNotResponding
from conformance.link.safety import after_a_read
from conformance.link.signals import Interrupted
from conformance.link.stops import SafetyStop
from conformance.protocol.framer import HostFramer


class Ahead:
    """The frames to tell a link's port ahead, admitted one after the other."""

    def __init__(self, link: Link) -> None:
        self.link = link
        self.open = link.takes_ahead
        self.guard = link.guard.ahead() if self.open else link.guard
        self.frames: list[tuple[bytes, float, int | None]] = []
        self._read = False                # a position read admitted

    def admit(self, data: bytes, timeout: float) -> bool:
        """Whether the raw frame ``data`` (whole frames only), whose answer is awaited
        ``timeout`` seconds, is told after those admitted so far; the first refused
        closes the list."""
        if not self.open:
            return False
        frames = HostFramer().frames(data)
        if not frames or b"".join(f.wire for f in frames) != data:
            self.open = False
            return False
        may, read = after_a_read([Body.parse(body).name for f in frames
                                  for body in f.bodies(None)], self._read)
        if not may:
            self.open = False                 # the read's answer decides what may follow
            return False
        try:
            self.guard.check_frames(frames, None)
        except (SafetyStop, Interrupted, TargetNotResponding):
            self.open = False
            return False
        for f in frames:
            for body in f.bodies(None):
                self.guard.book_any(body, f.address)
        self._read = read
        self.frames.append((data, timeout, None))
        return True

    def due(self, ns: int) -> None:
        """The last frame admitted is answered within ``ns`` of its first byte, if the
        unit is the one expected: a simulator that ends a batch at a frame not answered
        in time (`batch-stops`) then stops there when it is not."""
        data, timeout, _ = self.frames[-1]
        self.frames[-1] = (data, timeout, ns)

    def launch(self) -> bool:
        """Tell the port the frames admitted, its reply left to be read (:meth:`landed`)
        while the caller works and the target runs them; whether they were told (never
        fewer than two)."""
        return len(self.frames) >= 2 and self.link.tell_port(self.frames, read=False)

    def landed(self) -> int:
        """How many of the frames told the target ran (the port's reply, read now)."""
        return self.link.port.landed()
