"""The pytest plugin (entry point ``gve_conformance``: plugin.py) and the signals of a
pytest run (stop.py)."""
