"""Run every benchmark: `python -m bench`."""

from bench import (
    bench_cosim,
    bench_diff,
    bench_emulator,
    bench_host,
    bench_line,
    bench_stepper,
)

if __name__ == "__main__":
    bench_emulator.main()
    print()
    bench_stepper.main([])
    print()
    bench_host.main([])
    print()
    bench_diff.main([])
    print()
    bench_cosim.main([])
    print()
    bench_line.main([])
