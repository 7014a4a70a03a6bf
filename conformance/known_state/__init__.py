"""The known state a case starts from on a real unit: what the suite knows of the unit's
limits between cases (:mod:`.limits`), and the procedure that brings a unit there by the
manuals' rules only (:mod:`.procedure`: the stop in :mod:`.stop`, the way back and the
counters zeroed in :mod:`.way_back`, what the unit answered read in :mod:`.answers`, a
step that failed booked in :mod:`.failed_steps`). The run's session
(conformance/targets/session.py) sets it before each case and uses its stop and its way
back for Ctrl-C and the restorations.

Nothing is imported here, so that the motion probe reads the limits without the
procedure."""
