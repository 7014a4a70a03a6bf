/* The stepper's exact arithmetic (arith.py) and segments (segment.py), and the same
 * instants and counts taken one step after the other for pulse trains; shared by the
 * C core (_stepper.c) and the benchmark's plain kernel (_kernel.c). docs/motion-model.md
 * is the spec.
 *
 * Every quantity is an integer; products are computed in 128 bits so the results equal
 * the Python twin's (unbounded integers) bit for bit. The only floating point is the
 * first guess of an integer square root, which is then corrected exactly.
 */
#ifndef GVE_STEPPER_MATH_H
#define GVE_STEPPER_MATH_H
#include <math.h>
#include <stdint.h>

#include "_stepper.h"

typedef __int128 i128;
typedef unsigned __int128 u128;
typedef int64_t i64;

#define SECOND 1000000000LL
#define NEVER ((i64)((uint64_t)1 << 61))
/* the kinds of segment */
#define FWD 0
#define REV 1

/* ---- arithmetic (arith.py) ------------------------------------------------------ */

static inline i64 sat(i128 t) { return t < NEVER ? (i64)t : NEVER; }
static inline i128 max128(i128 a, i128 b) { return a > b ? a : b; }
static inline i128 min128(i128 a, i128 b) { return a < b ? a : b; }
static inline i64 max64(i64 a, i64 b) { return a > b ? a : b; }
static inline i64 min64(i64 a, i64 b) { return a < b ? a : b; }
static inline i128 abs128(i128 a) { return a < 0 ? -a : a; }

/* floor division (b > 0), as Python's // */
static inline i128 fdiv(i128 a, i128 b) {
    i128 q = a / b;
    if ((a % b != 0) && (a < 0)) q -= 1;
    return q;
}

static inline u128 isqrt_u128(u128 n) {
    if (n < 2) return n;
    u128 x = (u128)sqrtl((long double)n);
    const u128 limit = ((u128)1 << 64) - 1;   /* x*x must not overflow */
    if (x > limit) x = limit;
    while (x * x > n) x--;
    while (x < limit && (x + 1) * (x + 1) <= n) x++;
    return x;
}

static inline i128 isqrt(i128 n) { return n <= 0 ? 0 : (i128)isqrt_u128((u128)n); }

static inline i128 acc_count(i64 v, i64 a, i128 tau) {
    i128 num = (i128)2 * SECOND * v * tau + (i128)a * tau * tau;
    return fdiv(num, (i128)2 * SECOND * SECOND);
}

static inline i64 acc_time(i64 v, i64 a, i64 m) {
    if (m <= 0) return 0;
    i128 target = (i128)2 * SECOND * SECOND * m;
    i128 b = (i128)2 * SECOND * v;
    i128 tau;
    if (a == 0) {
        tau = -fdiv(-target, b);
    } else {
        u128 disc = (u128)(b * b) + (u128)4 * (u128)a * (u128)target;
        tau = fdiv((i128)isqrt_u128(disc) - b, (i128)2 * a);
        while (tau > 0 && b * (tau - 1) + (i128)a * (tau - 1) * (tau - 1) >= target) tau--;
        while (b * tau + (i128)a * tau * tau < target) tau++;
    }
    return sat(tau);
}

static inline i64 axis_count(i64 k, i64 d, i64 n) {
    if (d == 0 || n == 0) return 0;
    i128 c = fdiv((i128)2 * k * abs128(d) + n, (i128)2 * n);
    return (i64)(d > 0 ? c : -c);
}

static inline i64 first_step_reaching(i64 c, i64 d, i64 n) {
    i128 ad = abs128(d);
    i128 k = -fdiv(-((i128)2 * n * c - n), 2 * ad);
    return (i64)max128(0, k);
}

/* ---- segments (segment.py) -------------------------------------------------------- */

