"""The technician: the terminal and the question before the first move (console.py),
the hands that do what a rig's would (hands.py, worded by hand_steps.toml), and whether
a run may move something physical (consent.py)."""
