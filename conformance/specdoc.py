"""The specification the suite checks, as a document (docs/spec.md), generated from
fixtures/rules.toml: every rule with its ID, tag, source and the profiles it applies to,
grouped by section, with the cases (and host-certification checks) that can fail it.

The rules file stays the one source; the document cannot drift from what the cases
check, because a test compares it with what this module renders now.

    python -m conformance.specdoc            # print it
    python -m conformance.specdoc --write    # rewrite docs/spec.md
    python -m conformance.specdoc --check    # exit 1 when docs/spec.md is stale
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable
from pathlib import Path

from conformance.case.context import Case
from gve_fixtures.rules import Rule, Spec, load_spec

#: where the document lives in a checkout (an installed copy has no docs/: --document)
DOCUMENT = Path(__file__).resolve().parent.parent / "docs" / "spec.md"

_NOTICE = ("<!-- Generated from fixtures/rules.toml by `python -m conformance.specdoc "
           "--write`; edit the rules file, not this one. -->")


def judges(cases: Iterable[Case], host_checks: dict[str, tuple[str, ...]]
           ) -> dict[str, list[str]]:
    """Rule ID -> the case IDs and host checks (as ``host: NAME``) that can fail it."""
    out: dict[str, list[str]] = {}
    for c in cases:
        for rule in c.rules:
            out.setdefault(rule, []).append(f"`{c.id}`")
    for name, rules in host_checks.items():
        for rule in rules:
            out.setdefault(rule, []).append(f"host: `{name}`")
    return out


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _rule_row(rule: Rule, by: dict[str, list[str]]) -> str:
    profiles = ", ".join(rule.profiles) if rule.profiles else "all"
    checked = ", ".join(by.get(rule.id, [])) or "—"
    return (f"| `{rule.id}` | {rule.tag} | {_cell(rule.source)} | {profiles} | "
            f"{_cell(rule.text)} | {checked} |")


def render(spec: Spec, by: dict[str, list[str]]) -> str:
    """The document: title, opening, then per section its rules in file order."""
    counts = {tag: sum(r.tag == tag for r in spec.rules.values())
              for tag in ("M", "M-ex", "D", "D-info")}
    lines = [_NOTICE, "", f"# {spec.title}", "", spec.preamble, "",
             f"{len(spec.rules)} rules: " + ", ".join(f"{n} {t}" for t, n in counts.items())
             + ". Roles: `unit` rules judge a unit's answers (the catalogue's cases), `host` "
               "rules a host program's traffic (`gve-conformance host`).", ""]
    for section in spec.sections:
        lines += [f"## {section.number}. {section.title}", "", section.text, ""]
        rules = spec.rules_of(section.number)
        if not rules:
            continue
        lines += ["| rule | tag | source | profiles | requirement | checked by |",
                  "|---|---|---|---|---|---|"]
        lines += [_rule_row(r, by) for r in rules]
        lines.append("")
    return "\n".join(lines)


def current() -> str:
    """The document as the rules file and the registered cases make it now."""
    import conformance.host.oracle  # noqa: F401  (registers the host checks)
    from conformance.run.coverage import HOST_CHECKS
    from conformance.run.selection import select
    return render(load_spec(), judges(select(), HOST_CHECKS))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m conformance.specdoc",
                                 description="The specification the suite checks, generated "
                                             "from fixtures/rules.toml.")
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--write", action="store_true", help="rewrite the document")
    mode.add_argument("--check", action="store_true",
                      help="exit 1 when the document is not what the rules make")
    ap.add_argument("--document", type=Path, default=DOCUMENT, metavar="PATH",
                    help="the document to write or check (default: the checkout's docs/spec.md)")
    args = ap.parse_args(argv)
    text = current()
    if args.write:
        args.document.write_text(text, encoding="utf-8")
        return 0
    if args.check:
        if not args.document.exists() or args.document.read_text(encoding="utf-8") != text:
            print(f"{args.document} is stale: run python -m conformance.specdoc --write",
                  file=sys.stderr)
            return 1
        return 0
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
