/* The C stepper core: a faithful port of python_twin.py (its arithmetic and segments,
 * arith.py and segment.py, are in _stepper_math.h). docs/motion-model.md is the spec.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "_stepper.h"
#include "_stepper_math.h"

#define HISTORY 65536
/* deviations (interface.py Deviation) */
#define DEV_ZERO_LENGTH_JUNCTION 1
#define DEV_CONTINUOUS_DWELL 2
#define DEV_HALT_SHORT 4
#define DEV_JUNCTION_STOPS 8
#define DEV_HALT_DEAD 16
#define DEV_GO_AT_SPEED 32
#define DEV_NEXT_BRAKE 64
#define DEV_JUNCTION_UNBRAKED 128
#define DEV_REVERSAL_STOPS 256

/* ---- the exported arithmetic (tests, tools) ------------------------------------------ */

i64 st_acc_time(i64 v, i64 a, i64 m) { return acc_time(v, a, m); }

/* The count: exact for any tau >= 0, saturating at NEVER where the count leaves int64
 * (the core itself only counts within a segment's duration). */
i64 st_acc_count(i64 v, i64 a, i64 tau) {
    if (tau <= 0) return tau == 0 ? 0 : (i64)acc_count(v, a, tau);
    const u128 top = ~(u128)0;
    u128 lin = (u128)2 * SECOND * (u128)v * (u128)tau;     /* < 2^117 */
    u128 at = (u128)a * (u128)tau;                         /* < 2^92 */
    if (at != 0 && at > (top - lin) / (u128)tau) return NEVER;
    u128 q = (lin + at * (u128)tau) / ((u128)2 * SECOND * SECOND);
    return q < (u128)NEVER ? (i64)q : NEVER;
}

int64_t st_walk(int64_t v, int64_t a, int64_t m, int64_t count, int64_t *out) {
    if (count <= 0 || m < 0 || m > NEVER - count) return -1;
    i64 tau_max = acc_time(v, a, m + count - 1);
    if (!walk_fits(v, a, m + count - 1, tau_max)) return -1;
    walk_t w;
    walk_start(&w, v, a, m);
    out[0] = w.tau;
    for (i64 i = 1; i < count; i++) out[i] = walk_next(&w);
    return count;
}

uint64_t st_isqrt_u128(uint64_t hi, uint64_t lo) {
    return (uint64_t)isqrt_u128(((u128)hi << 64) | lo);
}

/* ---- the core (python_twin.py) ---------------------------------------------------- */

typedef struct {
    st_vector vec;
    i64 n, done;
    int has_plan, nseg;       /* has_plan = 0: Python's plan None */
    seg_t plan[3];
    i64 end, exit_rate, decision;
    int final;
} entry_t;

typedef struct {
    i64 base[ST_AXES], steps[ST_AXES];
    i64 n, k_from, k_to;
    int nseg;
    seg_t plan[3];
} piece_t;

struct stepper {
    int axes;
    i64 max_rate, now, rest, stop_end, xm;
    int halted;
    int after_c;              /* the last stop ended a C of non-zero length, no more */
    int dev;                  /* deviations */
    i64 base[ST_AXES];
    i64 offset[ST_AXES];      /* physical position minus counter */
    i64 lo[ST_AXES], hi[ST_AXES];   /* the physical extremes visited so far */
    entry_t *q;
    size_t qhead, qlen, qcap;
    piece_t *hist;            /* ring buffer of executed pieces */
    size_t hhead, hlen, hcap;
    int keep_history;
};

static entry_t *head(stepper *m) { return &m->q[m->qhead]; }

/* record a point the axes have been at (counter units) in the excursion */
static void visit(stepper *m, const i64 *counters) {
    for (int i = 0; i < m->axes; i++) {
        i64 x = counters[i] + m->offset[i];
        if (x < m->lo[i]) m->lo[i] = x;
        else if (x > m->hi[i]) m->hi[i] = x;
    }
}
static entry_t *qat(stepper *m, size_t i) { return &m->q[m->qhead + i]; }

stepper *st_new(int axes, int64_t max_rate) {
    stepper *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    m->axes = axes;
    m->max_rate = max_rate;
    m->xm = 100;
    m->keep_history = 1;
    return m;
}

void st_set_deviations(stepper *m, int flags) { m->dev = flags; }

void st_free(stepper *m) {
    if (!m) return;
    free(m->q);
    free(m->hist);
    free(m);
}

