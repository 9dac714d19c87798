/* The pulse tracker's update: hexdem.analysis.tracker_kernel.PulseState.update (see kernels.h). */
#include <math.h>

#include "kernels.h"

/* Window w (7 numbers) centred on sample s of speed v, from the ring's last three samples; its
 * index and count of samples after it. */
static void open_window(double *w, int64_t *index, int64_t *after, const double *ring, double v, int64_t s)
{
    for (int64_t j = 0; j < 3; j++)
        w[j] = s - 3 + j >= 0 ? ring[(s - 3 + j) % 3] : NAN;
    w[3] = v;
    for (int64_t j = 4; j < 7; j++)
        w[j] = NAN;
    *index = s;
    *after = 0;
}

int64_t update_pulses(const double *speeds, int64_t s, double q, double rival_ratio, PulseArrays *state,
                      int64_t *complete)
{
    const PulseArrays arrays = *state; /* a copy, which no store into the arrays can change */
    const PulseArrays *a = &arrays;
    const int64_t capacity = a->capacity;
    int64_t count = 0;
    for (int64_t b = 0; b < a->n; b++) {
        double v = speeds[b];
        double *ring = a->ring + 3 * b, *window = a->window + 7 * b, *rival = a->rival + 7 * b;
        if (v > a->peak[b]) {
            double before = s >= 1 ? ring[(s - 1) % 3] : NAN;
            double before2 = s >= 2 ? ring[(s - 2) % 3] : NAN;
            if (a->after[b] == 3 && a->peak_index[b] >= 3) {
                for (int j = 0; j < 7; j++)
                    rival[j] = window[j];
                a->rival_index[b] = a->peak_index[b];
                complete[count++] = b;
            }
            a->rival_after[b] = 3;
            a->peak[b] = v;
            open_window(window, &a->peak_index[b], &a->after[b], ring, v, s);
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
        } else {
            if (a->after[b] < 3) {
                window[4 + a->after[b]] = v;
                a->after[b] += 1;
            }
            double earlier = -INFINITY;
            for (int64_t k = 1; k <= (s < 3 ? s : 3); k++)
                earlier = ring[(s - k) % 3] > earlier ? ring[(s - k) % 3] : earlier;
            if (v * rival_ratio >= a->peak[b] && v > earlier) {
                open_window(rival, &a->rival_index[b], &a->rival_after[b], ring, v, s);
            } else if (a->rival_after[b] < 3) {
                rival[4 + a->rival_after[b]] = v;
                a->rival_after[b] += 1;
                if (a->rival_after[b] == 3 && a->rival_index[b] >= 3)
                    complete[count++] = b;
            }
        }
        ring[s % 3] = v;
    }
    return count;
}
