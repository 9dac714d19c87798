"""The physical model: lattice geometry, materials, units, the Hertz law, the model an engine integrates, and the run configuration."""
