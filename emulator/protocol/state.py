"""The unit's protocol state that a reset (power-on, `J`) restores (spec 9)."""

from __future__ import annotations

from dataclasses import dataclass

from gve_fixtures.profile import Profile

# ST6 bits (spec 10.3)
STOP = 0x01
INTCOM = 0x10
QUEUE_FULL = 0x20   # only in the answer to F
RUN = 0x40
INTA = 0x80


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
class UnitState:
    modal: Modal
    xm: int
    status: list[int]                 # ST0..ST5 as written; ST6's stored bits (INTA, INTCOM, ...)
    outputs: int
    inputs: dict[int, int]
    checksums: bool = False
    index: int = 0
    history: tuple[bytes, bytes] | None = None   # last answered frame and its response
    packet: list | None = None        # members of an open packet
    saved: tuple | None = None        # KEEP save: (motion save, ST4, ST5, ST6 bits)
    kept_single: bool = False         # after K on GVE84/GVE114: the queue takes one L only
    microstep: str = "F"
    current: str = "D"
    mpg: str = ""
    spindle: int = 0
    reference_until: int = -1         # a W reference run in progress until then

    @property
    def inta(self) -> bool:
        return bool(self.status[6] & INTA)


def reset_state(profile: Profile) -> UnitState:
    r = profile.reset
    axes = len(profile.axes)
    vl = list(r.VL) if r.VL else [profile.max_rate] * axes
    state = UnitState(
        modal=Modal(V=r.V, A=r.A, B=r.B, dollar=r.dollar, T=r.T, VK=r.VK, VL=vl),
        xm=r.XM,
        status=list(r.status),
        outputs=r.outputs,
        inputs={0: 0xFF, 1: 0xFF, 2: 0xFF},
        checksums=r.checksums,
    )
    if profile.microstep is not None:
        state.microstep = profile.microstep.reset_mode
        state.current = profile.microstep.reset_current
    if profile.mpg is not None:
        state.mpg = profile.mpg.reset_mode
    return state
