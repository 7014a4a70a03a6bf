"""The motion, measured (spec 10.2, 10.4, 10.7): the suite's own model of where the axes
must be at an instant, and the tolerance a position read from a target is judged with.

- ``tolerance.py``: the instant a frame was processed as a window of time, and the band
  of steps a reading may differ by (zero in virtual time).
- ``arith.py``, ``plan.py``, ``model.py``: the spec's motion model in exact integer
  arithmetic (docs/motion-model.md), written for the suite; never the emulator's code.
- ``probe.py``: sampling ``PF`` on a link and judging it against the model.
"""
