"""Time and ways in: clocks, the serial line with its units, the gve:// URL, servers."""
