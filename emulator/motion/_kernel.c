/* The benchmark's baseline: a plain exact kernel for the pulse train of one vector from
 * rest to rest, with none of the core's queue, history, ghost or timeline. Its vector is
 * planned once (the planner's segments), then one loop per segment takes the steps in
 * order: each axis's Bresenham remainder and the curve's integer recurrence for the
 * instants (walk_next), written out as they come. */
#include <stdint.h>

#include "_kernel.h"
#include "_stepper_math.h"

int64_t st_kernel_pulses(const int64_t *steps, int axes, int64_t t0, int64_t vc,
                            int64_t a, int64_t *times, uint8_t *masks, int64_t cap) {
    i64 n = 0;
    for (int i = 0; i < axes; i++) n = max64(n, (i64)abs128(steps[i]));
    if (n > cap) return n;
    if (n >= ((i64)1 << 61) || t0 < 0) return -1;
    seg_t segs[3];
    int nseg = plan(t0, 0, n, 0, vc, 0, a, segs);
    i64 two_n = 2 * n, inc[ST_AXES] = {0}, r[ST_AXES] = {0};
    uint8_t sign = 0;
    for (int i = 0; i < axes; i++) {
        inc[i] = 2 * (i64)abs128(steps[i]);
        r[i] = n;                                /* (2k|d| + n) mod 2n at k = 0 */
        if (steps[i] < 0) sign |= (uint8_t)(1 << (4 + i));
    }
    for (int i = 0; i < nseg; i++) {
        const seg_t *s = &segs[i];
        int fwd = s->kind == FWD;
        /* the curve steps this segment walks up, from its first instant's or its last's */
        i64 top = fwd ? s->length : s->total - s->m0 - 1;
        if (s->end >= NEVER || !walk_fits(s->v, s->a, top, fwd ? s->end - s->t0 : s->tdec))
            return -1;
        walk_t w;
        walk_start(&w, s->v, s->a, fwd ? 0 : s->total - s->m0 - s->length);
        i64 from = fwd ? s->t0 : s->t0 + s->tdec;
        for (i64 j = 0; j < s->length; j++) {
            uint8_t mask = 0;
            for (int ax = 0; ax < ST_AXES; ax++) {
                i64 x = r[ax] + inc[ax];
                int moved = x >= two_n;
                r[ax] = moved ? x - two_n : x;
                mask |= (uint8_t)(moved << ax);
            }
            masks[j] = mask | (sign & (uint8_t)(mask << 4));
            if (fwd) {
                times[j] = from + walk_next(&w);
            } else {
                times[s->length - 1 - j] = from - w.tau;
                if (j + 1 < s->length) walk_next(&w);
            }
        }
        times += s->length;
        masks += s->length;
    }
    return n;
}