static inline seg_t forward(i64 t0, i64 v, i64 a, i64 length, i64 k0) {
    seg_t s = {FWD, t0, v, a, length, 0, length, k0, 0, t0, 0};
    s.end = sat((i128)t0 + acc_time(v, a, length));
    return s;
}

static inline seg_t reverse(i64 t0, i64 v, i64 a, i64 total, i64 m0, i64 length, i64 k0) {
    seg_t s = {REV, t0, v, a, total, m0, length, k0, 0, 0, 0};
    s.tdec = acc_time(v, a, total);
    s.start = sat((i128)t0 + s.tdec - acc_time(v, a, total - m0));
    s.end = sat((i128)t0 + s.tdec - acc_time(v, a, total - m0 - length));
    return s;
}

static inline i64 seg_count(const seg_t *s, i64 t) {
    if (t < s->start) return 0;
    if (t >= s->end) return s->length;
    if (s->kind == FWD) return (i64)min128(s->length, acc_count(s->v, s->a, (i128)t - s->t0));
    i128 x = (i128)s->tdec - ((i128)t - s->t0);
    i128 curve = s->total - (acc_count(s->v, s->a, x - 1) + 1);
    return (i64)min128(max128(curve - s->m0, 0), s->length);
}

static inline i64 seg_step_instant(const seg_t *s, i64 j) {
    if (s->kind == FWD) return sat((i128)s->t0 + acc_time(s->v, s->a, j));
    return sat((i128)s->t0 + s->tdec - acc_time(s->v, s->a, s->total - s->m0 - j));
}

static inline i64 seg_rate(const seg_t *s, i64 t) {
    i128 tau = (i128)min64(max64(t, s->start), s->end) - s->t0;
    if (s->kind == FWD) return (i64)(s->v + fdiv((i128)s->a * tau, SECOND));
    return (i64)(s->v + fdiv((i128)s->a * max128((i128)s->tdec - tau, 0), SECOND));
}

/* ---- pulse trains: the same instants and counts, one step after the other ---------- */

/* A walk along a curve's step instants tau = acc_time(v, a, m) for m, m + 1, m + 2, ...:
 * each found from the one before by exact integer updates, with no division and no
 * square root. With P(tau) = 2e9 v tau + a tau^2 the walk keeps r = P(tau) - 2e18 m
 * (>= 0, and tau is the smallest such: r < P(tau) - P(tau - 1) = s - a) and
 * s = 2e9 v + 2 a tau (P(tau + 1) - P(tau) = s + a). A step guesses tau's increase from
 * the last (and, on a ramp, from the change before it), then corrects it nanosecond by
 * nanosecond on the defining inequality; a guess further off than WALK_FIX (the first
 * steps of a ramp from rest) takes acc_time itself. The results are acc_time's. */
typedef struct {
    i64 v, a, m, tau, d1, d2, r, s;
} walk_t;

#define WALK_FIX 8
/* s stays below this on a walk that fits (walk_fits), so no update overflows 64 bits */
#define WALK_SLOPE ((i64)1 << 61)

/* Whether a walk up to step m_max, whose instants stay at most tau_max, is exact in 64
 * bits: acc_time is exact there (its discriminant b^2 + 8e18 a m within 128 bits), no
 * instant saturates and the slope s stays below WALK_SLOPE; and v + a > 0. */
static inline int walk_fits(i64 v, i64 a, i64 m_max, i64 tau_max) {
    return v >= 0 && a >= 0 && (v > 0 || a > 0) && v < ((i64)1 << 32) && a < ((i64)1 << 40)
        && m_max >= 0 && m_max < ((i64)1 << 62) && (u128)a * (u128)m_max < ((u128)1 << 64)
        && tau_max >= 0 && tau_max < NEVER
        && (i128)2 * SECOND * v + (i128)2 * a * tau_max < WALK_SLOPE;
}

