"""``hexdem design``: which beads to instrument, and at which striker speed, so that a calibration's
records tell the parameters a group cares about (Bayesian experimental design)."""
