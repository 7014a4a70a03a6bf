"""The case catalogue, one module per spec section (as h2spec files its cases): importing
this package registers every case."""

from conformance.cases import (  # noqa: F401
    s01_units,
    s02_link,
    s02_rate,
    s03_frame,
    s04_response,
    s05_errors,
    s06_checksums,
    s07_packets,
    s08_index,
    s09_reset,
    s10_1_queue,
    s10_2_motion,
    s10_3_status,
    s10_4_halt_go_delete,
    s10_5_keep_restore,
    s10_6_eeprom,
    s10_7_motor_mode,
    s10_commands,
    s11_golden,
    s12_spindle,
)
from conformance.machines import register as _machines  # noqa: F401  (machine cases)
