"""The reference integrator of the paper's Hamiltonian: engine (:mod:`.engine`), neighbour search
(:mod:`.neighbours`) and compiled kernels (:mod:`.kernel`, :mod:`.friction_kernel`)."""
