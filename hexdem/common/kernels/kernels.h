/* The in-run analysis's per-sample arithmetic, compiled: plain C over a rank's rows, without
 * Python (module.c binds them to Python, every argument by name: binding.h). Each computes what
 * hexdem's NumPy code computes, in the same order and without fast-math or contracted multiply-adds,
 * so that every operation rounds as NumPy's does (see hexdem/analysis/compiled.py). Arrays are
 * C-ordered; (n, k) arrays are n rows of k numbers. A kernel that finds an index outside its array
 * returns -1 and leaves its outputs incomplete. */
#ifndef HEXDEM_KERNELS_H
#define HEXDEM_KERNELS_H

#include <stdint.h>

/* The full-step sample of LAMMPS's first n rows of (., 3) positions, half-step velocities and
 * forces: x (n, 2) the positions, v (n, 2) = velocities + (half_dt / masses) forces. */
void full_step_state(int64_t n, const double *positions, const double *velocities, const double *forces,
                     const double *masses, double half_dt, double *x, double *v);

/* The pairs (i[k] < j[k]) of the n points of positions (n, 2) within cutoff of each other
 * (|x_i − x_j|² ≤ cutoff²), found by a cell list, in the cells' order. Writes the first `capacity`
 * into i and j and returns how many there are (call again with room for them all); -1 when memory
 * runs out, -2 for a position or cutoff that is not finite. */
int64_t pairs_within(int64_t n, const double *positions, double cutoff, int64_t capacity, int64_t *i, int64_t *j);

/* The pulse tracker's state for n rows, each row's arrays as hexdem.analysis.tracker_kernel.PulseState
 * keeps them (capacity: the record ladders' length); the ring and its velocities slot by slot. */
typedef struct {
    int64_t n, capacity;
    double *ring, *peak;             /* (3, n), (n) */
    int64_t *peak_index;             /* (n) */
    double *window;                  /* (n, 7) */
    int64_t *after, *start, *length; /* (n) each */
    int64_t *rec_index;              /* (n, capacity) */
    double *rec_value, *rec_prev, *rec_prev2;
    int64_t *first_index;            /* (n, capacity) */
    double *first_value, *first_prev, *first_prev2;
    double *rival;                   /* (n, 7) */
    int64_t *rival_index, *rival_after;
    double *ring_velocity;           /* (3, n, 2): each ring slot's (vx, vy), read where its speed is not taken (-1) */
    double *lazy_below;              /* (n): the sum of squares below which a sample only enters the ring */
} PulseArrays;

/* A sample as the tracker reads it: its body ids (n_ids) and the previous sample's (n_previous),
 * its velocities (n_velocities, 2) and the rows of them that are the tracker's rows (the
 * PulseArrays' n); written: each row's velocity into end_velocity (n, 2) and, unless speeds is
 * NULL, its speed into speeds (n). */
typedef struct {
    int64_t n_ids, n_previous, n_velocities;
    const int64_t *ids, *previous_ids, *rows;
    const double *velocities;
    double *end_velocity, *speeds;
} SampleRows;

/* PulseState.update of every row but its refinement, row b taking as its sample s the speed
 * |v| (C's hypot, as np.hypot) of its velocity v. A row whose |v| lies clearly below its running
 * maximum divided by rival_ratio, with no window open (vx² + vy² below its lazy_below, which the
 * pass keeps), only enters its ring, whose slot keeps v and the speed -1 until a window needs it:
 * its hypot is not taken (unless speeds is wanted).
 * Writes the rows whose rival window is complete into complete (n) and returns their count;
 * -2 if the sample's ids are not the previous sample's, -1 for a row outside the velocities. */
int64_t sample_pulses(const SampleRows *sample, int64_t s, double q, double rival_ratio, PulseArrays *state,
                      int64_t *complete);

/* What the energy audit reads of a rank's rows (hexdem.analysis.energy.EnergyAudit._row_constants). */
typedef struct {
    int64_t n_rows;                  /* rows of positions and listed_at */
    const double *positions, *listed_at, *velocities, *spins; /* (n_rows, 2) twice, (n_own, 2), (n_own or 0) */
    int64_t n_spins;
    double distance;
    int64_t n_pairs;
    const int64_t *i, *j;
    const double *contact_m, *coefficient;
    const int64_t *region_i, *region_j;
    int64_t n_own;
    const double *masses, *inertia;
    const int64_t *regions;
    const double *start, *external;  /* (n_own, 2) each */
    int64_t n_walls;
    const int64_t *bounds, *curved;  /* (n_walls + 1), (n_walls) */
    const double *points, *lengths;  /* (n_walls, 2), (n_walls) */
    const int64_t *rows;
    const double *radii, *wall_coefficient;
    const int64_t *wall_regions;     /* (bounds[n_walls]) each, with rows, radii, wall_coefficient */
    int64_t n_regions;
} AuditRows;

/* EnergyAudit.part of a rank: 0 if a row of positions lies more than distance from listed_at (the
 * caller lists the contacts again), else 1 with sums (3 + 2 n_regions) = [total energy,
 * translational and rotational kinetic, then each region's kinetic and contact energy] [J];
 * -1 for an index outside its array, -2 when memory runs out. */
int audit_part(const AuditRows *rows, double *sums);

#endif
