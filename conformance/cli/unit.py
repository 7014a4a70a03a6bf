"""Before a run: which profile a unit is judged as (``--profile
auto`` asks it), what it says it is (for the report), and the question before the first
move on a real unit."""

from __future__ import annotations

from collections.abc import Callable

from conformance.cli.usage import UsageError
from conformance.metadata import RunMeta
from conformance.operator import Console, confirm_motion
from conformance.quoting import escaped, shown
from conformance.targetinfo import EMULATOR, is_emulator_spec
from conformance.targets import Target
from conformance.targets.identify import ask, bauds, choose, of_target, variant_of
from conformance.targets.port import locate
from gve_fixtures.profile import Profile

AUTO = "auto"
#: why a run that must ask before moving stops before sending anything
CANNOT_ASK = ("motion needs a yes and nobody can answer here (no terminal): give --yes on "
              "an unattended bench")


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


def _what_moves(target: Target, version: str, processor_id: str) -> list[str]:
    axes = ", ".join(f"{a} ±{target.info.max_travel}" for a in target.profile.axes)
    return [f"{target.info.spec}: {escaped(version) or '(no answer to ?)'}, "
            f"Q {escaped(processor_id)}, "
            f"judged as {target.profile.name}",
            f"  envelope (full steps either side of where the run began): {axes}",
            "  destructive tests (J, W, EEPROM writes; EEPROM backed up and restored): "
            + ("ON" if target.info.allow_destructive else "off")]


def ask_before_motion(target: Target, console: Console, meta: RunMeta
                      ) -> Callable[[], bool]:
    """The question the target's session asks before the run's first frame that can move
    an axis (its guard then refuses every motion frame unless the answer was yes)."""
    def ask() -> bool:
        found = target.session.identity
        yes = confirm_motion(console, _what_moves(target, found.get("version", ""),
                                                  found.get("processor_id", "")))
        meta.confirmed = "asked: yes" if yes else "asked: refused, nothing moved"
        if not yes:
            console.say("  motion refused: cases that move will be COULD-NOT-TEST")
        return yes
    return ask


def confirmed(targets: list[Target], meta: RunMeta, console: Console) -> bool:
    """The same question once for several targets before any of them runs (a fleet,
    whose members have no terminal); the identities are those known so far."""
    real = [t for t in targets if t.info.real]
    lines = [line for t in real for line in _what_moves(
        t, meta.target(t.info.spec).version, meta.target(t.info.spec).processor_id)]
    return not real or confirm_motion(console, lines)


def unattended(targets: list[Target], yes: bool, console: Console) -> None:
    """Refuse, before anything is sent, a run on a real unit that must ask before its
    first move (no ``--yes``) where nobody can answer (standard input not a terminal):
    the targets are closed, UsageError (exit status 2). The embedded emulator needs no
    question. ``--profile auto``, which asks the unit who it is, checks the specs first
    with :func:`unattended_specs`."""
    try:
        unattended_specs([t.info.spec for t in targets if t.info.real], yes, console)
    except UsageError:
        for t in targets:
            t.close()
        raise


def unattended_specs(specs: list[str], yes: bool, console: Console) -> None:
    """:func:`unattended` for target specs not yet opened."""
    real = [s for s in specs if not is_emulator_spec(s)]
    if real and not yes and not console.interactive:
        raise UsageError(CANNOT_ASK)
