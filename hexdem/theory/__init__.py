"""Theory of Secs. IV-V: the ternary collision approximation, the V0 sweep and the velocity-decay scaling laws, their
tables and figures."""
