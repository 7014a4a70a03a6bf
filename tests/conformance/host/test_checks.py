"""The host rules over hand-built recordings: each rule is broken where the spec says it
is and kept where it is not."""

from __future__ import annotations

from conformance.host.checks import MS, PATIENCE_MS
from conformance.host.frame_rules import byte_sum
from conformance.host.oracle import HOST_CHECKS
from gve_fixtures.profile import load_profile
from gve_fixtures.rules import load_rules
from tests.conformance.host.records import Wire, broken


def test_every_host_check_names_a_host_rule():
    rules = load_rules()
    assert HOST_CHECKS
    for rule in HOST_CHECKS:
        assert "host" in rules[rule].roles, rule


def test_simplex_waits_for_each_answer():
    w = Wire()
    w.frame(b"!0V1000", 0)                      # answered at 1 ms after its CR
    w.frame(b"!0A100", 0.5)                     # sent before that answer came: spec 2
    w.frame(b"!0B100", 50)
    assert broken(w.judge())["2.link.simplex"] == ["!0A100"]


def test_a_host_may_give_an_answer_up_after_waiting_long_enough():
    w = Wire()
    w.frame(b"!0V1000", 0, lost=True)
    w.frame(b"!0@", PATIENCE_MS + 5, answer=b"0,1\r")
    assert "2.link.simplex" not in broken(w.judge())
    w = Wire()
    w.frame(b"!0V1000", 0, lost=True)
    w.frame(b"!0@", PATIENCE_MS / 2, answer=b"0,1\r")
    assert "2.link.simplex" in broken(w.judge())


def test_frames_the_relay_read_together_after_a_stall_of_its_own_are_not_judged():
    # the host gave `@` up after its timeout and sent `?`; the relay, descheduled for
    # 300 ms, read both in one chunk and stamped them at the same instant
    w = Wire()
    w.frame(b"!0@", 300, lost=True)
    w.frame(b"!0?", 300, answer=b"0,IP114\r")
    assert "2.link.simplex" in broken(w.judge())
    w.rec.stalls.append((round(1 * MS), round(300 * MS)))
    j = w.judge()
    assert "2.link.simplex" not in broken(j)
    assert any("not judged for 2.link.simplex" in n for n in j.notes)


def test_members_get_no_answer_so_the_next_frame_follows_at_once():
    w = Wire()
    w.frame(b"!0*S", 0, answer=None)
    w.frame(b"!0C1,0,0", 0.2, answer=None)
    w.frame(b"!0C2,0,0", 0.4, answer=None)
    w.frame(b"!0*E2", 0.6, answer=b"0,2\r")
    assert broken(w.judge()) == {}


def test_packet_counts_and_members():
    w = Wire()
    w.frame(b"!0*S", 0, answer=None)
    w.frame(b"!0C1,0,0", 1, answer=None)
    w.frame(b"!0V100", 2, answer=None)           # not a member (spec 7)
    w.frame(b"!0*E1", 3, answer=b"4,2\r")        # two members were sent
    found = broken(w.judge())
    assert found["7.packet.members"] == ["!0V100"]
    assert found["7.packet.count"] == ["!0*E1"]


def test_a_star_e0_closing_a_packet_the_host_is_unsure_of_is_no_fault():
    w = Wire()
    w.frame(b"!0*S", 0, answer=None)
    w.frame(b"!0C1,0,0", 1, answer=None)
    w.frame(b"!0*E1", 2, answer=b"1,0\r")        # refused: the packet may still be open
    w.frame(b"!0*E0", 5, answer=b"4,0\r")        # the only sure way to end one
    found = broken(w.judge())
    assert "7.packet.exchange" not in found and "5.code.syntax" not in found
    w = Wire()
    w.frame(b"!0*E0", 0, answer=b"4,0\r")        # no packet was ever opened
    w.frame(b"!0*S", 3, answer=None)
    w.frame(b"!0C1,0,0", 4, answer=None)
    w.frame(b"!0*E1", 5, answer=b"0,1\r")
    w.frame(b"!0*E0", 8, answer=b"4,0\r")        # after a packet that ended well
    found = broken(w.judge())
    assert found["7.packet.exchange"] == ["!0*E0", "!0*E0"]


def test_gaps_below_the_watchdog():
    w = Wire()
    w.frame(b"!0V1000", 0, gap_ms=20)            # a COM_SEND host: 20 ms a byte
    w.frame(b"!0V2000", 500, gap_ms=120)         # slower than the 100 ms watchdog
    j = w.judge()
    assert broken(j)["3.frame.watchdog"] == ["!0V2000"]
    assert any("slowest gap" in n and "120.0 ms" in n for n in j.notes)