static stepper *ghost(const stepper *m) {
    stepper *g = malloc(sizeof *g);
    if (!g) return NULL;
    *g = *m;
    g->q = NULL;
    g->qhead = 0;
    g->qcap = m->qlen ? m->qlen : 1;
    g->q = malloc(g->qcap * sizeof(entry_t));
    if (!g->q) { free(g); return NULL; }
    if (m->qlen) memcpy(g->q, m->q + m->qhead, m->qlen * sizeof(entry_t));
    g->hist = NULL;
    g->hhead = g->hlen = g->hcap = 0;
    g->keep_history = 1;
    return g;
}

static i64 vec_len(const st_vector *v, int axes) {
    i64 n = 0;
    for (int i = 0; i < axes; i++) n = max64(n, (i64)abs128(v->steps[i]));
    return n;
}

static i64 entry_steps(const entry_t *e, i64 t) {
    if (!e->has_plan) return e->done;
    i64 k = e->done;
    for (int i = 0; i < e->nseg; i++) k += seg_count(&e->plan[i], t);
    return k;
}

static i64 entry_rate(const entry_t *e, i64 t) {
    if (!e->has_plan || e->nseg == 0 || t < e->plan[0].start) return 0;
    for (int i = 0; i < e->nseg; i++)
        if (t < e->plan[i].end) return seg_rate(&e->plan[i], t);
    return e->exit_rate;
}

static int history_push(stepper *m, const piece_t *p) {
    if (m->hlen == HISTORY) {                  /* full: drop the oldest */
        m->hist[m->hhead] = *p;
        m->hhead = (m->hhead + 1) % HISTORY;
        return 0;
    }
    if (m->hlen == m->hcap) {                 /* grow (the ring is not wrapped yet) */
        size_t cap = m->hcap ? m->hcap * 2 : 64;
        if (cap > HISTORY) cap = HISTORY;
        piece_t *h = realloc(m->hist, cap * sizeof(piece_t));
        if (!h) return -1;
        m->hist = h;
        m->hcap = cap;
    }
    m->hist[(m->hhead + m->hlen) % m->hcap] = *p;
    m->hlen++;
    return 0;
}

static void make_piece(piece_t *p, const i64 *base, const entry_t *e, i64 k_from, i64 k_to,
                       int axes) {
    memset(p, 0, sizeof *p);
    for (int i = 0; i < axes; i++) { p->base[i] = base[i]; p->steps[i] = e->vec.steps[i]; }
    p->n = e->n;
    p->k_from = k_from;
    p->k_to = k_to;
    p->nseg = e->nseg;
    memcpy(p->plan, e->plan, sizeof p->plan);
}

static void record(stepper *m, const entry_t *e, i64 k_to) {
    if (!m->keep_history) return;
    if (e->has_plan && e->nseg > 0 && k_to > e->done) {
        piece_t p;
        make_piece(&p, m->base, e, e->done, k_to, m->axes);
        history_push(m, &p);
    }
}

static i64 cruise(const stepper *m, const entry_t *e) {
    const st_vector *vec = &e->vec;
    i128 n = e->n;
    i128 v = fdiv((i128)vec->velocity * m->xm, 100);
    if (vec->path_speed) {
        i128 s = 0;
        for (int i = 0; i < m->axes && i < 3; i++) s += (i128)vec->steps[i] * vec->steps[i];
        if (s) v = isqrt(fdiv((v * n) * (v * n), s));
    }
    if (n < vec->short_) v = min128(v, vec->brake);
    v = min128(v, m->max_rate);
    for (int i = 0; i < m->axes; i++)
        if (vec->steps[i]) v = min128(v, fdiv((i128)vec->axis_limits[i] * n, abs128(vec->steps[i])));
    return (i64)max128(v, 1);
}

static i64 junction(const stepper *m, const entry_t *e, const entry_t *nxt, i64 vc) {
    if (!nxt || !(e->vec.continuous && nxt->vec.continuous) || nxt->n == 0) return 0;
    if (e->n == 0 && !(m->dev & DEV_ZERO_LENGTH_JUNCTION)) return 0;
    if (m->dev & DEV_JUNCTION_STOPS) return 0;
    if (m->dev & DEV_REVERSAL_STOPS)
        for (int i = 0; i < m->axes; i++)
            if ((e->vec.steps[i] > 0 && nxt->vec.steps[i] < 0)
                    || (e->vec.steps[i] < 0 && nxt->vec.steps[i] > 0)) return 0;
    i64 brake = (m->dev & DEV_NEXT_BRAKE) ? nxt->vec.brake : e->vec.brake;
    if (m->dev & DEV_JUNCTION_UNBRAKED) brake = vc;
    i128 v = min128(min128(brake, vc), cruise(m, nxt));
    v = min128(v, isqrt((i128)2 * nxt->vec.accel * nxt->n));
    return (i64)max128(0, v);
}

