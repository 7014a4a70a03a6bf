"""A disagreement as the reports and the console show it: two different values, also
when the answers are the same bytes at different instants (a timing difference: the
instants, both sides), in results.json, on the console, in findings.jsonl and in
`replay`."""

from __future__ import annotations

import json

from conformance.cli import main

#: a mutant whose H answers at once instead of after its ramp
MUTANT = "emu:GVE84-100?mutant=halt-without-ramp"


def test_a_timing_disagreement_shows_both_instants(tmp_path, capsys):
    main(["diff", "--target", MUTANT, "--examples", "100", "--report-dir", str(tmp_path),
          "--run-id", "timing", "--seed", "1"])
    out = capsys.readouterr().out
    folder = tmp_path / "timing"
    checks = [c for r in json.loads((folder / "results.json").read_text())["results"]
              for c in r["checks"] if "(timing)" in c["what"]]
    assert checks, out
    for c in checks:
        assert c["observed"] != c["expected"], c
        assert c["observed"].endswith(" ms after the frame"), c
        assert f'observed "{c["observed"]}", expected "{c["expected"]}"' in out
    (event, *_) = [json.loads(line) for line in (folder / "findings.jsonl").open()
                   if '"timing"' in line]
    assert event["target"] == event["reference"]
    assert event["after"]["target"] != event["after"]["reference"]
    replayed = folder / event["transcript"].rsplit("/", 1)[-1]
    assert main(["replay", str(replayed), "--target", MUTANT]) == 1
    lines = capsys.readouterr().out.splitlines()
    (different,) = [line for line in lines if "DIFFERENT (timing" in line]
    assert (f"the target answered {event['after']['target']} after the frame, the "
            f"reference {event['after']['reference']}") in different
    assert lines[-1].endswith(f"after {event['after']['reference']} (timing): still there")
