"""Time and ways in: clocks, the serial line, pyserial URLs, pty and TCP servers."""
