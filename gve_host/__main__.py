"""`python -m gve_host PORT --job FILE`: drive one GVE unit through a job.

PORT is a serial device or pseudo-terminal path, or a pyserial URL (``socket://HOST:PORT``).
Exit status: 0 the job is done; 1 the unit refused a step or is not where the job says;
2 bad usage; 3 the unit was lost (no answer, restarted, out of step).
"""

from __future__ import annotations

import argparse
import platform
import sys
from importlib.metadata import PackageNotFoundError, version

import serial

from gve_host import job
from gve_host.bugs import BUGS, Bugs
from gve_host.driver import Driver, JobFailed
from gve_host.session import Session, UnitLost

EXAMPLES = """\
examples:
  python -m gve_host /dev/ttyUSB0 --job gve_host/jobs/square.job
  python -m gve_host socket://127.0.0.1:5114 --job gve_host/jobs/square-packets.job --checksums
  gve-conformance host --profile GVE84-100 -- python -m gve_host {port} --job J.job"""


def version_text() -> str:
    """The reference host drives a unit and runs no stepper core of its own."""
    try:
        ours = version("gve-conformance")
    except PackageNotFoundError:
        ours = "unknown (not installed)"
    return (f"gve_host {ours}\nC stepper core: none (a host program: it drives a unit)\n"
            f"Python {platform.python_version()} ({sys.implementation.name})")


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(prog="gve_host", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=EXAMPLES)
    ap.add_argument("--version", action="version", version=version_text(),
                    help="print the version and the Python, then exit")
    ap.add_argument("port", nargs="?", help="device path, pty path or pyserial URL")
    ap.add_argument("--job", help="the job file (see gve_host/jobs/)")
    ap.add_argument("--address", type=int, default=0, choices=range(8), metavar="0..7")
    ap.add_argument("--baud", type=int, default=115200)
    ap.add_argument("--checksums", action="store_true",
                    help="use checksum mode (spec 6; also `use checksums` in the job)")
    ap.add_argument("--packets", type=int, default=None, metavar="N",
                    help="send runs of C/B as packets of up to N members (spec 7; also "
                         "`use packets N` in the job)")
    ap.add_argument("--char-gap", type=float, default=0.0, metavar="MS",
                    help="send one byte at a time, pausing MS milliseconds after each")
    ap.add_argument("--timeout", type=float, default=0.25, metavar="S",
                    help="how long to wait for an answer before asking `@` (default 0.25)")
    ap.add_argument("--hold-limit", type=float, default=30.0, metavar="S",
                    help="how long an interrupt may hold the job (default 30)")
    ap.add_argument("--resend-repeatable", action="store_true",
                    help="after a lost or damaged answer to a setting or a read (V, A, SW, "
                         "PF...), send it again at once instead of asking `@` first (the "
                         "manual: most commands may be repeated)")
    ap.add_argument("--bug", action="append", default=[], metavar="NAME",
                    help="plant a deliberate host bug (see --list-bugs)")
    ap.add_argument("--list-bugs", action="store_true")
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.list_bugs:
        for name, what in BUGS.items():
            print(f"{name:26} {what}")
        return 0
    try:
        if not args.port or not args.job:
            raise ValueError("give a PORT and --job FILE")
        if (args.packets or 0) < 0 or args.char_gap < 0 or args.timeout <= 0:
            raise ValueError("--packets, --char-gap and --timeout take positive numbers")
        bugs = Bugs(args.bug)
        work = job.load(args.job)
        stop = serial.STOPBITS_TWO if bugs.on("two-stop-bits") else serial.STOPBITS_ONE
        port = serial.serial_for_url(args.port, baudrate=args.baud, bytesize=8,
                                     parity="N", stopbits=stop, timeout=args.timeout)
    except (ValueError, serial.SerialException) as err:
        print(f"gve_host: {err}", file=sys.stderr)
        return 2
    session = Session(port, args.address, timeout=args.timeout,
                      char_gap=args.char_gap / 1000, bugs=bugs,
                      resend_repeatable=args.resend_repeatable)
    packets = work.packets if args.packets is None else args.packets
    driver = Driver(session, checksums=args.checksums or work.checksums, packets=packets,
                    hold_limit=args.hold_limit)
    try:
        driver.run(work.steps)
    except JobFailed as err:
        print(f"gve_host: {err}", file=sys.stderr)
        return 1
    except UnitLost as err:
        print(f"gve_host: the unit is lost: {err}", file=sys.stderr)
        return 3
    finally:
        port.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
