"""What each key of a run configuration means: one line per :class:`~hexdem.model.config.RunConfig`
field, with its unit. The configuration reference prints them beside each key's type and default,
and a test holds the two lists equal, so that a new key cannot go undescribed.

Lengths are in metres; ``v0``, ``dt`` and ``duration`` are in the run's ``units``.
"""

KEY_DESCRIPTIONS = {
    "shape": "the packing: hexagon, half-hexagon, half-disc, triangle, parallelogram, disc, sites (the "
    "triangular lattice); square, centered-square, chain, packing (beads placed by their builders); "
    "random (a disordered disc packed by a LAMMPS compaction)",
    "edge_beads": "beads per edge of a hexagon or a triangle; along the struck edge of a parallelogram",
    "long_edge": "beads along the struck edge (the long diagonal) of a half-hexagon: 2 short_edge − 1",
    "short_edge": "beads along each short edge of a half-hexagon",
    "radius_beads": "radius of a half-disc or a disc, in bead diameters",
    "depth_beads": "layers of a parallelogram (none: as many as edge_beads)",
    "sites": 'shape = "sites": the sites [m, n] of the packing (m + n even)',
    "sites_file": 'shape = "sites": a CSV with the header m,n, or a TOML file with sites = [[m, n], ...]',
    "site_walls_deg": 'shape = "sites": inward normals of flat walls touching the packing [deg from +x]',
    "vacancies": "labels [m, n] of beads left out of the packing (the walls stay)",
    "diameter_m": "nominal bead diameter d [m] (the paper's 19.05 mm)",
    "bead_material": "the beads' material: a preset (steel316, delrin, brass, aluminium, glass, ptfe) or one "
    "of materials",
    "wall_material": 'the walls\' lining (its own E and ν against each bead), or "none" for no walls',
    "materials": "a table of the configuration's own materials {name: {youngs_modulus_pa, poisson_ratio, "
    "density_kg_m3}}, named like the presets by every key that takes a material",
    "regions": "tables {material, sites, x_min_d, x_max_d, y_min_d, y_max_d}: the beads they select take "
    "that material (interfaces, strips, intruders)",
    "striker_material": "the striker sphere's material (none: the beads')",
    "striker_diameter_m": "the striker sphere's diameter [m] (none: diameter_m)",
    "impacts": "several impacts, or one elsewhere: tables {site or edge_deg, v0, angle_deg, kind, "
    "striker_material, striker_diameter_m}, each defaulting to the run's own",
    "lines": "observation lines besides the packing's own: tables {name, site, angle_deg}",
    "movie": "also write movie.gif, the speed field animated from samples taken in the run",
    "units": "si, or nondimensional (the paper's A = d = M = 1, eq. 3): the units of v0, dt, duration and "
    "of every result",
    "v0": "impact speed V0 (the paper's 0.4 m/s)",
    "strike_angle_deg": "direction of the strike from +x [deg], within 90° of the way into the packing: 0 is "
    "perpendicular to the struck edge, 30 along a row of the hexagonal lattice (none: into "
    "the packing, 0, or a chain's angle_deg)",
    "impact": "velocity (V0 given to the struck bead) or striker (a sphere at V0 hits it)",
    "dt": "time step (none: the contact time over steps_per_contact)",
    "steps_per_contact": "steps per two-body Hertz contact time at the fastest approach (at least 20)",
    "duration": "length of the run (none: until the leading wave has crossed the packing, layer by layer "
    "at the pace of each layer's quickest material)",
    "dump_every": "steps between samples of the analysis and of the dump (none: 1/20 of the contact time)",
    "ranks": "MPI ranks for LAMMPS",
    "engine": "lammps, or reference (hexdem's own integrator of the same model)",
    "dump": "also write LAMMPS's full trajectory dump into the deck",
    "restitution": "bead–bead coefficient of restitution (1: elastic, the paper's ideal model)",
    "wall_restitution": "bead–wall coefficient of restitution (none: restitution)",
    "friction": "Coulomb friction coefficient μ between bodies (0: frictionless spheres that never turn)",
    "wall_friction": "Coulomb friction coefficient against the walls (none: friction)",
    "rolling_friction": "rolling resistance coefficient",
    "precompression_n": "static force per bead–bead contact [N] (0: uncompressed)",
    "initial_state_file": "a CSV m,n,vx,vy[,dx,dy] of initial velocities [m/s] and displacements [m]",
    "sensors": 'sensor particles, each "line:n" ("0:1", "+30:6") or a bead id',
    "sensor_rate_hz": "the sensors' sampling rate [Hz] (the paper's 500 kS/s)",
    "sensor_mass_factor": "a sensor bead's mass relative to a plain bead's",
    "launcher": "the MPI launcher that starts the ranks (none: this environment's mpiexec)",
    "rows": "rows of a square or centered-square crystal",
    "columns": "columns of a square or centered-square crystal",
    "interstitial_diameter_m": "a centered-square crystal's interstitial diameter [m] (none: (√2 − 1) d, "
    "touching its four corners)",
    "interstitial_material": "a centered-square crystal's interstitial material (none: the beads')",
    "beads": "beads of a chain",
    "angle_deg": "direction of a chain from +x [deg]",
    "diameters_m": "a chain's bead diameters [m], one per bead or a pattern that repeats from bead 0 (its length "
    "dividing beads: [0.01905, 0.009525] is a dimer chain; empty: all diameter_m)",
    "bead_materials": "a chain's bead materials, one per bead or a pattern that repeats from bead 0, as "
    "diameters_m (an empty name, or none: bead_material)",
    "intruders": "a chain's intruders: tables {bead, diameter_m, material}, bead counted from 0 (the struck "
    "one), each with its own diameter [m] and/or material",
    "packing_file": 'shape = "packing": a CSV x,y,diameter[,material] of measured positions [m]',
    "walls": 'shape = "packing" or "random": none, or hull (flat walls along the convex hull)',
    "struck_bead": 'shape = "packing": the struck bead, its line in the file counted from 0 (beads.csv\'s '
    "bead_id counts from 1: bead_id = struck_bead + 1)",
    "radius_m": 'shape = "random": radius of the disc the beads fill [m]',
    "diameter_spread": 'shape = "random": the diameters are uniform in d (1 ± diameter_spread), below 0.5',
    "seed": 'shape = "random": seed of the diameters and the loose start (the same seed, the same packing)',
}