def test_a_gap_while_the_relay_itself_stalled_is_not_held_against_the_host():
    w = Wire()
    w.frame(b"!0V2000", 0, gap_ms=120)
    w.rec.stalls.append((0, 1000 * 1_000_000))      # the relay was late all along
    assert "3.frame.watchdog" not in broken(w.judge())


def test_a_lost_answer_is_recovered_with_the_index():
    w = Wire()
    w.frame(b"!0L1000,0,0", 0, lost=True, fault="lost-answer")
    w.frame(b"!0@", 300, answer=b"0,5\r")
    w.frame(b"!0>", 301, answer=b"0\r")
    assert broken(w.judge()) == {}


def test_a_vector_resent_blindly():
    w = Wire()
    w.frame(b"!0L1000,0,0", 0, lost=True, fault="lost-answer")
    w.frame(b"!0L1000,0,0", 300)
    assert broken(w.judge())["8.recovery.no-blind-resend"] == ["!0L1000,0,0"]


def test_a_setting_sent_again_is_a_recovery_an_answer_ignored_is_not():
    # "Většina příkazů se dá zopakovat (A,V,PF atd..)": once or twice, the unit is alike
    w = Wire()
    w.frame(b"!0V1000", 0, lost=True, fault="lost-answer")
    w.frame(b"!0V1000", 300)
    w.frame(b"!0A100", 400, lost=True, fault="lost-answer")
    w.frame(b"!0B100", 700)
    assert broken(w.judge()) == {"8.recovery.ask-index": ["!0B100"]}


def test_an_answer_whose_checksum_fails_is_not_trusted():
    w = Wire()
    w.frame(b"!0V1000,C4", 0, answer=b"0,5C\r", given=b"1,5C\r", fault="corrupt-answer",
            checksums=True)
    w.frame(b"!0A100,4F", 10, answer=b"0,5C\r", checksums=True)
    w.frame(b"!0L10,0,0,E2", 20, answer=b"0,5C\r", given=b"1,5C\r",
            fault="corrupt-answer", checksums=True)
    w.frame(b"!0L10,0,0,E2", 30, answer=b"0,5C\r", checksums=True)
    assert broken(w.judge())["6.checksum.response-sum"] == ["!0A100,4F", "!0L10,0,0,E2"]


def test_reads_while_the_host_waits_to_ask_trust_nothing():
    # a damaged answer to a vector: F until the motion ends, then PF and @, then on
    w = Wire()
    w.frame(b"!0L10,0,0,E2", 0, answer=b"0,5C\r", given=b"1,5C\r", fault="corrupt-answer",
            checksums=True)
    w.frame(b"!0F,C3", 10, answer=b"0,40,EC\r", checksums=True)
    w.frame(b"!0PF,13", 20, answer=b"0,0,0,0,70\r", checksums=True)
    w.frame(b"!0@,BD", 30, answer=b"0,15,EE\r", checksums=True)
    w.frame(b"!0V1000,94", 40, answer=b"0,5C\r", checksums=True)
    assert broken(w.judge()) == {}
    # reads, then on without asking: still trusted
    w = Wire()
    w.frame(b"!0L10,0,0,E2", 0, answer=b"0,5C\r", given=b"1,5C\r",
            fault="corrupt-answer", checksums=True)
    w.frame(b"!0F,C3", 10, answer=b"0,40,EC\r", checksums=True)
    w.frame(b"!0L10,0,0,E2", 20, answer=b"0,5C\r", checksums=True)
    assert broken(w.judge())["6.checksum.response-sum"] == ["!0L10,0,0,E2"]


def _summed(body: bytes) -> bytes:
    return body + b",%02X" % byte_sum(body + b",")


