"""A correct unit that has been used (its index elsewhere, the owner's EEPROM bytes, axes
and counters away from 0) earns no FAIL: every case PASSes it, or is MISSING, or cannot
test it and says why. Cases that assumed a fresh unit (the index counted from 0, ER0D
reading FF) FAILed it. Within the default envelope (2000 full steps) only the cases that
cannot be made smaller leave it."""

from __future__ import annotations

from fnmatch import fnmatch

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.verdicts.verdict import COULD_NOT_TEST, MISSING, PASS
from tests.conformance.cases.used import used_unit

#: cases that assumed a fresh unit: each must judge a used one
ONCE_FRESH = {"GVE84-100": ["3.params.hex-fields"],
              "GVE114-500": ["3.params.hex-fields", "6.checksum.address-7-shares"],
              "GVE54": ["3.params.hex-fields"]}

#: what needs more than 2000 full steps whatever the case does: a component at the top
#: of the vector range, the top rate of a fast variant (the ramps alone are longer), the
#: manuals' exchanges as they are
BEYOND_THE_ENVELOPE = ("1.profile.vector-range.limits", "10.2.measured.max-rate",
                       "11.golden.*")


@pytest.mark.parametrize("profile", sorted(ONCE_FRESH))
def test_a_used_unit_passes_every_case_it_can_be_judged_by(profile: str) -> None:
    unit = used_unit(profile, allow_destructive=True)
    before = unit.state()
    result = run([unit], select(), settings_name="ci")
    results = result.results
    wrong = {r.id: (r.verdict, [c["what"] for c in r.checks if not c["ok"]][:2])
             for r in results if r.verdict not in (PASS, MISSING, COULD_NOT_TEST)}
    assert wrong == {}
    unexplained = [r.id for r in results if r.verdict == COULD_NOT_TEST and not r.notes]
    assert unexplained == []
    stopped = [r.id for r in results if any(n.startswith("safety stop") for n in r.notes)]
    assert [i for i in stopped if not any(fnmatch(i, g) for g in BEYOND_THE_ENVELOPE)] == []
    verdicts = {r.id: r.verdict for r in results}
    assert {i: verdicts[i] for i in ONCE_FRESH[profile]} == dict.fromkeys(ONCE_FRESH[profile],
                                                                          PASS)
    # and the owner gets the unit back as it was used (the GVE54's counters excepted: it
    # has no N<axis> to set them back with)
    assert result.sessions[unit.info.spec]["problems"] == []
    after = unit.state()
    assert after["physical"] == before["physical"]
    if "NX" in unit.profile.commands:
        assert after["position"] == before["position"]
