"""The precompressed lattice's linear waves (the paper's second open question, Sec. VII): the
measured dispersion against the phonon bands, conical diffraction at the Dirac point, and the
transition from the nonlinear front to the linear regime."""
