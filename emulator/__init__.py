"""The reference emulator of GVE54, GVE84 and GVE114 serial interpolators.

Importing it registers the ``gve://`` URL scheme with pyserial
(``serial.serial_for_url("gve://?model=GVE84-100&address=0")``).
"""

import serial

if "emulator.link" not in serial.protocol_handler_packages:
    serial.protocol_handler_packages.append("emulator.link")
