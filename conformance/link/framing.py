"""The suite's framing, as the link and its readers import it: the wire's own model lives
in conformance/protocol (wire.py, framer.py); this module names it for the link."""

from __future__ import annotations

from conformance.protocol.framer import HostFrame, HostFramer
from conformance.protocol.wire import (
    BANG,
    CR,
    Response,
    UnitDataError,
    Values,
    byte_sum,
    frame,
    parse_response,
    readable,
    shown_bytes,
)

__all__ = ["BANG", "CR", "HostFrame", "HostFramer", "Response", "UnitDataError", "Values",
           "byte_sum", "frame", "parse_response", "readable", "shown_bytes"]
