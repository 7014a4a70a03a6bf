"""Response frames (spec 4): code digit with the INTA bit, values, optional checksum."""

from __future__ import annotations

from emulator.protocol.checksum import checksum


def response(code: int, values: list[str] | tuple[str, ...], *, inta: bool, summed: bool,
             comma: bool = True, lower: bool = False) -> bytes:
    """The bytes of a response, CR included."""
    text = "%X" % (code | (8 if inta else 0))
    if values:
        text += "," + ",".join(values)
    body = text.encode("latin-1")
    if summed:
        body += b","
        digits = "%02x" if lower else "%02X"
        body += (digits % checksum(body, comma=comma)).encode()
    return body + b"\r"