static void plan_entry(stepper *m, entry_t *e, i64 t, i64 vin, int join) {
    i64 vc = cruise(m, e);
    const entry_t *nxt = (m->qlen > 1 && e == head(m)) ? qat(m, 1) : NULL;
    i64 vx = join ? junction(m, e, nxt, vc) : 0;
    e->nseg = plan(t, e->done, e->n - e->done, vin, vc, vx, e->vec.accel, e->plan);
    e->has_plan = 1;
    e->end = e->nseg ? e->plan[e->nseg - 1].end : t;
    e->exit_rate = vx;
    e->final = 1;
    e->decision = -1;
    if (vx == 0 && e->vec.continuous) {
        const seg_t *last = e->nseg ? &e->plan[e->nseg - 1] : NULL;
        if (!last) e->decision = t;
        else if (last->kind == REV) e->decision = last->start;
        else e->decision = (m->dev & DEV_CONTINUOUS_DWELL) ? t : last->end;
    }
}

static void start_head(stepper *m, i64 t, i64 vin) {
    entry_t *e = head(m);
    if (e->has_plan) return;
    int at_once = vin > 0 || e->done == e->n || (e->vec.continuous && m->after_c);
    i64 start = at_once ? t : max64(t, sat((i128)m->rest + e->vec.dwell));
    plan_entry(m, e, start, vin, 1);
}

static void replan(stepper *m, i64 t, int join) {
    if (!m->qlen || m->halted) return;
    entry_t *e = head(m);
    if (!e->has_plan || e->nseg == 0 || !e->final) return;
    join = join && (e->exit_rate > 0 || e->decision > t);
    if (t < e->plan[0].start) {
        i64 start = e->plan[0].start;
        plan_entry(m, e, start, 0, join);
        return;
    }
    i64 k = entry_steps(e, t);
    i64 v = entry_rate(e, t);
    record(m, e, k);
    e->done = k;
    plan_entry(m, e, t, v, join);
}

static void pop_head(stepper *m) {
    m->qhead++;
    m->qlen--;
    if (!m->qlen) m->qhead = 0;
}

static void position_now(stepper *m, i64 *out);

void st_advance(stepper *m, int64_t t) {
    if (t < m->now) t = m->now;
    while (m->qlen) {
        entry_t *e = head(m);
        if (!e->has_plan) {
            if (m->halted) break;
            start_head(m, m->now, 0);
        }
        if (e->end > t) break;
        record(m, e, entry_steps(e, e->end));
        if (!e->final) {
            e->done = entry_steps(e, e->end);
            e->has_plan = 0;
            e->nseg = 0;
            m->rest = e->end;
            m->after_c = 0;
            i64 here[ST_AXES];
            position_now(m, here);
            visit(m, here);
            if (m->halted) break;
            start_head(m, e->end, 0);
            continue;
        }
        i64 end = e->end, exit_rate = e->exit_rate, n = e->n;
        int continuous = e->vec.continuous;
        for (int i = 0; i < m->axes; i++) m->base[i] += e->vec.steps[i];
        visit(m, m->base);
        pop_head(m);
        if (!n) {
            m->after_c = 0;
        } else if (exit_rate == 0) {
            m->rest = end;
            m->after_c = continuous && !m->halted && !(m->dev & DEV_CONTINUOUS_DWELL);
        }
        if (m->qlen && (!m->halted || head(m)->has_plan)) start_head(m, end, exit_rate);
    }
    m->now = t;
}

int64_t st_now(stepper *m) { return m->now; }

int st_next_event(stepper *m, int64_t *out) {
    if (m->qlen) {
        entry_t *e = head(m);
        if (e->has_plan && e->end > m->now) { *out = e->end; return 1; }
    }
    if (m->halted && m->stop_end > m->now) { *out = m->stop_end; return 1; }
    return 0;
}

int st_drain_instant(stepper *m, int64_t *out) {
    if (m->halted || !m->qlen) return 0;
    stepper *g = ghost(m);
    if (!g) return -1;
    g->keep_history = 0;
    st_advance(g, NEVER);
    int ok = g->qlen == 0;
    if (ok) *out = g->rest;
    st_free(g);
    return ok;
}

