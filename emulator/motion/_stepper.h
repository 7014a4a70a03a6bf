/* The C stepper core's API (a port of python_twin.py; see docs/motion-model.md). */
#ifndef GVE_STEPPER_H
#define GVE_STEPPER_H
#include <stdint.h>

#define ST_AXES 4

typedef struct {
    int64_t steps[ST_AXES];
    int continuous;
    int64_t velocity, accel, brake, short_, dwell;
    int path_speed;
    int64_t axis_limits[ST_AXES];
} st_vector;

typedef struct {
    int kind;
    int64_t t0, v, a, total, m0, length, k0, tdec, start, end;
} seg_t;

typedef struct stepper stepper;

stepper *st_new(int axes, int64_t max_rate);
void st_free(stepper *m);
/* deliberate deviations from the model (interface.py Deviation), for mutants */
void st_set_deviations(stepper *m, int flags);
int64_t st_acc_time(int64_t v, int64_t a, int64_t m);
int64_t st_acc_count(int64_t v, int64_t a, int64_t tau);
/* acc_time(v, a, m + i) for i = 0..count-1 into out, one from the other as pulse
 * trains take them (the walk of _stepper_math.h); -1 (nothing written) where that walk
 * does not fit (rates, accelerations and counts beyond every profile's) */
int64_t st_walk(int64_t v, int64_t a, int64_t m, int64_t count, int64_t *out);
/* floor(sqrt(hi·2^64 + lo)), exact */
uint64_t st_isqrt_u128(uint64_t hi, uint64_t lo);
void st_advance(stepper *m, int64_t t);
int64_t st_now(stepper *m);
int st_next_event(stepper *m, int64_t *out);
int st_drain_instant(stepper *m, int64_t *out);
void st_position(stepper *m, int64_t t, int64_t *out);
/* the state flags at t (interface.py MotionFlags) as bits */
enum { ST_BUSY = 1, ST_MOVING = 2, ST_STOPPING = 4, ST_HALTED = 8 };
int st_flags(stepper *m, int64_t t);
int64_t st_queued(stepper *m, int64_t t);
int st_instant_of_position(stepper *m, int axis, int64_t value, int64_t *out);
/* the pulse train in [t0, t1): returns its length, and writes its instants and masks
 * when the length is at most cap (so cap 0 asks for the length alone); -1: no memory */
int64_t st_pulses(stepper *m, int64_t t0, int64_t t1, int64_t *times, uint8_t *masks,
                  int64_t cap);
int st_push(stepper *m, const st_vector *v, int64_t t);
/* pushes in a batch: each vector at its instant, in order, as st_push one by one;
 * returns how many were pushed (fewer: out of memory) */
typedef struct {
    int64_t t;
    st_vector v;
} st_timed_vector;
int64_t st_push_many(stepper *m, const st_timed_vector *v, int64_t n);
int64_t st_halt(stepper *m, int64_t t);
void st_resume(stepper *m, int64_t t);
void st_clear(stepper *m, int64_t t);
int64_t st_entries(stepper *m);
void st_entry(stepper *m, int64_t i, st_vector *v, int64_t *done);
int st_halted(stepper *m);
void st_restore_begin(stepper *m, int64_t t, int64_t *here);
int st_restore_add(stepper *m, const st_vector *v, int64_t done);
void st_restore_end(stepper *m, const int64_t *here, int halted, int64_t t);
void st_set_position(stepper *m, int axis, int64_t value, int64_t t);
/* the W reference run: the axis moves by delta outside the planner (counter and axis) */
void st_jump(stepper *m, int axis, int64_t delta, int64_t t);
void st_physical(stepper *m, int64_t t, int64_t *out);
/* the lowest physical positions in out[0..ST_AXES), the highest in out[ST_AXES..2 ST_AXES) */
void st_excursion(stepper *m, int64_t t, int64_t *out);
void st_set_velocity(stepper *m, int64_t velocity, int64_t t, int has_accel, int64_t accel);
void st_scale_velocity(stepper *m, int64_t num, int64_t den, int64_t t, int accel);
void st_set_multiplier(stepper *m, int64_t percent, int64_t t);
#endif
