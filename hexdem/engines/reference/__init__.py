"""The reference integrator of the paper's fixed-neighbour Hamiltonian: engine (:mod:`.engine`) and compiled kernel (:mod:`.kernel`)."""