static inline void walk_at(walk_t *w, i64 m) {
    i64 tau = acc_time(w->v, w->a, m);
    w->m = m;
    w->tau = tau;
    w->r = (i64)((i128)2 * SECOND * w->v * tau + (i128)w->a * tau * tau
                 - (i128)2 * SECOND * SECOND * m);
    w->s = (i64)((i128)2 * SECOND * w->v + (i128)2 * w->a * tau);
}

/* a walk standing on step m of the curve (v, a) */
static inline void walk_start(walk_t *w, i64 v, i64 a, i64 m) {
    w->v = v;
    w->a = a;
    w->d1 = w->d2 = 0;
    walk_at(w, m);
}

/* the instant of the walk's next step */
static inline i64 walk_next(walk_t *w) {
    const i64 a = w->a, tau0 = w->tau;
    i64 d = w->d1;
    if (a) {                               /* on a ramp the increase drifts */
        i64 dd = d - w->d2;
        if (dd > 1 || dd < -1) d += dd;
        if (d < 0) d = 0;
    }
    /* r and s at tau0 + d: P(tau0 + d) - P(tau0) = d (s + a d) */
    i64 ad, slope, rise, r, s;
    if (__builtin_mul_overflow(a, d, &ad) || __builtin_add_overflow(w->s, ad, &slope)
            || __builtin_mul_overflow(slope, d, &rise)
            || __builtin_add_overflow(w->r - 2 * SECOND * SECOND, rise, &r)
            || __builtin_add_overflow(slope, ad, &s) || s >= WALK_SLOPE)
        goto exact;
    i64 tau = tau0 + d;
    int budget = WALK_FIX;
    while (r < 0) {
        if (!budget--) goto exact;
        r += s + a;
        s += 2 * a;
        tau++;
    }
    while (tau > 0 && r >= s - a) {
        if (!budget--) goto exact;
        r -= s - a;
        s -= 2 * a;
        tau--;
    }
    w->r = r;
    w->s = s;
    w->tau = tau;
    w->m++;
    w->d2 = w->d1;
    w->d1 = tau - tau0;
    return tau;
exact:
    walk_at(w, w->m + 1);
    w->d2 = w->d1;
    w->d1 = w->tau - tau0;
    return w->tau;
}

/* The instants of a segment's steps j = first..last (1 <= first, last <= length) in
 * order, into times[0 .. last - first]: seg_step_instant of each. A REV segment's curve
 * runs backwards in time, so its walk goes up the curve and fills times from the end. */
static inline void seg_instants(const seg_t *s, i64 first, i64 last, i64 *times) {
    i64 n = last - first + 1;
    if (n <= 0) return;
    walk_t w;
    if (s->kind == FWD) {
        if (s->t0 >= 0 && s->end < NEVER && walk_fits(s->v, s->a, last, s->end - s->t0)) {
            walk_start(&w, s->v, s->a, first);
            times[0] = s->t0 + w.tau;
            for (i64 i = 1; i < n; i++) times[i] = s->t0 + walk_next(&w);
            return;
        }
    } else {
        i64 top = s->total - s->m0 - first;       /* the curve step of j = first */
        if (s->t0 >= 0 && s->end < NEVER && walk_fits(s->v, s->a, top, s->tdec)) {
            i64 from = s->t0 + s->tdec;
            walk_start(&w, s->v, s->a, top - (n - 1));
            times[n - 1] = from - w.tau;
            for (i64 i = n - 2; i >= 0; i--) times[i] = from - walk_next(&w);
            return;
        }
    }
    /* beyond the walk's range: step by step, as defined */
    for (i64 j = first; j <= last; j++) *times++ = seg_step_instant(s, j);
}

/* Bresenham over a vector's axes: for each dominant step k = first..last, the axes whose
 * count axis_count(k, d, n) differs from the step before (bit i: axis i), into
 * masks[0 .. last - first]. Each axis keeps (2k|d| + n) mod 2n, which passes 2n exactly
 * when its count moves (|d| <= n: at most once a step). */
