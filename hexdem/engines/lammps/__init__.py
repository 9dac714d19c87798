"""hexdem's LAMMPS engine: deck rendering (:mod:`.deck`), library loading (:mod:`.library`)
and running in-process or through ``mpiexec`` (:mod:`.runner`)."""
