"""One view of a unit from the wire: what the frames a host sent it and the answers it
gave tell of its protocol state, folded one exchange at a time by :func:`observe`.

The view owns, for the rest of the suite, the facts every reader of the wire needs alike:
the checksum mode, the open packet and its members, the index as `@` last read it (and
the form the unit writes it in, once measured), the modal settings and status words as
the host wrote them, the position counters as last read and whether the axes were last
seen moving. Readers keep only what is their own (the guard its envelope, a model its
expectations) and read the rest here, so that no two of them can disagree about an open
packet or the checksum mode.

Frames sent with no answer awaited (packet members, `*S`) stay :attr:`View.pending`
until the next awaited answer: a unit that answers one of them all the same (a frame it
does not take as a member) is given that answer by :func:`late`, which folds the frames
after it again from there — so an answer is the frame's that got it, never a later
frame's (docs/decisions.md, "one view of the unit").

The rules, each of them a decision where the suite's earlier trackers read the wire
differently (docs/decisions.md):

- an unanswered `*S` opens a packet (a second one restarts it); an answered `*S` opens
  nothing: the unit did not take it as a packet's start (spec 7: `*S` has no answer);
- inside an open packet an unanswered frame is a member, and *any* frame answered at
  once ends the packet: `*E` and the breakers (spec 7), and a frame the unit did not take
  as a member (only `C` and `B` may be one [M]);
- `%+` and `%-` taken set the checksum mode, `J` taken restarts the unit (the reset state:
  mode off, no packet), whichever of the unit's addresses they were sent to (the
  spindle's address shares the mode, spec 6 [D]);
- frames for another unit change nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from conformance.protocol import index as indexes
from conformance.protocol.bounded import decimal
from conformance.protocol.catalogue import classes
from conformance.protocol.index import Form
from conformance.protocol.parse import Parsed, parse
from conformance.protocol.wire import Response, is_hex_byte
from gve_fixtures.protocol import St6

#: frames a packet's start is, and those that are its members when unanswered [M]
_OPENS = classes(packet="opens")
_SURE_MEMBERS = classes(packet="member")
_CLOSES = classes(packet="closes")
_MODAL = classes(modal=True)
_POSITION = classes(position=True)
_RESTARTS = classes(restart=True)
_UNCOUNTED = classes(indexed=False)
#: the checksum mode a command leaves when taken (spec 6, 10 J)
_MODE_AFTER = {"%+": True, "%-": False}


@dataclass(frozen=True)
class Pending:
    """A frame sent with no answer awaited whose answer, if the unit gives one, has not
    come yet: its body, its address and the view before it (to fold again from)."""

    body: str
    address: int
    before: View


@dataclass(frozen=True)
class View:
    """A unit as the wire shows it (see the module's docstring). ``addresses``: the
    addresses it answers (its own, and a GVE114's spindle)."""

    addresses: frozenset[int] = frozenset({0})
    checksums: bool = False
    #: the open packet's members as sent (None: no packet open)
    packet: tuple[str, ...] | None = None
    #: how the last frame observed for the unit stood to a packet: "opens", "member" (a
    #: `C` or `B` the manuals answer with nothing there), "kept" (another frame
    #: unanswered there, kept as a member that fails the packet: a unit may take a
    #: breaker as one), "unclosed" (an `*E` unanswered, kept so too), "closes"
    #: (answered, it ended one), or "" (none open)
    role: str = ""
    #: frames sent with no answer awaited whose answer may still come, oldest first
    pending: tuple[Pending, ...] = ()
    index_form: Form | None = None
    #: the index as `@` last read it (None: not read since the unit last restarted, or
    #: not readable), and the frames sent to the unit since that read
    index: int | None = None
    since_index: int = 0
    #: modal settings and status words taken since the unit last restarted, as written
    modal: tuple[tuple[str, str], ...] = ()
    status: tuple[tuple[str, str], ...] = ()
    #: the position counters as last read (None: not read since the last restart)
    position: tuple[str, ...] | None = None
    #: whether ST6 last read showed RUN (None: not read)
    moving: bool | None = None

    @property
    def packet_open(self) -> bool:
        return self.packet is not None

    @property
    def silent_by_rule(self) -> bool:
        """Whether the last frame went unanswered as a packet's start or member may:
        its silence is no sign of a unit gone. `*E` is answered whatever the packet
        (spec 7): its silence is one."""
        return self.role in ("opens", "member", "kept")

    @property
    def answerable(self) -> int:
        """How many frames pending may still be answered: those the manuals answer
        (every one but `*S` and a packet's members)."""
        return sum(1 for p in self.pending if _may_answer(p))

    def summed_after(self, body: str) -> bool:
        """Whether the answer to ``body`` carries a checksum: iff the mode is on after
        the command (spec 6, 10 J)."""
        if body in _MODE_AFTER:
            return _MODE_AFTER[body]
        return False if body == "J" else self.checksums

    def assume(self, **known: object) -> View:
        """The view with what the caller learnt otherwise than from one exchange (the
        checksum mode a probe found, the index's form measured)."""
        return replace(self, **known)  # type: ignore[arg-type]

    def listened(self) -> View:
        """The line was listened to after the frames pending (a wait): what did not come
        meanwhile answers none of them (a unit answers as soon as possible, spec 2)."""
        return _with(self, pending=()) if self.pending else self

    def restarted(self) -> View:
        """The unit restarted (a taken `J`, a power cycle): the reset state (spec 9)."""
        return View(addresses=self.addresses, index_form=self.index_form, index=0)


def _may_answer(p: Pending) -> bool:
    name = parse(p.body).key
    return not (name in _OPENS or (p.before.packet is not None and name in _SURE_MEMBERS))


def observe(view: View, body: str, answer: Response | None, address: int | None = None,
            *, awaited: bool = True) -> View:
    """The view after the frame ``body`` for ``address`` (None: the unit's first) got
    ``answer`` (None: none read). ``awaited``: its answer was waited for; a frame sent
    with none awaited stays pending, to be given an answer that comes later (:func:`late`).
    An awaited answer read ends every pending frame's chance of one."""
    where = min(view.addresses) if address is None else address
    if awaited and view.pending:
        view = _with(view, pending=())
    if where not in view.addresses:
        return view
    after = _fold(view, body, answer)
    if not awaited and answer is None:
        after = _with(after, pending=(*after.pending, Pending(body, where, view)))
    return after


def answered_late(view: View) -> Pending | None:
    """The frame pending that an answer coming now belongs to (:func:`late`)."""
    return next((p for p in view.pending if _may_answer(p)), None)


def late(view: View, answer: Response) -> View | None:
    """The view once ``answer``, which came after its frame, is given to the first frame
    pending that may be answered (answers come in the order of their frames: those
    pending before it got none); the frames after it are folded again, unanswered, from
    there. None: no frame pending may have it (it is nobody's)."""
    for i, p in enumerate(view.pending):
        if _may_answer(p):
            out = _with(_fold(p.before, p.body, answer), pending=())
            for q in view.pending[i + 1:]:
                out = observe(out, q.body, None, q.address, awaited=False)
            return out
    return None


def _with(view: View, **changes: object) -> View:
    """``view`` with ``changes``: what dataclasses.replace does, without its checks (a
    view is folded on every frame)."""
    twin = object.__new__(View)
    twin.__dict__.update(view.__dict__)
    twin.__dict__.update(changes)
    return twin


def _fold(view: View, body: str, answer: Response | None) -> View:
    parsed = parse(body)
    name = parsed.key
    answered = answer is not None and answer.code is not None
    changes: dict[str, object] = {}
    if name not in _UNCOUNTED:
        changes["since_index"] = view.since_index + 1
    # the packet (spec 7)
    packet = view.packet
    if name in _OPENS and not answered:
        changes.update(packet=(), role="opens")
    elif packet is not None and not answered:
        role = ("member" if name in _SURE_MEMBERS else "unclosed" if name in _CLOSES
                else "kept")
        changes.update(packet=(*packet, body), role=role)
    elif packet is not None:
        changes.update(packet=None, role="closes")
    elif view.role:
        changes["role"] = ""
    if answered and answer.ok:
        # what a frame the unit took sets or shows
        if name in _RESTARTS:
            return view.restarted()
        changes.update(_taken(view, parsed, list(answer.values)))
    return _with(view, **changes) if changes else view


def _taken(view: View, parsed: Parsed, values: list[str]) -> dict[str, object]:
    """What a frame the unit took sets (the mode, a setting) or shows (the index, the
    counters, RUN)."""
    name = parsed.key
    mode = _MODE_AFTER.get(f"{parsed.name}{parsed.params}")
    if mode is not None:
        return {"checksums": mode}
    if name == "@" and values:
        form = view.index_form or indexes.evident(values[0])
        read = indexes.value(values[0], form) if form is not None else None
        return {"index": read, "since_index": 0}
    if name in _MODAL:
        return {"modal": _set(view.modal, name, parsed.params)}
    if name == "SW" and len(parsed.fields) >= 2:
        return {"status": _set(view.status, parsed.fields[0], parsed.fields[1])}
    if name in _POSITION:
        counters = tuple(values)
        if all(decimal(v, signed=True) is not None for v in counters):
            return {"position": counters}
        return {}
    if (name == "F" or (name == "SR" and parsed.params.strip() == "6")) and values \
            and is_hex_byte(values[0]):
        return {"moving": bool(int(values[0], 16) & St6.RUN)}
    return {}


def _set(pairs: tuple[tuple[str, str], ...], key: str, value: str) -> tuple[tuple[str, str], ...]:
    return tuple(sorted({**dict(pairs), key: value}.items()))
