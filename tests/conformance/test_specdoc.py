"""The specification in docs/: generated from fixtures/rules.toml, never stale, every
rule with its tag and the cases that can fail it."""

import dataclasses
from pathlib import Path

from conformance import specdoc
from conformance.case.context import REGISTRY
from gve_fixtures.rules import load_spec

#: the checkout's document (the tests also run against an installed copy, which has none)
DOCUMENT = Path(__file__).resolve().parents[2] / "docs" / "spec.md"


def test_docs_spec_is_what_the_rules_and_cases_make_now():
    assert DOCUMENT.read_text(encoding="utf-8") == specdoc.current(), \
        "docs/spec.md is stale: run python -m conformance.specdoc --write"


def test_every_rule_appears_once_with_its_tag_under_its_section():
    text = specdoc.current()
    spec = load_spec()
    for rule in spec.rules.values():
        rows = [line for line in text.splitlines() if line.startswith(f"| `{rule.id}` |")]
        assert len(rows) == 1, rule.id
        assert rows[0].split(" | ")[1] == rule.tag
        heading = text.rindex("\n## ", 0, text.index(rows[0]))
        assert text[heading:].startswith(f"\n## {rule.section}. ")


def test_a_rule_lists_the_cases_that_name_it():
    text = specdoc.current()
    row = next(line for line in text.splitlines() if line.startswith("| `6.checksum.bad-refused"))
    naming = [c.id for c in REGISTRY.values() if "6.checksum.bad-refused" in c.rules]
    assert naming and all(f"`{c}`" in row for c in naming)


def test_a_changed_rule_makes_the_document_stale(tmp_path, capsys):
    spec = load_spec()
    rule = next(iter(spec.rules.values()))
    changed = dataclasses.replace(spec, rules={**spec.rules,
                                               rule.id: dataclasses.replace(rule, tag="M")})
    document = tmp_path / "spec.md"
    document.write_text(specdoc.render(changed, {}), encoding="utf-8")
    where = ["--document", str(document)]
    assert specdoc.main(["--check", *where]) == 1
    assert "stale" in capsys.readouterr().err
    assert specdoc.main(["--write", *where]) == 0
    assert specdoc.main(["--check", *where]) == 0
