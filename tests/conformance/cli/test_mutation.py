"""`gve-conformance mutation --sweep`: a case runs against a mutant only where its clean
run reached the mutant's code, and what it leaves out it says; the catch is the one the
whole sweep makes."""

from __future__ import annotations

import re

from conformance.catalogue import select
from conformance.cli.mutation import clean_run, hunt, main
from conformance.targets import parse_target


def test_the_sweep_leaves_out_the_cases_that_never_reach_the_mutant(capsys):
    args = ["--mutant", "sw6-inert", "--profile", "GVE84-100", "--cases", "10.3.*"]
    assert main([*args, "--sweep"]) == 0
    out = capsys.readouterr().out
    assert "caught  sw6-inert" in out
    (left_out,) = re.findall(r"(\d+) not run, the mutant's code unreached", out)
    clean = parse_target("emu:GVE84-100")
    cases = [c for c in select(["10.3.*"]) if not c.missing_for(clean.profile)]
    unreached = [c for c in cases if "sw6-inert" not in clean_run(c, clean)[1]]
    assert int(left_out) == len(unreached) > 0
    # the hunt without the sweep runs every case until the catch, and catches it alike
    assert hunt("sw6-inert", ["GVE84-100"], ["10.3.*"]).caught_by == \
        hunt("sw6-inert", ["GVE84-100"], ["10.3.*"], sweep=True).caught_by
