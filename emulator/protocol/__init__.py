"""The unit: the serial protocol of spec sections 3-12 on top of a stepper core."""