static void position_now(stepper *m, i64 *out) {
    for (int i = 0; i < m->axes; i++) out[i] = m->base[i];
    if (!m->qlen) return;
    entry_t *e = head(m);
    i64 k = entry_steps(e, m->now);
    for (int i = 0; i < m->axes; i++) out[i] += axis_count(k, e->vec.steps[i], e->n);
}

void st_position(stepper *m, int64_t t, int64_t *out) {
    st_advance(m, t);
    position_now(m, out);
}

int st_flags(stepper *m, int64_t t) {
    st_advance(m, t);
    int stopping = m->halted && m->stop_end > m->now;
    int busy = m->qlen > 0;
    int moving = (busy && !m->halted) || stopping;
    return (busy ? ST_BUSY : 0) | (moving ? ST_MOVING : 0) | (stopping ? ST_STOPPING : 0)
        | (m->halted ? ST_HALTED : 0);
}

int64_t st_queued(stepper *m, int64_t t) {
    st_advance(m, t);
    return (i64)m->qlen;
}

/* The executed pieces, then the planned future up to t1 (played on a ghost): read in
 * place (the history ring, the ghost's, the head's remaining plan), never copied. */
typedef struct {
    const stepper *m;
    stepper *g;
    piece_t tail;
    size_t n;
} timeline_t;

static int timeline(stepper *m, i64 t1, timeline_t *tl) {
    stepper *g = ghost(m);
    if (!g) return -1;
    st_advance(g, t1);
    tl->m = m;
    tl->g = g;
    tl->n = m->hlen + g->hlen;
    if (g->qlen && head(g)->has_plan && head(g)->nseg > 0) {
        entry_t *e = head(g);
        make_piece(&tl->tail, g->base, e, e->done, entry_steps(e, NEVER), g->axes);
        tl->n++;
    }
    return 0;
}

static const piece_t *timeline_piece(const timeline_t *tl, size_t i) {
    const stepper *m = tl->m, *g = tl->g;
    if (i < m->hlen) return &m->hist[(m->hhead + i) % m->hcap];
    i -= m->hlen;
    if (i < g->hlen) return &g->hist[(g->hhead + i) % g->hcap];
    return &tl->tail;
}

static void timeline_free(timeline_t *tl) { st_free(tl->g); }

static i64 piece_instant(const piece_t *p, i64 k) {
    for (int i = 0; i < p->nseg; i++) {
        const seg_t *s = &p->plan[i];
        if (s->k0 < k && k <= s->k0 + s->length) return seg_step_instant(s, k - s->k0);
    }
    return -1;
}

static i64 plan_steps(const piece_t *p, i64 t) {
    if (!p->nseg) return 0;
    i64 k = p->plan[0].k0;
    for (int i = 0; i < p->nseg; i++) k += seg_count(&p->plan[i], t);
    return k;
}

int st_instant_of_position(stepper *m, int axis, int64_t value, int64_t *out) {
    i64 here[ST_AXES];
    position_now(m, here);
    if (here[axis] == value) { *out = m->now; return 1; }
    timeline_t tl;
    if (timeline(m, NEVER, &tl)) return -1;
    int found = 0;
    for (size_t i = 0; i < tl.n && !found; i++) {
        const piece_t *p = timeline_piece(&tl, i);
        i64 d = p->steps[axis];
        i128 c = (i128)value - p->base[axis];
        if (d == 0 || c == 0 || ((c > 0) != (d > 0)) || abs128(c) > abs128(d)) continue;
        i64 k = max64(first_step_reaching((i64)abs128(c), d, p->n), p->k_from + 1);
        if (k <= p->k_to && p->base[axis] + axis_count(k, d, p->n) == value) {
            i64 t = piece_instant(p, k);
            if (t >= m->now) { *out = t; found = 1; }
        }
    }
    timeline_free(&tl);
    return found;
}

/* Steps first..last of a piece: their instants, segment by segment (the plan's
 * segments follow each other over the steps), and the axes each moves (Bresenham over
 * the whole stretch), both carried from one step to the next (seg_instants, axis_steps). */