def test_a_host_that_read_the_positions_after_a_damaged_answer_did_not_trust_it():
    # a damaged answer to a packet's *E: *E0, F until the motion ends, PF until it rests,
    # then the next packet's setting: it found out by the positions what became of it
    def damaged_packet() -> Wire:
        w = Wire()
        w.frame(_summed(b"!0*S"), 0, answer=None, checksums=True)
        w.frame(_summed(b"!0C0,-400,0"), 1, answer=None, checksums=True)
        w.frame(_summed(b"!0*E1"), 2, answer=_summed(b"0,1") + b"\r",
                given=_summed(b"0,1").replace(b"0,", b"1,", 1) + b"\r",
                fault="corrupt-answer", checksums=True)
        w.frame(_summed(b"!0*E0"), 10, answer=_summed(b"4,0") + b"\r", checksums=True)
        w.frame(_summed(b"!0F"), 20, answer=_summed(b"0,40") + b"\r", checksums=True)
        w.frame(_summed(b"!0F"), 30, answer=_summed(b"0,00") + b"\r", checksums=True)
        w.frame(_summed(b"!0PF"), 40, answer=_summed(b"0,0,-400,0") + b"\r",
                checksums=True)
        return w
    w = damaged_packet()
    w.frame(_summed(b"!0B10"), 50, answer=_summed(b"0") + b"\r", checksums=True)
    found = broken(w.judge())
    assert "6.checksum.response-sum" not in found
    # the manual's recovery is `@`: going on after the positions alone is its [D] rule's
    assert found == {"8.recovery.ask-index": [_summed(b"!0B10").decode()]}
    # a host that only read after it and stopped trusted nothing either
    assert broken(damaged_packet().judge()) == {}
    # the same reads, then the packet sent again without asking: a blind resend
    w = damaged_packet()
    w.frame(_summed(b"!0*S"), 50, answer=None, checksums=True)
    found = broken(w.judge())
    assert "6.checksum.response-sum" not in found
    assert found["8.recovery.no-blind-resend"] == [_summed(b"!0*S").decode()]


def test_a_status_read_tells_nothing_of_a_damaged_answer():
    # F alone says whether the unit moves, not what became of the frame: a setting after
    # it rests on the damaged answer
    w = Wire()
    w.frame(b"!0L10,0,0,E2", 0, answer=b"0,5C\r", given=b"1,5C\r", fault="corrupt-answer",
            checksums=True)
    w.frame(b"!0F,C3", 10, answer=b"0,40,EC\r", checksums=True)
    w.frame(b"!0V1000,94", 20, answer=b"0,5C\r", checksums=True)
    assert broken(w.judge())["6.checksum.response-sum"] == ["!0V1000,94"]


def test_a_setting_sent_again_after_a_damaged_answer_trusts_nothing():
    w = Wire()
    w.frame(b"!0SW2,00,E5", 0, answer=b"0,5C\r", given=b"1,5C\r", fault="corrupt-answer",
            checksums=True)
    w.frame(b"!0SW2,00,E5", 10, answer=b"0,5C\r", checksums=True)
    w.frame(b"!0V1000,94", 20, answer=b"0,5C\r", checksums=True)
    assert broken(w.judge()) == {}


def test_noise_before_a_whole_answer_may_simply_be_skipped():
    w = Wire()
    w.frame(b"!0V1000", 0, given=b"\x00\xff0\r", fault="noise")
    w.frame(b"!0A100", 10)
    assert broken(w.judge()) == {}


def test_a_full_queue_is_tried_again():
    w = Wire()
    w.frame(b"!0L10,0,0", 0, answer=b"1\r")
    w.frame(b"!0L20,0,0", 10, answer=b"1\r")
    w.frame(b"!0L10,0,0", 20)
    assert broken(w.judge())["5.code.queue-full"] == ["!0L20,0,0"]


def test_a_host_that_gives_up_while_a_refused_vector_waits_did_not_ignore_the_refusal():
    # refused with 1 until the host gave up for a reason of its own (exit 4): its giving
    # up is judged by 8.recovery.finishes, not as a vector left out
    w = Wire()
    w.frame(b"!0L10,0,0", 0)
    w.frame(b"!0L20,0,0", 10, answer=b"1\r")
    w.frame(b"!0L20,0,0", 20, answer=b"1\r")
    w.frame(b"!0@", 30, answer=b"0,13\r")
    j = w.judge(exit_code=4)
    assert "5.code.queue-full" not in broken(j)
    assert any("gave up" in n for n in j.notes)
    # one that went on with the next vector after giving the refused one up left it out,
    # whatever its exit
    w.frame(b"!0L30,0,0", 40)
    assert broken(w.judge(exit_code=4))["5.code.queue-full"] == ["!0L20,0,0"]
    # and one that exits 0 never sent it again
    w = Wire()
    w.frame(b"!0L20,0,0", 10, answer=b"1\r")
    assert broken(w.judge(exit_code=0))["5.code.queue-full"] == ["!0L20,0,0"]


def test_refusals_a_host_leans_on_are_its_fault():
    # each command refused twice: a host that repeats what the unit refuses relies on it
    w = Wire()
    for t in (0, 40):
        w.frame(b"!0l100,0,0", t, answer=b"3\r")
        w.frame(b"!0V1000.0", t + 10, answer=b"4\r")
        w.frame(b"!0SW8,F1", t + 20, answer=b"5\r")
        w.frame(b"!0N", t + 30, answer=b"7\r")           # while moving (spec 5, 10.1)
    found = broken(w.judge())
    assert found["10.1.queue.wait-idiom"] == ["!0N", "!0N"]
    assert found["5.code.unknown"] == ["!0l100,0,0"] * 2
    assert found["5.code.syntax"] == ["!0V1000.0"] * 2
    assert found["5.code.range"] == ["!0SW8,F1"] * 2


