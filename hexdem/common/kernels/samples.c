/* The samples LAMMPS hands over, and the speeds the tracker takes of them (see kernels.h). */
#include <math.h>

#include "kernels.h"

void full_step_state(int64_t n, const double *positions, const double *velocities, const double *forces,
                     const double *masses, double half_dt, double *x, double *v)
{
    for (int64_t r = 0; r < n; r++) {
        double h = half_dt / masses[r];
        x[2 * r] = positions[3 * r];
        x[2 * r + 1] = positions[3 * r + 1];
        v[2 * r] = velocities[3 * r] + h * forces[3 * r];
        v[2 * r + 1] = velocities[3 * r + 1] + h * forces[3 * r + 1];
    }
}

int sample_speeds(int64_t n_ids, const int64_t *ids, int64_t n_previous, const int64_t *previous_ids,
                  int64_t n_velocities, const double *velocities, int64_t n_rows, const int64_t *rows,
                  double *speeds, double *end_velocity)
{
    for (int64_t k = 0; k < n_rows; k++) {
        int64_t row = rows[k];
        if ((uint64_t)row >= (uint64_t)n_velocities)
            return -1;
        double vx = velocities[2 * row], vy = velocities[2 * row + 1];
        speeds[k] = hypot(vx, vy);
        end_velocity[2 * k] = vx;
        end_velocity[2 * k + 1] = vy;
    }
    if (n_ids != n_previous)
        return 0;
    for (int64_t r = 0; r < n_ids; r++)
        if (ids[r] != previous_ids[r])
            return 0;
    return 1;
}