static void piece_train(const piece_t *p, i64 first, i64 last, i64 *times, uint8_t *masks) {
    uint8_t sign = 0;
    for (int a = 0; a < ST_AXES; a++)
        if (p->steps[a] < 0) sign |= (uint8_t)(1 << (4 + a));
    axis_steps(p->steps, p->n, first, last, masks);
    if (sign)
        for (i64 i = 0; i <= last - first; i++) masks[i] |= sign & (uint8_t)(masks[i] << 4);
    for (int i = 0; i < p->nseg; i++) {
        const seg_t *s = &p->plan[i];
        i64 lo = max64(first, s->k0 + 1), hi = min64(last, s->k0 + s->length);
        if (lo <= hi) seg_instants(s, lo - s->k0, hi - s->k0, times + (lo - first));
    }
}

/* the steps of a piece in the train [t0, t1): first..last (none when last < first) */
static void piece_range(const piece_t *p, i64 t0, i64 t1, i64 *first, i64 *last) {
    *first = max64(p->k_from, plan_steps(p, t0 - 1)) + 1;
    *last = min64(p->k_to, plan_steps(p, t1 - 1));
}

int64_t st_pulses(stepper *m, int64_t t0, int64_t t1, int64_t *times, uint8_t *masks,
                  int64_t cap) {
    timeline_t tl;
    if (timeline(m, t1, &tl)) return -1;
    i64 count = 0, first, last;
    for (size_t i = 0; i < tl.n; i++) {
        piece_range(timeline_piece(&tl, i), t0, t1, &first, &last);
        if (last >= first) count += last - first + 1;
    }
    if (count <= cap) {
        i64 at = 0;
        for (size_t i = 0; i < tl.n; i++) {
            const piece_t *p = timeline_piece(&tl, i);
            piece_range(p, t0, t1, &first, &last);
            if (last < first) continue;
            piece_train(p, first, last, times + at, masks + at);
            at += last - first + 1;
        }
    }
    timeline_free(&tl);
    return count;
}

static int append(stepper *m, const st_vector *v, i64 done) {
    if (m->qhead + m->qlen == m->qcap) {
        if (m->qhead) {
            memmove(m->q, m->q + m->qhead, m->qlen * sizeof(entry_t));
            m->qhead = 0;
        } else {
            size_t cap = m->qcap ? m->qcap * 2 : 16;
            entry_t *q = realloc(m->q, cap * sizeof(entry_t));
            if (!q) return -1;
            m->q = q;
            m->qcap = cap;
        }
    }
    entry_t *e = &m->q[m->qhead + m->qlen];
    memset(e, 0, sizeof *e);
    e->vec = *v;
    e->n = vec_len(v, m->axes);
    e->done = done;
    e->decision = -1;
    e->final = 1;
    m->qlen++;
    return 0;
}

int st_push(stepper *m, const st_vector *v, int64_t t) {
    st_advance(m, t);
    if (append(m, v, 0)) return -1;
    if (m->qlen == 1) {
        if (!m->halted) {
            start_head(m, t, 0);
            st_advance(m, t);
        }
    } else if (m->qlen == 2 && head(m)->decision > t && v->continuous) {
        replan(m, t, 1);
    }
    return 0;
}

int64_t st_push_many(stepper *m, const st_timed_vector *v, int64_t n) {
    for (int64_t i = 0; i < n; i++)
        if (st_push(m, &v[i].v, v[i].t)) return i;
    return n;
}

int64_t st_halt(stepper *m, int64_t t) {
    i64 here[ST_AXES];
    st_position(m, t, here);
    visit(m, here);
    if (m->halted) return max64(m->stop_end, t);
    m->halted = 1;
    m->after_c = 0;
    m->stop_end = t;
    if (!m->qlen || !head(m)->has_plan) return t;
    entry_t *h = head(m);
    if (t < h->plan[0].start) {
        h->has_plan = 0;
        h->nseg = 0;
        return t;
    }
    if (h->nseg) {
        const seg_t *last = &h->plan[h->nseg - 1];
        if (h->exit_rate == 0 && last->kind == REV && t >= last->start
                && !(m->dev & (DEV_HALT_SHORT | DEV_HALT_DEAD))) {
            /* already braking to rest on its target: that ramp is the stop */
            m->stop_end = h->end;
            return h->end;
        }
    }
    i64 k = entry_steps(h, t);
    i64 v = entry_rate(h, t);
    i64 a = h->vec.accel;
    i64 distance = (m->dev & DEV_HALT_DEAD) ? 0 : (i64)fdiv((i128)v * v, (i128)2 * a);
    record(m, h, k);
    h->done = k;
    i64 covered = 0, start = t;
    for (size_t i = 0; i < m->qlen; i++) {
        entry_t *e = qat(m, i);
        if (covered == distance) break;
        i64 length = min64(distance - covered, e->n - e->done);
        seg_t piece = reverse(t, 0, a, distance, covered, length, e->done);
        e->has_plan = 1;
        e->nseg = length ? 1 : 0;
        if (length) e->plan[0] = piece;
        e->end = length ? piece.end : start;
        e->exit_rate = 0;
        e->decision = -1;
        covered += length;
        e->final = e->done + length == e->n;
        start = e->end;
    }
    if (covered == 0) {
        h->has_plan = 0;
        h->nseg = 0;
        m->rest = t;
        return t;
    }
    m->stop_end = start;
    return start;
}

