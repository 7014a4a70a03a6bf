"""A minimal co-simulator of a GVE84 at address 0, written from docs/cosim.md alone.

It speaks the whole protocol (tx, until, next, baud, quit; the rig's commands answered
`error:`, so the suite runs no rig case against it), takes the host's bytes at their
instants and answers when a frame's CR is complete, one byte time per answer byte. The
unit knows only a few commands (`?`, the checksum mode, modal values, status words,
position counters, H, G, D, N, K, R and the EEPROM): enough for the suite's known state
and the golden transcripts G1, G2, G4a, G4b, G4d, G4e, G4f and G9. An L moves the
counters at once (no motion model); a frame it cannot read is refused with 4.

    python examples/cosim_minimal.py      # then type: tx 21303F0D 10000000
"""

import sys

CR = 0x0D
TWO_LETTERS = ("%+", "%-", "SW", "SR", "EW", "ER", "PF", "NX", "NY", "NZ", "O0", "XM", "VL", "VN")
MODAL = ("A", "V", "B", "T", "$", "O0", "XM", "VL", "VN", "K", "R")   # taken, not kept


class Unit:
    def __init__(self):
        self.frame, self.checksums, self.inta = b"", False, False
        self.status, self.counters, self.eeprom = [0] * 7, [0, 0, 0], [0xFF] * 256

    def take(self, value):
        """One byte from the host: the answer's bytes when it completes a frame."""
        self.frame = b"!" if value == ord("!") else self.frame + bytes([value])
        if value != CR or not self.frame.startswith(b"!0"):
            return b""
        frame, self.frame = self.frame, b""
        if self.checksums and (frame[-4:-3] != b"," or
                               frame[-3:-1].upper() != b"%02X" % (sum(frame[:-3]) & 0xFF)):
            return self.answer(4)                 # a wrong or missing checksum
        try:
            return self.answer(*self.execute(frame[2:-4 if self.checksums else -1].decode()))
        except (ValueError, IndexError, UnicodeDecodeError):   # fields it cannot read
            return self.answer(4)

    def execute(self, body):
        """(error code, values) for one command."""
        name = next((n for n in TWO_LETTERS if body.startswith(n)), body[:1])
        args = body[len(name):].split(",") if body[len(name):] else []
        if name == "?":
            return 0, ["IP84 v3 27.1.2010"]
        if name in ("%+", "%-"):
            self.checksums = name == "%+"
        elif name == "SW":
            if not 0 <= int(args[0]) <= 6:
                return 5, []
            self.status[int(args[0])] = int(args[1], 16)
        elif name == "SR":
            return 0, ["%02X" % self.status[int(args[0])]]
        elif name in ("NX", "NY", "NZ"):
            self.counters["XYZ".index(name[1])] = int(args[0])
        elif name == "N":
            self.counters = [0, 0, 0]
        elif name == "PF":
            return 0, [str(c) for c in self.counters]
        elif name == "L":
            self.counters = [c + int(a) for c, a in zip(self.counters, args, strict=False)]
        elif name in ("H", "G", "D"):
            self.inta = name == "H"
        elif name == "EW":
            self.eeprom[int(args[0], 16)] = int(args[1], 16)
        elif name == "ER":
            return 0, ["%02X" % self.eeprom[int(args[0], 16)]]
        elif name not in MODAL:
            return 3, []                          # unknown command
        return 0, []

    def answer(self, code, values=()):
        text = ",".join(["%X" % (code | (8 if self.inta else 0)), *values])
        if self.checksums:
            text += ",%02X" % (sum(text.encode() + b",") & 0xFF)
        return text.encode("latin-1") + b"\r"


def main():
    unit, now, byte_ns = Unit(), 0, round(1e10 / 115200)
    to_unit, to_host = [], []            # (instant the byte is complete, byte), in order

    def run(limit, stop_at_cr):
        """Advance to ``limit`` (or to the first CR to the host): the bytes delivered."""
        nonlocal now
        sent = []
        while True:
            t = min([limit + 1] + [q[0][0] for q in (to_unit, to_host) if q])
            if t > limit:
                now = limit
                return sent
            if to_host and to_host[0][0] == t:
                sent.append(to_host.pop(0))
                if stop_at_cr and sent[-1][1] == CR:
                    now = t
                    return sent
                continue
            _, value = to_unit.pop(0)
            start = max([t] + [at for at, _ in to_host[-1:]])
            to_host.extend((start + (i + 1) * byte_ns, b)
                           for i, b in enumerate(unit.take(value)))

    print("cosim 1", flush=True)
    for line in sys.stdin:
        words = line.split()
        if not words:
            continue
        try:
            if words[0] == "tx":
                data = bytes.fromhex(words[1])
                end = now + len(data) * byte_ns
                until = instant(words[2], end) if len(words) == 3 else None
                to_unit.extend((now + (i + 1) * byte_ns, b) for i, b in enumerate(data))
                sent = run(end, False)
                if until is not None and all(b != CR for _, b in sent):
                    sent += run(until, True)
                out = [f"rx {t} {b:02X}" for t, b in sent] + [f"now {now}"]
            elif words[0] == "until":
                out = [f"rx {t} {b:02X}" for t, b in run(instant(words[1], now), True)]
                out.append(f"now {now}")
            elif words[0] == "next":
                out = [f"next {to_host[0][0]}" if to_host else "next none"]
            elif words[0] == "baud":
                byte_ns, out = round(1e10 / instant(words[1], 1)), ["ok"]
            elif words[0] in ("quit", "exit"):
                return
            else:
                out = [f"error: {words[0]} is not in this simulator"]
        except (ValueError, IndexError) as err:      # a bad number, a missing word
            out = [f"error: {err}"]
        print("\n".join(out), flush=True)


def instant(word, least):
    """A number of the protocol: ASCII digits, and not below ``least``."""
    if not (word.isascii() and word.isdigit()) or int(word) < least:
        raise ValueError(f"{word!r} is not a whole number from {least} on")
    return int(word)

if __name__ == "__main__":
    main()
