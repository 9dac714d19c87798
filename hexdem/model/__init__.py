"""The physical model: packings and their builders, materials, units, the Hertz law, the model an engine integrates,
and the run configuration."""
