"""Weak disorder (Sec. VI): preparation of disordered packings, ensembles of impacts, their statistics and figures."""
