"""The guard, diff and the host role class every frame alike: the catalogue's examples,
the frames of the golden transcripts, diff's idioms, and a Hypothesis sample of bodies
(spec 10's names in either case, then parameters of any shape)."""

from __future__ import annotations

from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.diff.grammar import load_grammar
from conformance.diff.labels import command_of
from conformance.host.frame_rules import parse_frame
from conformance.link.body import Body
from conformance.protocol.catalogue import catalogue, commands
from conformance.protocol.framer import HostFramer
from gve_fixtures.profile import load_profile
from gve_fixtures.transcript import HOST, load

TRANSCRIPTS = Path(__file__).parents[3] / "fixtures" / "transcripts"
#: the GVE114 has every command but `M`; the GVE54 has `M`
UNITS = [{0: load_profile("GVE114-125")}, {0: load_profile("GVE54")}]


def classes(body: str) -> tuple[str, ...]:
    """The class each reader gives the body: the guard's, diff's, the host role's on
    each profile ("" for none)."""
    raw = b"!0" + body.encode("latin-1")
    return (Body.parse(body).name, command_of(body),
            *(parse_frame(raw, units, checksums=False).key for units in UNITS))


def alike(body: str) -> None:
    got = classes(body)
    assert len(set(got)) == 1, f"{body!r} is classed {got}"


def test_the_catalogues_examples_are_classed_alike_and_as_their_command():
    for name, command in catalogue().items():
        for body in command.examples:
            alike(body)
            if body.upper().startswith(name.rstrip("6")) and name != "SW":
                assert classes(body)[0] in (name, "SW6" if name == "SW" else name)


def test_the_decided_readings():
    # a write of ST6 however a unit that does not conform might read it (decisions.md)
    for body in ("SW6,80", "SW06,00", "SW+6,00", "sw6,00", "SW 6,00", "SW6"):
        assert classes(body) == ("SW6",) * 4, body
    for body in ("SW60,00", "SW0,80", "SW", "SW,6"):
        assert classes(body) == ("SW",) * 4, body
    assert classes("O0,FB") == ("O",) * 4
    assert classes("h") == ("H",) * 4
    for body in ("I3", "ZZ", "*X", ""):
        assert classes(body) == ("",) * 4, body


def test_the_golden_transcripts_frames_are_classed_alike():
    seen = 0
    for path in sorted(TRANSCRIPTS.glob("*.gvt")):
        framer = HostFramer()
        for rec in load(path).records:
            if rec.direction != HOST:
                continue
            for f in framer.frames(rec.data):
                for body in f.bodies(None):
                    alike(body)
                    seen += 1
    assert seen > 50


def test_diffs_idioms_are_classed_alike():
    g = load_grammar()
    frames = [*g["motion"]["events"], *(f for s in g["scenarios"]["list"] for f in s
                                        if not f.startswith(("wait ", "input ")))]
    for body in frames:
        alike(body.removeprefix("bad:"))


_NAMES = sorted(commands())
_TAIL = st.text(alphabet="0123456789,+- ABCDEFXYZswlf.e&%*!", max_size=12)


@settings(max_examples=400, deadline=None, derandomize=True)
@given(st.one_of(
    st.tuples(st.sampled_from(_NAMES), st.booleans(), _TAIL).map(
        lambda t: (t[0].lower() if t[1] else t[0]) + t[2]),
    st.text(alphabet=st.characters(min_codepoint=0x20, max_codepoint=0x7E), max_size=10)))
def test_a_sample_of_bodies_is_classed_alike(body):
    alike(body)
