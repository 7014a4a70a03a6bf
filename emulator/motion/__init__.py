"""The stepper core: the motion model of spec 10.2 behind the interface of interface.py."""
