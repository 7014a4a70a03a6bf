"""The technician's hands: on a real unit without a test rig, a person at the unit does
what the rig's hands would (docs/rig.md, "By hand"). The wording is hand_steps.toml's.

- :class:`HandRig` is a :class:`~conformance.link.virtual.Rig` whose every action is a
  prompt: which input to ground or release, when to cycle the power, which outputs are
  lit. Each step is asked only with the unit at rest (SR6: not moving), the guard
  refuses motion while it is open, and it is verified by reading the unit back (``I<port>``
  for an input, ``@`` for a power cycle): not verified, it is asked again, then given up.
  Skipped, given up, or with nobody to ask, the case is COULD-NOT-TEST with the reason,
  never a FAIL. What no hand can do (a switch at an exact position, the spindle's
  setting) is COULD-NOT-TEST saying so.
- :class:`Hands` (``ctx.operator`` in a case): ground or release one input. With a rig
  (the emulator's, a simulator's control channel) the rig does it; else the technician,
  through a :class:`HandRig`.
- :func:`cannot_by_hand`: why no person can do a rig case (None: a person can).
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import cache
from importlib import resources
from typing import Any

from conformance.link.account import Spent
from conformance.link.framing import Response, UnitDataError
from conformance.link.link import Link
from conformance.link.liveness import SILENCE_LIMIT
from conformance.operator.console import Console, HandStep
from conformance.verdicts.verdict import CouldNotTest
from gve_fixtures.protocol import St6

#: input ports read FF with nothing connected (spec 10.3: inputs are grounded to act)
NOTHING_CONNECTED = 0xFF


@cache
def wording() -> dict[str, Any]:
    """hand_steps.toml."""
    text = resources.files("conformance.operator").joinpath("hand_steps.toml").read_text("utf-8")
    return tomllib.loads(text)


def cannot_by_hand(case_id: str) -> str | None:
    """Why no person can do the rig case ``case_id`` (None: a person can)."""
    return wording()["cannot"].get(case_id)


def _at_rest(r: Response) -> bool:
    """Whether an answer to `SR6` shows the unit not moving (spec 5: moving is RUN = 1
    with INTA = 0, or a stop ramp in progress): halted vectors holding RUN are at rest."""
    try:
        st6 = r.hex() if r.ok and r.values else None
    except UnitDataError:
        return False
    return st6 is not None and not st6 & St6.STOP and (not st6 & St6.RUN or bool(st6 & St6.INTA))


def _sentence(text: str) -> str:
    return text[:1].upper() + text[1:]


class HandRig:
    """A test rig whose hands are the technician's (see the module's docstring).
    ``link`` gives the case's current link: the steps outlive a case's fresh links, as
    the inputs a hand grounded stay grounded."""

    def __init__(self, link: Callable[[], Link], console: Console | None) -> None:
        self._link = link
        self.console = console
        self.words = wording()
        self._found: dict[int, int] = {}      # input ports as first read, before any step

    # -- asking ------------------------------------------------------------------------------
    def _step(self, kind: str, instruction: str, **where: int) -> HandStep:
        prompt = self.words["prompt"].format(instruction=instruction)
        return HandStep(kind, instruction, prompt, tuple(self.words["skip"]), **where)

    def _asked(self, step: HandStep, ask: Callable[[HandStep], Any]) -> Any:
        """``ask(step)`` with the unit at rest, no motion while it waits."""
        words = self.words
        if self.console is None or not self.console.interactive:
            raise CouldNotTest(words["nobody"].format(instruction=step.instruction[:1].lower()
                                                      + step.instruction[1:]))
        link = self._link()
        if link.poll("SR6", _at_rest, words["rest_seconds"]) is None:
            raise CouldNotTest(words["not_at_rest"].format(instruction=step.instruction))
        with link.guard.hands_on(), link.spending(Spent.HANDS):
            return ask(step)

    def _done(self, step: HandStep, verify: Callable[[], str | None]) -> None:
        """Ask ``step`` until ``verify()`` finds it done (None; else what it found) or
        the attempts run out; skipped or given up: COULD-NOT-TEST."""
        words = self.words
        for attempt in range(words["attempts"]):
            if not self._asked(step, lambda s: self.console.hand_step(s)):
                raise CouldNotTest(words["skipped"].format(instruction=step.instruction))
            found = verify()
            if found is None:
                return
            if attempt + 1 == words["attempts"]:
                raise CouldNotTest(words["not_verified"].format(instruction=step.instruction,
                                                                found=found))
            self.console.say(words["again"].format(found=found))

    # -- inputs ------------------------------------------------------------------------------
    def _read(self, port: int) -> int | None:
        r = self._link().send(f"I{port}")
        if r is None or not r.ok or not r.values:
            return None
        try:
            return int(r.values[0], 16)
        except ValueError:
            return None

    def set_input(self, port: int, value: int, address: int | None = None,
                  what: dict[int, str] | None = None) -> None:
        """Input port ``port`` to read ``value``: the bits that differ grounded or
        released by hand, then read back with ``I<port>``. ``what`` names inputs by bit."""
        words = self.words["input"]
        level = self._read(port)
        self._found.setdefault(port, NOTHING_CONNECTED if level is None else level)
        if level == value:
            return                                   # already so: nothing to ask
        now = NOTHING_CONNECTED if level is None else level
        changed = [bit for bit in range(8) if (now ^ value) >> bit & 1]
        parts = []
        for bit in changed:
            grounded = not value >> bit & 1
            named = (what or {}).get(bit) or words["of_port"].format(port=port)
            parts.append(words["ground" if grounded else "release"].format(bit=bit,
                                                                           what=named))
        step = self._step("input", _sentence("; ".join(parts)), port=port, level=value)

        def verify() -> str | None:
            got = self._read(port)
            if got == value:
                self.console.say(words["verified"].format(port=port, level=f"{got:02X}"))
                return None
            shown = "nothing" if got is None else f"{got:02X}"
            if len(changed) == 1:
                return words["one_bit"].format(port=port, shown=shown, bit=changed[0],
                                               want=value >> changed[0] & 1)
            return words["several"].format(port=port, shown=shown, level=f"{value:02X}")
        self._done(step, verify)

    def hands_off(self) -> None:
        """The inputs the steps changed, back as they were first read."""
        for port, level in sorted(self._found.items()):
            self.set_input(port, level)
        self._found.clear()

    # -- the power -------------------------------------------------------------------------
    def _index(self) -> int | None:
        link = self._link()
        r = link.send("@")
        if r is None or not r.ok or not r.values:
            return None
        try:
            return link.index_value(r)
        except UnitDataError:
            return None

    def power_on(self, address: int | None = None) -> None:
        """The technician cycles the power; verified by the index (`@`, which counts
        itself not): at least 2 before, 0 or 1 after (spec 8, 9)."""
        words = self.words["power"]
        link = self._link()
        before = self._index()
        for _ in range(2):                      # SR6 changes nothing and counts
            if before is None or before >= 2:
                break
            link.send("SR6")
            before = self._index()
        if before is None:
            raise CouldNotTest(f"{words['cycle']}: the unit does not answer @, so a power "
                               "cycle cannot be verified")
        step = self._step("power-on", words["cycle"])

        def verify() -> str | None:
            # a unit that restarted is in the reset state, its checksums off (spec 9): the
            # index is asked as of it; the mode as it was where no restart is seen
            summing, link.checksums = link.checksums, False
            after = None
            for _ in range(min(words["asks"], SILENCE_LIMIT - 1)):
                link.wait(words["ready_seconds"], Spent.MANUAL)
                after = self._index()
                if after is not None:
                    break
            if after is None or not after <= 1 < before:
                link.checksums = summing
            if after is None:
                raise CouldNotTest(words["no_answer"].format(instruction=step.instruction))
            if after <= 1 < before:
                link.guard.restarted()           # counters zeroed, the axes where they were
                self.console.say(words["verified"].format(after=after, before=before))
                return None
            return words["found"].format(after=after, before=before)
        self._done(step, verify)

    # -- what no hand does, and what an eye reads --------------------------------------------
    def set_switch(self, axis: str, position: int | None, address: int | None = None) -> None:
        words = self.words["switch"]
        if position is not None:
            raise CouldNotTest(words["exact"].format(axis=axis, position=position))
        # taking a switch away is done by hand but cannot be read back: asked, not verified
        step = self._step("switch", _sentence(words["remove"].format(axis=axis)))
        self._done(step, lambda: None)

    def spindle(self, address: int | None = None) -> int:
        raise CouldNotTest(self.words["spindle"]["exact"])

    def state(self, address: int | None = None) -> dict:
        raise CouldNotTest(self.words["state"]["exact"])

    def outputs(self, address: int | None = None) -> int:
        """The output port as the technician sees it (the outputs lit), active low."""
        words = self.words["outputs"]
        step = HandStep("outputs", words["instruction"], words["ask"],
                        tuple(self.words["skip"]))
        while True:
            answer = self._asked(step, lambda s: self.console.observe(s))
            if answer is None or answer.lower() in step.skip:
                raise CouldNotTest(words["skipped"])
            lit = _outputs(answer)
            if lit is not None:
                return NOTHING_CONNECTED & ~sum(1 << n for n in lit)
            self.console.say(words["again"])


def _outputs(answer: str) -> set[int] | None:
    """The output numbers in ``answer`` ("2 5", "none"); None when it is not that."""
    words = answer.replace(",", " ").split()
    if [w.lower() for w in words] in (["none"], []):
        return set() if words else None
    if all(w.isdigit() and int(w) < 8 for w in words):
        return {int(w) for w in words}
    return None


class Hands:
    """Hand steps for a case (``ctx.operator``): ``with ctx.operator.grounded(1, 0,
    "the X reference input"):`` — the input is active inside the block, released after."""

    def __init__(self, link: Callable[[], Link], console: Console | None) -> None:
        self._link = link                    # the case's current link (ctx.link)
        self.by_hand = HandRig(link, console)
        self._levels: dict[int, int] = {}    # rig ports as the rig was told to set them

    def _set(self, port: int, bit: int, what: str, grounded: bool) -> bool:
        rig = self._link().rig
        level = self._levels.get(port, NOTHING_CONNECTED)
        level = level & ~(1 << bit) if grounded else level | 1 << bit
        if rig is not None and not isinstance(rig, HandRig):
            self._levels[port] = level
            rig.set_input(port, level)
            return True
        now = self.by_hand._read(port)
        now = NOTHING_CONNECTED if now is None else now
        want = now & ~(1 << bit) if grounded else now | 1 << bit
        self.by_hand.set_input(port, want, what={bit: f"({what})"})
        return True

    def ground(self, port: int, bit: int, what: str) -> bool:
        """Make input IN<bit> of port I<port> active (grounded); True once verified."""
        return self._set(port, bit, what, grounded=True)

    def release(self, port: int, bit: int, what: str) -> bool:
        """Disconnect input IN<bit> again (reads 1); True once verified."""
        return self._set(port, bit, what, grounded=False)

    @contextmanager
    def grounded(self, port: int, bit: int, what: str) -> Iterator[None]:
        self.ground(port, bit, what)
        try:
            yield
        finally:
            self.release(port, bit, what)
