"""The suite's own model of the wire, below every other room of the suite (and apart from
the emulator's: the two share only ``fixtures``).

    commands.toml, catalogue.py   every command of spec 10 and what the suite relies on
                                  of it, written once
    parse.py     a frame's body read as the catalogue's command and fields (lenient: how
                 every reader classes a frame; strict: as spec 3 writes it)
    framer.py    a host's byte stream cut into frames as a unit cuts it
    wire.py      frames built, checksums, answers read (``Response``)
    view.py      one view of a unit from the wire, folded one exchange at a time: its
                 checksum mode, open packet, index, settings as written (the link feeds
                 it; the guard and the rest read it)
"""
