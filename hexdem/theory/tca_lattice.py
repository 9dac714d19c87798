"""Fig. 5: the TCA beside the full lattice, both lattices simulated (``hexdem tca --out``).

Fig. 5a: pulse speeds c_n = 1/T_n along the 30° line of a 30° strike at V₀ = 0.1
(nondimensional); Fig. 5b: arrival times along the 30° line of the 11-per-edge experiment
struck at 0° with 0.4 m/s. Each against the TCA and its closed form (eq. (6)).
"""

from __future__ import annotations

import tempfile

import numpy as np

from hexdem.common.io import write_csv
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig
from hexdem.theory import tca
from hexdem.theory import theory_figures as theory_plots
from hexdem.theory.sweep import SweepSettings

#: Fig. 5a: V₀ (nondimensional) and the last bead shown.
FIG5A_V0, FIG5A_LAST = 0.1, 15
#: Fig. 5b: V₀ of the experiment [m/s].
FIG5B_V0_M_S = 0.4


def _rows(table):
    keys = list(table)
    return keys, [
        tuple(int(table[k][i]) if k == "n" else float(table[k][i]) for k in keys) for i in range(len(table["n"]))
    ]


def write_fig5(out, engine: str, log) -> dict:
    """Simulate both lattices of Fig. 5, write its tables and figures, return their summary."""
    config_a = SweepSettings(engine=engine, last=FIG5A_LAST).config(FIG5A_V0, 30.0)
    config_b = RunConfig(engine=engine, v0=FIG5B_V0_M_S, strike_angle_deg=0.0)
    with tempfile.TemporaryDirectory(prefix="hexdem-tca-") as scratch:
        log(f"Fig. 5a: 30 deg strike, V0 = {FIG5A_V0} (nondimensional), {engine}")
        speeds = tca.pulse_speed_table(simulate(config_a, f"{scratch}/a", trace_lines=["+30"]))
        log(f"Fig. 5b: 0 deg strike, V0 = {FIG5B_V0_M_S} m/s, the experiment's hexagon, {engine}")
        arrivals = tca.arrival_time_table(simulate(config_b, f"{scratch}/b", trace_lines=["+30"]))
    speeds = {k: v[speeds["n"] <= FIG5A_LAST] for k, v in speeds.items()}
    header, rows = _rows(speeds)
    write_csv(out / "fig5a_pulse_speed.csv", header, rows)
    header, rows = _rows(arrivals)
    write_csv(out / "fig5b_arrival_time.csv", [h if h == "n" else f"{h}_s" for h in header], rows)
    theory_plots.tca_pulse_speeds(
        speeds["n"],
        speeds["lattice"],
        speeds["n"],
        speeds["tca"],
        speeds["hyperg"],
        FIG5A_V0,
        out / "fig5a_pulse_speed.png",
    )
    theory_plots.tca_arrival_times(
        arrivals["n"],
        *(arrivals[k] * 1e3 for k in ("lattice", "tca", "hyperg")),
        FIG5B_V0_M_S,
        out / "fig5b_arrival_time.png",
    )

    def deviation(table, key):
        return float(np.max(np.abs(table[key] / table["lattice"] - 1)))

    return {
        "engine": engine,
        "fig5a": {
            "v0": FIG5A_V0,
            "beads": [int(speeds["n"][0]), int(speeds["n"][-1])],
            "max_relative_deviation_tca": deviation(speeds, "tca"),
            "max_relative_deviation_hyperg": deviation(speeds, "hyperg"),
        },
        "fig5b": {
            "v0_m_s": FIG5B_V0_M_S,
            "beads": [int(arrivals["n"][0]), int(arrivals["n"][-1])],
            "max_relative_deviation_tca": deviation(arrivals, "tca"),
            "max_relative_deviation_hyperg": deviation(arrivals, "hyperg"),
        },
    }
