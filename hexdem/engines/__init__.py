"""Engines that integrate a model: LAMMPS (:mod:`.lammps`) and the RK4 reference integrator (:mod:`.reference`)."""
