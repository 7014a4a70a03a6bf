"""Text from a unit made safe for the reports: whatever bytes a (hostile or broken) unit
sent, the HTML page has no raw control character or unescaped markup and the JUnit file
stays well-formed XML 1.0."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from html import escape

# XML 1.0 allows TAB, LF, CR and the characters from U+0020 on, less the surrogates and
# U+FFFE/U+FFFF; C1 controls and DEL are legal but invisible, so they are shown too
_UNSAFE = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")


def _shown(m: re.Match) -> str:
    code = ord(m.group(0))
    return f"\\x{code:02X}" if code < 0x100 else f"\\u{code:04X}"


def clean(text: object) -> str:
    """``text`` with every character XML and HTML cannot carry shown as ``\\xNN``."""
    return _UNSAFE.sub(_shown, str(text))


def html_text(text: object) -> str:
    """Cleaned and escaped for HTML element content and quoted attribute values."""
    return escape(clean(text), quote=True)


def rule_html(text: object) -> str:
    """A rule's sentence for HTML: escaped as :func:`html_text`, its Markdown code spans
    (the spec writes commands as `` `H` ``) and bold set as HTML, no markup shown."""
    escaped = html_text(text)
    escaped = re.sub(r"`([^`]+)`", r"<code>\1</code>", escaped)
    return re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", escaped)


def element(parent: ET.Element, tag: str, text: str | None = None, **attrs: object
            ) -> ET.Element:
    """An XML element under ``parent``, its text and attributes made clean."""
    el = ET.SubElement(parent, tag, {k: clean(v) for k, v in attrs.items()})
    if text is not None:
        el.text = clean(text)
    return el
