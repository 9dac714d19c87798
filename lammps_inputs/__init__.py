"""LAMMPS deck templates shipped with hexdem (``string.Template`` syntax, one block per job)."""
