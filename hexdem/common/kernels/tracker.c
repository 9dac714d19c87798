/* A sample's speeds and the pulse tracker's update in one pass:
 * hexdem.analysis.tracker_kernel.PulseState.update of np.hypot's speeds (see kernels.h). */
#include <math.h>
#include <stddef.h>

#include "kernels.h"

/* A ring slot whose speed is not taken yet: ring_velocity holds the velocity it is C's hypot of. */
#define LAZY (-1.0)
/* A bead whose sample s² = vx² + vy² lies below (peak / rival_ratio)² by more than CLEAR_MARGIN's
 * relative 1e-9 (any libm's hypot lies within a few ulps, 1e-15, of |v|; s², the squares and
 * their quotient within a few more) neither overtakes its running maximum nor opens a rival, for
 * certain; a peak of at least CLEAR_PEAK keeps both squares far above the subnormal numbers. */
#define CLEAR_MARGIN (1.0 - 1e-9)
#define CLEAR_PEAK 1e-100

/* The speed in slot k of row b's ring. */
static double ring_speed(const PulseArrays *a, int64_t b, int64_t k)
{
    double v = a->ring[k * a->n + b];
    if (v == LAZY)
        return hypot(a->ring_velocity[2 * (k * a->n + b)], a->ring_velocity[2 * (k * a->n + b) + 1]);
    return v;
}

/* The sum of squares vx² + vy² below which a sample of row b can neither overtake its running
 * maximum nor open a rival, while no window is open: (peak / rival_ratio)² less CLEAR_MARGIN's
 * relative 1e-9 (clear: rival_ratio²); -1 (none) while a window is open or below CLEAR_PEAK. */
static double lazy_below(const PulseArrays *a, int64_t b, double clear)
{
    double peak = a->peak[b];
    if (a->after[b] >= 3 && a->rival_after[b] >= 3 && peak >= CLEAR_PEAK)
        return peak * peak * CLEAR_MARGIN / clear;
    return -1.0;
}

/* Window w (7 numbers) centred on sample s of speed v, from row b's ring of the last three
 * samples; its index and count of samples after it. */
static void open_window(const PulseArrays *a, int64_t b, double *w, int64_t *index, int64_t *after, double v,
                        int64_t s)
{
    for (int64_t j = 0; j < 3; j++)
        w[j] = s - 3 + j >= 0 ? ring_speed(a, b, (s - 3 + j) % 3) : NAN;
    w[3] = v;
    for (int64_t j = 4; j < 7; j++)
        w[j] = NAN;
    *index = s;
    *after = 0;
}

/* Row b's running maximum rises to v at sample s: the open rival ends, a complete peak window
 * becomes the rival (written into complete), a new peak window opens and v climbs the record
 * ladder (PulseState._new_maxima). Returns the count written into complete (0 or 1). */
static int64_t new_maximum(const PulseArrays *a, int64_t b, double v, int64_t s, double q, int64_t *complete)
{
    const int64_t capacity = a->capacity;
    double *window = a->window + 7 * b, *rival = a->rival + 7 * b;
    double before = s >= 1 ? ring_speed(a, b, (s - 1) % 3) : NAN;
    double before2 = s >= 2 ? ring_speed(a, b, (s - 2) % 3) : NAN;
    int64_t count = 0;
    if (a->after[b] == 3 && a->peak_index[b] >= 3) {
        for (int j = 0; j < 7; j++)
            rival[j] = window[j];
        a->rival_index[b] = a->peak_index[b];
        complete[count++] = b;
    }
    a->rival_after[b] = 3;
    a->peak[b] = v;
    open_window(a, b, window, &a->peak_index[b], &a->after[b], v, s);
    int64_t n = a->length[b];
    double half = 0.5 * v;
    const double *values = a->rec_value + capacity * b;
    int64_t below = 0;
    for (int64_t k = 0; k < capacity; k++)
        below += values[k] < half;
    below -= capacity - n;
    int64_t drop = below - 1 > 0 ? below - 1 : 0;
    int64_t first = (a->start[b] + drop) % capacity;
    n -= drop;
    int64_t slot;
    if (n >= 2 && values[(first + n - 1) % capacity] < q * values[(first + n - 2) % capacity]) {
        n -= 1;
    } else {
        slot = capacity * b + (first + n) % capacity;
        a->first_index[slot] = s;
        a->first_value[slot] = v;
        a->first_prev[slot] = before;
        a->first_prev2[slot] = before2;
    }
    slot = capacity * b + (first + n) % capacity;
    a->rec_index[slot] = s;
    a->rec_value[slot] = v;
    a->rec_prev[slot] = before;
    a->rec_prev2[slot] = before2;
    a->start[b] = first;
    a->length[b] = n + 1;
    return count;
}

