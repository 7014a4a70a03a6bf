"""Before a run: which profile a unit is judged as (``--profile
auto`` asks it), what it says it is (for the report), and the question before the first
move on a real unit."""

from __future__ import annotations

from conformance.cli.usage import UsageError
from conformance.operator.consent import Consent, NoConsent
from conformance.operator.console import Console
from conformance.run.metadata import RunMeta
from conformance.targets import Target
from conformance.targets.identify import ask, bauds, choose, of_target, variant_of
from conformance.targets.info import EMULATOR
from conformance.targets.port import locate
from conformance.verdicts.quoting import shown
from gve_fixtures.profile import Profile

AUTO = "auto"


def _ask_variant(console: Console):
    def ask_variant(found: list[Profile]) -> str | None:
        return console.choose(f"Which {found[0].family} is this unit? (its maximum pulse rate "
                              "in thousands, on its label)", [variant_of(p.name) for p in found])
    return ask_variant if console.interactive else None


def resolve(spec: str, profile: str | None, variant: str | None, console: Console
            ) -> tuple[str, str | None, str]:
    """(spec, profile, how it was chosen) for one target; ``--profile auto`` asks a
    serial/tcp unit `?` and `Q` and says what it chose. ValueError when it cannot."""
    kind, _, rest = spec.partition(":")
    if profile != AUTO:
        return spec, profile, "emulated" if kind == EMULATOR else "--profile"
    if kind == EMULATOR:
        return spec, None, "emulated"                 # the emulated unit is its profile
    if kind == "exec":
        raise ValueError(f"{spec}: name the profile the simulator behaves as (--profile "
                         "auto asks a unit already on a port)")
    url, q = locate(kind, rest)
    address = int(q.get("address", ["0"])[-1])
    identity = ask(url, address, bauds(int(q["baud"][-1]) if "baud" in q else None))
    if identity is None:
        raise ValueError(f"{spec}: no GVE unit answered ? at address {address} "
                         "(is it on, on this port, at this address?)")
    chosen, how = choose(identity, variant, _ask_variant(console))
    console.say(f"{spec}: ? {shown(identity.version)}, Q {shown(identity.processor_id)} at "
                f"{identity.baud} baud -> profile {chosen.name} ({how})")
    if "baud" not in q:                               # keep the rate it answered at
        spec += ("&" if "?" in rest else "?") + f"baud={identity.baud}"
    return spec, chosen.name, how


def record_identities(targets: list[Target], meta: RunMeta) -> None:
    """Each unit's answers to `?` and `Q` into the run's metadata (a real unit's session
    reads them itself, before its first case)."""
    for target in targets:
        identity = of_target(target)
        if identity is not None:
            t = meta.target(target.info.spec)
            t.version, t.processor_id = identity.version, identity.processor_id


def consent(yes: bool, console: Console, meta: RunMeta) -> Consent:
    """The run's consent to motion (conformance/operator/consent.py), its answer into ``meta``."""
    return Consent(yes, console, answered=lambda how: setattr(meta, "confirmed", how))


def confirmed(targets: list[Target], meta: RunMeta, console: Console) -> bool:
    """The same question once for several targets before any of them runs (a fleet,
    whose members have no terminal); the identities are those known so far."""
    return consent(False, console, meta).ask_once(
        targets, lambda t: (meta.target(t.info.spec).version,
                            meta.target(t.info.spec).processor_id))


def unattended(targets: list[Target], yes: bool, console: Console) -> None:
    """Refuse, before anything is sent, a run on a unit that can move and must ask before
    its first move (no ``--yes``) where nobody can answer (standard input not a
    terminal): the targets are closed, UsageError (exit status 2). ``--profile auto``,
    which asks the unit who it is, checks the specs first with :func:`unattended_specs`."""
    try:
        Consent(yes, console).check(targets)
    except NoConsent as err:
        for t in targets:
            t.close()
        raise UsageError(str(err)) from None


def unattended_specs(specs: list[str], yes: bool, console: Console) -> None:
    """:func:`unattended` for target specs not yet opened."""
    try:
        Consent(yes, console).check_specs(specs)
    except NoConsent as err:
        raise UsageError(str(err)) from None
