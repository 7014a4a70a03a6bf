"""Text that any report format can carry: characters XML 1.0 forbids (NUL, most control
characters, lone surrogates) and raw control characters in HTML are written as ``\\xHH``
(``\\uHHHH``), so unit bytes can never make a report malformed (issue 8 item 7)."""

from __future__ import annotations

import re

_FORBIDDEN = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")


def clean(text: str) -> str:
    return _FORBIDDEN.sub(lambda m: f"\\x{ord(m.group()):02X}" if ord(m.group()) < 0x100
                          else f"\\u{ord(m.group()):04X}", text)
