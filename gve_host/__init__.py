"""gve_host: a small, careful host for GVE units — the reference the host certification
(`gve-conformance host`) is tried on, and a worked example for host authors.

It reads a job (one command a line, `jobs/*.job`) and drives one unit through it:

- frames ``!<address><body>[,<checksum>]\\r`` (spec 3, 6), with checksum mode if asked;
- strictly one command at a time: send, wait for the answer (spec 2);
- runs of continuous vectors as packets ``*S`` … ``*E n`` if asked (spec 7);
- a full queue (answer 1) tried again a little later (spec 5, 10.1);
- the motion awaited with ``L0,0,0`` until it answers 0 (spec 10.1);
- an answer that is lost or damaged recovered as spec 8 says: ask ``@``; if the command
  arrived, ``>`` shows the answer it got; resend only what did not arrive;
- an interrupt (INTA in an answer) held until the input is released, then ``G`` (10.3);
- optionally one byte at a time with a pause after each, as a PLC's ``COM_SEND`` does.

Modules: ``job.py`` (the job file), ``wire.py`` (frames and answers), ``session.py`` (one
command and its answer, with recovery), ``driver.py`` (the job: vectors, packets, waits,
interrupts), ``bugs.py`` (deliberate host bugs for the certification's own tests).
"""
