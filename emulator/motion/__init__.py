"""The stepper core: the motion model of spec 10.2 behind the interface of interface.py.

``emulator.motion.factory.create`` gives a core (the C core when it is built, else the
Python twin); ``interface.py`` is the contract both keep; ``docs/motion-model.md`` is
their exact arithmetic.
"""
