"""A host that stops half-way and says it finished: it sends the first vector of the
shell host's job (tests/conformance/host/shell_host.sh: L500,0,0 L-500,500,0 L0,0,0),
then exits 0. Usage: python half_host.py PORT"""

import sys

import serial


def ask(port: serial.Serial, body: str) -> bytes:
    port.write(f"!0{body}\r".encode())
    return port.read_until(b"\r")


def main() -> int:
    with serial.serial_for_url(sys.argv[1], 115200, timeout=1) as port:
        if ask(port, "V5000") != b"0\r":
            return 1
        while (answer := ask(port, "L500,0,0")) == b"1\r":
            pass
        return 0 if answer == b"0\r" else 1        # ... and the rest of the job never


if __name__ == "__main__":
    sys.exit(main())
