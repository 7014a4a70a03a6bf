"""The cases are filed by spec section, one module each (as h2spec files its cases): a
case lives in the module of the section its ID names, and each module says which section
it is."""

from __future__ import annotations

import importlib
import pkgutil
import re

import conformance.cases
from conformance.run.selection import select
from gve_fixtures.rules import load_spec

NUMBERS = {s.number for s in load_spec().sections}


def _section(case_id: str) -> str:
    """The section a case's ID files it under: its longest leading number the spec has
    (``10.cmd.override`` → ``10``)."""
    m = re.match(r"\d+(?:\.\d+)*", case_id)
    assert m is not None, case_id
    number = m.group(0)
    while number not in NUMBERS:
        number = number.rsplit(".", 1)[0]
    return number


def _sections() -> dict[str, str]:
    """Section module name → the section its name gives (``s10_2_motion`` → ``10.2``)."""
    out = {}
    for info in pkgutil.iter_modules(conformance.cases.__path__):
        m = re.fullmatch(r"s(\d+)((?:_\d+)*)_[a-z0-9_]+", info.name)
        if m:
            out[info.name] = ".".join([str(int(m.group(1))), *m.group(2).split("_")[1:]])
    return out


def test_every_module_of_the_catalogue_is_a_section_or_the_kit():
    names = {info.name for info in pkgutil.iter_modules(conformance.cases.__path__)}
    assert names - set(_sections()) == {"_kit"}
    assert set(_sections().values()) <= NUMBERS


def test_each_section_module_names_its_section_first():
    for name, number in _sections().items():
        doc = importlib.import_module(f"conformance.cases.{name}").__doc__ or ""
        assert doc.startswith(f"Spec section {number}, "), name


def test_every_case_is_filed_under_the_section_of_its_id():
    filed: dict[str, str] = {}
    for name, number in _sections().items():
        module = importlib.import_module(f"conformance.cases.{name}")
        for case_id in getattr(module, "SCENARIOS", {}):
            filed[case_id] = number
    misfiled = []
    for c in select():
        module = c.func.__module__.rsplit(".", 1)[-1]
        if c.func.__module__.startswith("conformance.machines."):
            continue                 # the Hypothesis machines keep their own room
        number = filed.get(c.id, _sections().get(module))
        if number != _section(c.id):
            misfiled.append((c.id, module, number))
    assert misfiled == []
