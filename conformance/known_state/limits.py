"""The known state a case starts from on a real unit, as far as a case must know it to
predict answers (the known state sets it, the motion probe models from it)."""

from __future__ import annotations

from gve_fixtures.profile import Profile


def known_axis_limits(profile: Profile) -> tuple[int, ...]:
    """The VL a unit is put back to: the reset VL (the variant's maximum) where VL's range
    reaches it, else the top of the range (only J restores more, spec 9, 10)."""
    if "VL" not in profile.ranges:
        return tuple(profile.reset.VL)
    top = profile.range("VL").hi
    return tuple(min(v, top) for v in profile.reset.VL)
