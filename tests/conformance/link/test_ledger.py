"""The run's EEPROM ledger: a copy for frames told ahead records their writes apart from
the run's own, which it leaves as they were."""

from __future__ import annotations

from conformance.link.ledger import EepromLedger


def test_a_copy_s_writes_and_put_backs_change_nothing_of_the_ledger_it_was_made_from():
    ledger = EepromLedger()
    ledger.found({0x10: 0xAB, 0x11: 0xCD})
    ledger.write([0x10])
    trial = ledger.copy()
    trial.write([0x11])
    trial.put_back([0x11])
    assert ledger.written == {0x10} and ledger.touched == set()
    assert trial.written == set() and trial.touched == {0x11}
    assert trial.backed_up(0x11) and ledger.originals == {0x10: 0xAB, 0x11: 0xCD}
