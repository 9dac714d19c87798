/* The energy audit of a rank's rows: hexdem.analysis.energy.EnergyAudit.part (see kernels.h). */
#include <math.h>
#include <stdlib.h>

#include "kernels.h"

/* Whether a row of positions lies more than distance from the same row of listed_at. */
static int moved_beyond(const AuditRows *a)
{
    double limit = a->distance * a->distance;
    for (int64_t r = 0; r < a->n_rows; r++) {
        double dx = a->positions[2 * r] - a->listed_at[2 * r];
        double dy = a->positions[2 * r + 1] - a->listed_at[2 * r + 1];
        if (dx * dx + dy * dy > limit)
            return 1;
    }
    return 0;
}

/* A Hertz contact's energy, coefficient × δ^{5/2} with δ the overlap (0 when apart), δ^{5/2} taken as
 * δ² √δ. A pair apart adds +0 rather than being skipped: at rest, ahead of a pulse, whether a pair
 * touches is round-off's coin toss, which a branch mispredicts. max(gap, 0) is written without a
 * condition, as (gap + |gap|) / 2, which is exact (gap + gap doubles gap; gap − gap is +0): with
 * one, GCC compiles that branch back in (docs/validation/benchmarks.md, *C instead of numba*). */
static double hertz(double coefficient, double gap)
{
    double overlap = 0.5 * (gap + fabs(gap));
    return coefficient * (overlap * overlap * sqrt(overlap));
}

/* Each region's contact energy (n_regions) of the candidate pairs, half to each of its rows'
 * regions (-1: a ghost, not audited here), the i sides' halves pair by pair, then the j sides'
 * (hexdem.analysis.energy._pair_energies_j); sides: 2 n_regions of scratch. */
static int pair_energies(const AuditRows *a, double *sides, double *contact)
{
    const int64_t R = a->n_regions;
    for (int64_t k = 0; k < 2 * R; k++)
        sides[k] = 0.0;
    for (int64_t p = 0; p < a->n_pairs; p++) {
        int64_t i = a->i[p], j = a->j[p], ri = a->region_i[p], rj = a->region_j[p];
        if ((uint64_t)i >= (uint64_t)a->n_rows || (uint64_t)j >= (uint64_t)a->n_rows || ri >= R || rj >= R)
            return -1;
        double dx = a->positions[2 * i] - a->positions[2 * j];
        double dy = a->positions[2 * i + 1] - a->positions[2 * j + 1];
        double half = hertz(a->coefficient[p], a->contact_m[p] - sqrt(dx * dx + dy * dy)) / 2;
        if (ri >= 0)
            sides[ri] += half;
        if (rj >= 0)
            sides[R + rj] += half;
    }
    for (int64_t k = 0; k < R; k++)
        contact[k] = sides[k] + sides[R + k];
    return 0;
}

/* Adds to contact the walls' contact energies, member by member within a wall, then wall by wall
 * (hexdem.analysis.energy._add_wall_energies_j): a flat wall {x : n·x = lengths[w]} of normal
 * n = points[w], or (curved[w]) the inside of the circle of centre points[w] and radius lengths[w];
 * wall_sum: n_regions of scratch. */
static int add_wall_energies(const AuditRows *a, double *wall_sum, double *contact)
{
    const int64_t R = a->n_regions;
    for (int64_t w = 0; w < a->n_walls; w++) {
        for (int64_t k = 0; k < R; k++)
            wall_sum[k] = 0.0;
        const double px = a->points[2 * w], py = a->points[2 * w + 1], length = a->lengths[w];
        for (int64_t e = a->bounds[w]; e < a->bounds[w + 1]; e++) {
            int64_t row = a->rows[e], region = a->wall_regions[e];
            if ((uint64_t)row >= (uint64_t)a->n_rows || (uint64_t)region >= (uint64_t)R)
                return -1;
            double x = a->positions[2 * row], y = a->positions[2 * row + 1], depth;
            if (a->curved[w]) {
                double dx = x - px, dy = y - py;
                depth = -(length - sqrt(dx * dx + dy * dy) - a->radii[e]);
            } else {
                depth = -(x * px + y * py - a->radii[e] - length);
            }
            wall_sum[region] += hertz(a->wall_coefficient[e], depth);
        }
        for (int64_t k = 0; k < R; k++)
            contact[k] += wall_sum[k];
    }
    return 0;
}

/* The audited rows' own terms, row by row: translational and rotational kinetic energy, each
 * region's kinetic energy (n_regions) and the work Σ F·u of the constant forces since start. */
static int body_energies(const AuditRows *a, double *translational, double *rotational, double *kinetic,
                         double *work)
{
    double moving_sum = 0.0, turning_sum = 0.0, done = 0.0;
    for (int64_t k = 0; k < a->n_regions; k++)
        kinetic[k] = 0.0;
    for (int64_t r = 0; r < a->n_own; r++) {
        int64_t region = a->regions[r];
        if ((uint64_t)region >= (uint64_t)a->n_regions)
            return -1;
        double vx = a->velocities[2 * r], vy = a->velocities[2 * r + 1];
        double moving = 0.5 * a->masses[r] * (vx * vx + vy * vy);
        double turning = a->n_spins ? 0.5 * a->inertia[r] * (a->spins[r] * a->spins[r]) : 0.0;
        moving_sum += moving;
        turning_sum += turning;
        kinetic[region] += moving + turning;
        done += (a->positions[2 * r] - a->start[2 * r]) * a->external[2 * r]
                + (a->positions[2 * r + 1] - a->start[2 * r + 1]) * a->external[2 * r + 1];
    }
    *translational = moving_sum;
    *rotational = turning_sum;
    *work = done;
    return 0;
}

int audit_part(const AuditRows *a, double *sums)
{
    if (moved_beyond(a))
        return 0;
    const int64_t R = a->n_regions;
    double *scratch = malloc(sizeof(double) * (size_t)(5 * R + 1));
    if (scratch == NULL)
        return -2;
    double *sides = scratch, *contact = scratch + 2 * R, *kinetic = scratch + 3 * R, *wall_sum = scratch + 4 * R;
    double translational, rotational, work;
    int status = pair_energies(a, sides, contact);
    if (status == 0)
        status = add_wall_energies(a, wall_sum, contact);
    if (status == 0)
        status = body_energies(a, &translational, &rotational, kinetic, &work);
    if (status == 0) {
        for (int64_t r = 0; r < R; r++) {
            sums[3 + 2 * r] = kinetic[r];
            sums[4 + 2 * r] = contact[r];
        }
        double rest = 0.0;
        for (int64_t k = 4; k < 3 + 2 * R; k++)
            rest += sums[k];
        sums[0] = (sums[3] + rest) - work; /* as NumPy sums a few numbers: the first, plus the rest in order */
        sums[1] = translational;
        sums[2] = rotational;
        status = 1;
    }
    free(scratch);
    return status;
}
