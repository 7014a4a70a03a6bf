"""The silent port: nothing to read, ever; every answer taken whole."""

import select

from conformance.host.ports.silent import SilentPort


def test_nothing_to_read_and_every_answer_taken():
    port = SilentPort()
    try:
        assert select.select([port.fileno()], [], [], 0)[0] == []
        assert port.read() == b""
        assert port.write(b"0\r0,12\r") == 7
    finally:
        port.close()
