"""From engine output to the paper's observables: trajectories, pulse peaks and arrival times, the energy audit, dump
reading, figures."""