/* Row b's sample s of speed v at or below its running maximum: it fills the peak window's next
 * slot, opens a rival window if it may overtake the maximum and exceeds the three samples before
 * it, or else fills the open rival's next slot (PulseState._follow_rivals). Returns the count
 * written into complete (0 or 1): b, if its rival is now complete. */
static int64_t calm_sample(const PulseArrays *a, int64_t b, double v, int64_t s, double rival_ratio,
                           int64_t *complete)
{
    double *window = a->window + 7 * b, *rival = a->rival + 7 * b;
    if (a->after[b] < 3) {
        window[4 + a->after[b]] = v;
        a->after[b] += 1;
    }
    if (v * rival_ratio >= a->peak[b]) {
        double earlier = -INFINITY;
        for (int64_t k = 1; k <= (s < 3 ? s : 3); k++) {
            double sample = ring_speed(a, b, (s - k) % 3);
            earlier = sample > earlier ? sample : earlier;
        }
        if (v > earlier) {
            open_window(a, b, rival, &a->rival_index[b], &a->rival_after[b], v, s);
            return 0;
        }
    }
    if (a->rival_after[b] < 3) {
        rival[4 + a->rival_after[b]] = v;
        a->rival_after[b] += 1;
        if (a->rival_after[b] == 3 && a->rival_index[b] >= 3) {
            complete[0] = b;
            return 1;
        }
    }
    return 0;
}

int64_t sample_pulses(const SampleRows *sample, int64_t s, double q, double rival_ratio, PulseArrays *state,
                      int64_t *complete)
{
    if (sample->n_ids != sample->n_previous)
        return -2;
    for (int64_t r = 0; r < sample->n_ids; r++)
        if (sample->ids[r] != sample->previous_ids[r])
            return -2;
    const PulseArrays arrays = *state; /* a copy, which no store into the arrays can change */
    const PulseArrays *a = &arrays;
    const double clear = rival_ratio * rival_ratio;
    double *ring = a->ring + (s % 3) * a->n, *velocity = a->ring_velocity + 2 * (s % 3) * a->n; /* slot s % 3 */
    int64_t count = 0;
    for (int64_t b = 0; b < a->n; b++) {
        int64_t row = sample->rows[b];
        if ((uint64_t)row >= (uint64_t)sample->n_velocities)
            return -1;
        double vx = sample->velocities[2 * row], vy = sample->velocities[2 * row + 1];
        sample->end_velocity[2 * b] = vx;
        sample->end_velocity[2 * b + 1] = vy;
        if (sample->speeds == NULL && vx * vx + vy * vy < a->lazy_below[b]) {
            ring[b] = LAZY;
            velocity[2 * b] = vx;
            velocity[2 * b + 1] = vy;
            continue;
        }
        double v = hypot(vx, vy);
        if (sample->speeds != NULL)
            sample->speeds[b] = v;
        if (v > a->peak[b])
            count += new_maximum(a, b, v, s, q, complete + count);
        else
            count += calm_sample(a, b, v, s, rival_ratio, complete + count);
        ring[b] = v;
        a->lazy_below[b] = lazy_below(a, b, clear);
    }
    return count;
}
