"""Frame-level helpers of the GVE84 serial protocol (manual 12.3, 12.6)."""
import re

CR = 0x0D
INT_MAX = 2147483647

_DEC = re.compile(r"^[+-]?[0-9]+$")
_HEX = re.compile(r"^[0-9A-Fa-f]+$")


class CmdError(Exception):
    """Raised by a command handler: .code is the 3-bit error code of 12.6."""

    def __init__(self, code):
        super().__init__(code)
        self.code = code


def checksum(text):
    """12.3.2: sum of the ASCII values of all characters, modulo 256."""
    return sum(text.encode("latin-1")) & 0xFF


def with_checksum(text):
    """'0' -> '0,5C' (the sum includes the comma placed before it)."""
    t = text + ","
    return "%s%02X" % (t, checksum(t))


def parse_dec(s, lo=-INT_MAX, hi=INT_MAX):
    if not _DEC.match(s or ""):
        raise CmdError(4)
    digits = s.lstrip("+-")
    if len(digits) > 12:
        raise CmdError(5)
    v = int(s)
    if v < lo or v > hi:
        raise CmdError(5)
    return v


def parse_hex(s, lo=0, hi=0xFF):
    if not s or not _HEX.match(s):
        raise CmdError(4)
    if len(s) > 8:
        raise CmdError(5)
    v = int(s, 16)
    if v < lo or v > hi:
        raise CmdError(5)
    return v


def split_params(s, n):
    """Exactly n comma-separated parameters, else syntax error."""
    parts = s.split(",") if s != "" else []
    if len(parts) != n:
        raise CmdError(4)
    return parts
