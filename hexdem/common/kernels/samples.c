/* The samples LAMMPS hands over (see kernels.h). */
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
