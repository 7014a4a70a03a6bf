/* The benchmark's baseline (bench/bench_stepper.py): a plain exact kernel for one
 * vector's pulse train, with the arithmetic of _stepper_math.h. */
#ifndef GVE_KERNEL_H
#define GVE_KERNEL_H
#include <stdint.h>

/* The pulse train of a vector of steps[0..axes) planned from rest to rest from t0 at
 * cruise rate vc and acceleration a: its instants and masks as st_pulses gives them.
 * Returns its length (the dominant |steps|), written when at most cap; -1 for a vector
 * beyond the kernel's range (walk_fits), which it does not compute. */
int64_t st_kernel_pulses(const int64_t *steps, int axes, int64_t t0, int64_t vc,
                         int64_t a, int64_t *times, uint8_t *masks, int64_t cap);
#endif