void st_resume(stepper *m, int64_t t) {
    st_advance(m, t);
    if (!m->halted) return;
    m->halted = 0;
    if (m->qlen && !head(m)->has_plan) {
        entry_t *h = head(m);
        int at_speed = (m->dev & DEV_GO_AT_SPEED) && h->done < h->n;
        start_head(m, t, at_speed ? cruise(m, h) : 0);
    }
}

void st_clear(stepper *m, int64_t t) {
    st_advance(m, t);
    position_now(m, m->base);
    visit(m, m->base);
    m->qlen = 0;
    m->qhead = 0;
    m->halted = 0;
    m->after_c = 0;
}

int64_t st_entries(stepper *m) { return (i64)m->qlen; }

void st_entry(stepper *m, int64_t i, st_vector *v, int64_t *done) {
    entry_t *e = qat(m, (size_t)i);
    *v = e->vec;
    *done = e->done;
}

int st_halted(stepper *m) { return m->halted; }

void st_restore_begin(stepper *m, int64_t t, int64_t *here) {
    st_advance(m, t);
    position_now(m, here);
    visit(m, here);
    m->qlen = 0;
    m->qhead = 0;
}

int st_restore_add(stepper *m, const st_vector *v, int64_t done) { return append(m, v, done); }

void st_restore_end(stepper *m, const int64_t *here, int halted, int64_t t) {
    m->halted = halted;
    m->after_c = 0;
    if (m->qlen) {
        entry_t *h = head(m);
        for (int i = 0; i < m->axes; i++)
            m->base[i] = here[i] - axis_count(h->done, h->vec.steps[i], h->n);
        if (!halted) start_head(m, t, 0);
    } else {
        for (int i = 0; i < m->axes; i++) m->base[i] = here[i];
    }
}

void st_set_position(stepper *m, int axis, int64_t value, int64_t t) {
    i64 here[ST_AXES];
    st_advance(m, t);
    position_now(m, here);
    visit(m, here);
    m->base[axis] += value - here[axis];
    m->offset[axis] -= value - here[axis];     /* the axis itself does not move */
}

void st_jump(stepper *m, int axis, int64_t delta, int64_t t) {
    i64 here[ST_AXES];
    st_advance(m, t);
    position_now(m, here);
    visit(m, here);
    m->base[axis] += delta;
    position_now(m, here);
    visit(m, here);
}

void st_physical(stepper *m, int64_t t, int64_t *out) {
    st_position(m, t, out);
    for (int i = 0; i < m->axes; i++) out[i] += m->offset[i];
}

void st_excursion(stepper *m, int64_t t, int64_t *out) {
    i64 here[ST_AXES];
    st_position(m, t, here);
    visit(m, here);
    for (int i = 0; i < m->axes; i++) { out[i] = m->lo[i]; out[ST_AXES + i] = m->hi[i]; }
}

void st_set_velocity(stepper *m, int64_t velocity, int64_t t, int has_accel, int64_t accel) {
    st_advance(m, t);
    for (size_t i = 0; i < m->qlen; i++) {
        entry_t *e = qat(m, i);
        e->vec.velocity = velocity;
        if (has_accel) e->vec.accel = accel;
    }
    replan(m, t, 1);
}

void st_scale_velocity(stepper *m, int64_t num, int64_t den, int64_t t, int accel) {
    st_advance(m, t);
    for (size_t i = 0; i < m->qlen; i++) {
        entry_t *e = qat(m, i);
        e->vec.velocity = (i64)max128(1, fdiv((i128)e->vec.velocity * num, den));
        if (accel) e->vec.accel = (i64)max128(1, fdiv((i128)e->vec.accel * num, den));
    }
    replan(m, t, 1);
}

void st_set_multiplier(stepper *m, int64_t percent, int64_t t) {
    st_advance(m, t);
    m->xm = percent;
    replan(m, t, 1);
}
