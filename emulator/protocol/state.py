"""The device's protocol state that a reset (power-on, `J`) restores (spec 9).

The session's state (index, `>` history, checksum mode, packet) is in session.py; the
input levels are physical and survive a reset (they belong to the device, not here).
"""

from __future__ import annotations

from dataclasses import dataclass

from emulator.motion.interface import KeepSave
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import St6

# plain ints of the St6 bits for the per-frame path (IntFlag's operators are slow)
INTA, INTCOM, RUN, STOP, FREE, QUEUE_FULL = (
    b.value for b in (St6.INTA, St6.INTCOM, St6.RUN, St6.STOP, St6.FREE, St6.QUEUE_FULL))


@dataclass
class Modal:
    """Modal parameters captured by each vector when it is accepted (spec 10.1)."""

    V: int
    A: int
    B: int
    dollar: int
    T: int
    VK: bool
    VL: list[int]


@dataclass
class Saved:
    """The KEEP save (spec 10.5): the motion's queue and ST4, ST5, ST6."""

    motion: KeepSave
    st4: int
    st5: int
    st6: int


@dataclass
class DeviceState:
    modal: Modal
    xm: int
    status: list[int]                 # ST0..ST5 as written; ST6's stored bits (INTA, INTCOM, ...)
    outputs: int
    saved: Saved | None = None        # the KEEP save (one level)
    kept_single: bool = False         # after K on GVE84/GVE114: the queue takes one L only
    microstep: str = "F"
    current: str = "D"
    mpg: str = ""
    spindle: int = 0
    reference_until: int = -1         # a W reference run in progress until then
    #: the readings zero-vector-dwells and dwell-outlives-halt: the T dwell of an `L0,0,0`
    #: holds RUN until then
    dwell_until: int = -1

    @property
    def inta(self) -> bool:
        return bool(self.status[6] & INTA)


def reset_state(profile: Profile) -> DeviceState:
    r = profile.reset
    axes = len(profile.axes)
    vl = list(r.VL) if r.VL else [profile.max_rate] * axes
    state = DeviceState(
        modal=Modal(V=r.V, A=r.A, B=r.B, dollar=r.dollar, T=r.T, VK=r.VK, VL=vl),
        xm=r.XM,
        status=list(r.status),
        outputs=r.outputs,
    )
    if profile.microstep is not None:
        state.microstep = profile.microstep.reset_mode
        state.current = profile.microstep.reset_current
    if profile.mpg is not None:
        state.mpg = profile.mpg.reset_mode
    return state