def _graded(j, rule: str) -> list[tuple[str, str | None]]:
    return [(f.frame, f.tag) for f in j.findings if f.rule == rule]


def test_a_refusal_provoked_once_and_never_repeated_is_graded_by_our_reading():
    # a host that sends V39 to learn how the GVE54 answers, takes the 5 and goes on with
    # other values: no sentence of the manuals forbids the frame, so the refusal and the
    # value's range are [D] (NON-STRICT), not the unit's [M] rule
    w = Wire({0: load_profile("GVE54")})
    w.frame(b"!0V39", 0, answer=b"5\r")
    w.frame(b"!0@", 10, answer=b"0,1\r")
    w.frame(b"!0V1000", 20)
    j = w.judge()
    assert _graded(j, "5.code.range") == [("!0V39", "D")]
    assert _graded(j, "1.profile.v-b-range-gve54") == [("!0V39", "D")]
    assert all("a probe" in f.what for f in j.findings if f.tag == "D")
    # the same value sent again: the host leans on it, the unit's rule FAILs it
    w.frame(b"!0V39", 30, answer=b"5\r")
    j = w.judge()
    assert _graded(j, "5.code.range") == [("!0V39", None), ("!0V39", None)]
    assert _graded(j, "1.profile.v-b-range-gve54") == [("!0V39", None), ("!0V39", None)]


def test_a_refusal_the_host_stopped_at_is_no_probe():
    w = Wire({0: load_profile("GVE54")})
    w.frame(b"!0V1000", 0)
    w.frame(b"!0V39", 10, answer=b"5\r")
    assert broken(w.judge(exit_code=1))["5.code.range"] == ["!0V39"]


def test_a_second_refusal_of_the_same_command_is_no_probe():
    w = Wire({0: load_profile("GVE54")})
    w.frame(b"!0V39", 0, answer=b"5\r")
    w.frame(b"!0V38", 10, answer=b"5\r")
    assert broken(w.judge())["5.code.range"] == ["!0V39", "!0V38"]


def test_nothing_is_sent_while_the_unit_restarts_after_j():
    w = Wire()
    w.frame(b"!0J", 0)
    w.frame(b"!0@", 500, answer=None)            # the unit restarts for 2000 ms
    w.frame(b"!0@", 2500, answer=b"0,0\r")
    assert broken(w.judge())["2.link.ready-after-restart"] == ["!0@"]


def test_port_settings():
    w = Wire()
    w.rec.settings.append((0, "115200 8N2"))
    assert broken(w.judge())["2.link.serial-8n1"] == ["(port settings)"]


def test_coverage_counts_the_host_checks():
    from conformance.run.coverage import coverage

    (pc,) = coverage(["GVE84-100"], role="host", cases=[])
    assert "8.recovery.exactly-once" in next(s for s in pc.sections if s.section == "8").covered
    assert pc.covered == pc.total, pc.uncovered


def test_a_worked_example_is_sent_as_the_spec_sums_it():
    w = Wire()
    w.frame(b"!0A100,4F", 0, answer=b"0,5C\r", checksums=True)   # spec 11 G2
    w.frame(b"!0A200,50", 10, answer=b"0,5C\r", checksums=True)  # no worked example
    assert "11.golden.g2" not in broken(w.judge())
    w = Wire()
    w.frame(b"!0A100,4E", 0, answer=b"4,5D\r", checksums=True)   # summed one short
    found = broken(w.judge())
    assert found["11.golden.g2"] == ["!0A100,4E"]
    assert found["6.checksum.sum"] == ["!0A100,4E"]


def test_a_refusal_the_relay_gave_late_is_not_held_against_the_host():
    # the relay stalled 300 ms (its process under load) before giving the `1`: the host
    # had given it up for lost and asked `@`; it then stopped (exit status 1)
    w = Wire()
    w.frame(b"!0L10,0,0", 0, answer=b"1\r", given_ms=305)
    w.frame(b"!0@", 300, answer=b"0,1\r")
    w.rec.stalls.append((2 * MS, 302 * MS))
    j = w.judge()
    assert "5.code.queue-full" not in broken(j)
    assert any("not judged for 5.code.queue-full" in n for n in j.notes)
    # given at once, the same refusal is the host's to try again
    w.rec.exchanges[0].delivered_at = 1 * MS
    assert broken(w.judge())["5.code.queue-full"] == ["!0L10,0,0"]
