/* The benchmark's reference: the pulse train of one vector computed by a bare loop,
 * without the core's queue, history, ghost or timeline. It plans the vector with the
 * core's planner and places every step and axis with the core's arithmetic, so it does
 * the same arithmetic the core does for that train, and nothing else. */
#include <stdint.h>

#include "_reference.h"
#include "_stepper_math.h"

int64_t st_reference_pulses(const int64_t *steps, int axes, int64_t t0, int64_t vc,
                            int64_t a, int64_t *times, uint8_t *masks, int64_t cap) {
    i64 n = 0;
    for (int i = 0; i < axes; i++) n = max64(n, (i64)abs128(steps[i]));
    if (n > cap) return n;
    seg_t segs[3];
    int nseg = plan(t0, 0, n, 0, vc, 0, a, segs);
    i64 before[ST_AXES] = {0};
    i64 k = 1;
    for (int i = 0; i < nseg; i++) {
        const seg_t *s = &segs[i];
        for (; k <= s->k0 + s->length; k++) {
            uint8_t mask = 0;
            for (int ax = 0; ax < axes; ax++) {
                i64 c = axis_count(k, steps[ax], n);
                if (c != before[ax])
                    mask |= (uint8_t)((1 << ax) | ((steps[ax] < 0) << (4 + ax)));
                before[ax] = c;
            }
            *times++ = seg_step_instant(s, k - s->k0);
            *masks++ = mask;
        }
    }
    return n;
}