static inline void axis_steps(const i64 *steps, i64 n, i64 first, i64 last, uint8_t *masks) {
    i64 count = last - first + 1;
    if (count <= 0) return;
    if (n <= 0 || n >= ((i64)1 << 61)) {
        for (i64 k = first; k <= last; k++) {
            uint8_t mask = 0;
            for (int a = 0; a < ST_AXES; a++)
                if (axis_count(k, steps[a], n) != axis_count(k - 1, steps[a], n))
                    mask |= (uint8_t)(1 << a);
            *masks++ = mask;
        }
        return;
    }
    const i64 two_n = 2 * n;
    i64 r[ST_AXES], inc[ST_AXES];
    for (int a = 0; a < ST_AXES; a++) {
        inc[a] = 2 * (i64)abs128(steps[a]);
        r[a] = (i64)(((i128)2 * (first - 1) * abs128(steps[a]) + n) % two_n);
    }
    for (i64 i = 0; i < count; i++) {
        uint8_t mask = 0;
        for (int a = 0; a < ST_AXES; a++) {
            i64 x = r[a] + inc[a];
            int moved = x >= two_n;
            r[a] = moved ? x - two_n : x;
            mask |= (uint8_t)(moved << a);
        }
        masks[i] = mask;
    }
}

typedef struct { int kind; i128 v, acc, length; } piece_spec;

static inline int plan(i64 t, i64 k0, i64 r, i64 vin, i64 vc, i64 vx, i64 a, seg_t *out) {
    if (r <= 0) return 0;
    i128 two_a = (i128)2 * a, R = r, VIN = vin, VC = vc, VX = vx;
    i128 down = fdiv(VC * VC - VX * VX, two_a);
    piece_spec p[3];
    int np = 0;
    if (vin <= vc) {
        i128 up = fdiv(VC * VC - VIN * VIN, two_a);
        if (up + down <= R) {
            p[0] = (piece_spec){FWD, VIN, a, up};
            p[1] = (piece_spec){FWD, VC, 0, R - up - down};
            p[2] = (piece_spec){REV, VX, a, down};
            np = 3;
        } else if (VIN * VIN + two_a * R <= VX * VX) {
            p[0] = (piece_spec){FWD, VIN, a, R};
            np = 1;
        } else if (VX * VX + two_a * R <= VIN * VIN) {
            p[0] = (piece_spec){REV, isqrt(VIN * VIN - two_a * R), a, R};
            np = 1;
        } else {
            i128 peak2 = fdiv(two_a * R + VIN * VIN + VX * VX, 2);
            up = min128(max128(fdiv(peak2 - VIN * VIN, two_a), 0), R);
            p[0] = (piece_spec){FWD, VIN, a, up};
            p[1] = (piece_spec){REV, VX, a, R - up};
            np = 2;
        }
    } else {
        i128 over = fdiv(VIN * VIN - VC * VC, two_a);
        if (over + down <= R) {
            p[0] = (piece_spec){REV, VC, a, over};
            p[1] = (piece_spec){FWD, VC, 0, R - over - down};
            p[2] = (piece_spec){REV, VX, a, down};
            np = 3;
        } else {
            p[0] = (piece_spec){REV, max128(VX, isqrt(max128(0, VIN * VIN - two_a * R))), a, R};
            np = 1;
        }
    }
    int n = 0;
    for (int i = 0; i < np; i++) {
        if (p[i].length <= 0) continue;
        seg_t s = p[i].kind == FWD
            ? forward(t, (i64)p[i].v, (i64)p[i].acc, (i64)p[i].length, k0)
            : reverse(t, (i64)p[i].v, (i64)p[i].acc, (i64)p[i].length, 0, (i64)p[i].length, k0);
        out[n++] = s;
        t = s.end;
        k0 += (i64)p[i].length;
    }
    return n;
}
#endif
