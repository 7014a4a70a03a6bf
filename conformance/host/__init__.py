"""The host role (spec 2, 3, 6, 7, 8, 10.1): the suite plays GVE units to a host program
and judges the host's traffic on the wire, under the faults a real line and unit bring.

    ports/          where the host meets the relay (pty, TCP, serial device)
    units.py        the emulated units behind the relay (gve://, its rig and its clock)
    frame_rules.py  one frame judged against spec 3 and 10 (the command catalogue's
                    parameters; the host's bytes are framed by conformance/protocol/framer.py)
    relay.py        host <-> units, answers paired with frames, faults applied: only what
                    the line needs while it runs
    booking.py      the frames read and the units' views booked in the relay's order, when
                    a fault or the end of the run asks
    line_faults.py  lost, damaged, late and noisy answers, lost and cut frames, a full
                    queue, an interrupt, a restart
    recording.py, unitview.py   what was seen both ways; what the units executed (the
                    checksum mode and open packet read from conformance/protocol/view.py)
    checks.py       the host rules judged on the wire (WIRE_CHECKS: rule ID -> check)
    scenarios.py, oracle.py     the scenarios; the executed motion against the clean run
                    (oracle.HOST_CHECKS: every host rule -> the check that judges it)
    final_state.py  where the motion ended, asked over the wire after the host left
    certify.py      a whole certification, launched or attended
"""
