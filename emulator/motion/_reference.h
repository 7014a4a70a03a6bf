/* The benchmark's reference (bench/bench_stepper.py): a bare loop over one vector's
 * steps, with the C core's own arithmetic (_stepper_math.h). */
#ifndef GVE_REFERENCE_H
#define GVE_REFERENCE_H
#include <stdint.h>

/* The pulse train of a vector of steps[0..axes) planned from rest to rest from t0 at
 * cruise rate vc and acceleration a: its instants and masks as st_pulses gives them.
 * Returns its length (the dominant |steps|), written when at most cap. */
int64_t st_reference_pulses(const int64_t *steps, int axes, int64_t t0, int64_t vc,
                            int64_t a, int64_t *times, uint8_t *masks, int64_t cap);
#endif
