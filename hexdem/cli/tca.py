"""``hexdem tca``: the ternary collision approximation of Sec. IV.

Without ``--out`` it only solves the TCA (ω, c, the residence time at V₀ = 1); with
``--out DIR`` it also simulates the two lattices of Fig. 5 and writes ``tca.json``,
``fig5a_pulse_speed.csv/png`` (30° strike and line, V₀ = 0.1 nondimensional) and
``fig5b_arrival_time.csv/png`` (0° strike, 30° line, the experiment at V₀ = 0.4 m/s).
"""

from __future__ import annotations

import json
import sys

from hexdem.model.config import ENGINES


def add_arguments(parser) -> None:
    parser.add_argument("--out", metavar="DIR", help="also simulate the lattices of Fig. 5 and write figures here")
    parser.add_argument("--engine", choices=ENGINES, default="reference", help="integrator (default: reference)")
    parser.add_argument("--json", action="store_true", help="print the results as JSON")


def run(args) -> None:
    from hexdem.common.io import ensure_writable_dir, write_json

    def log(message):
        print(f"hexdem tca: {message}", file=sys.stderr, flush=True)

    from hexdem.theory import tca
    from hexdem.theory.tca_lattice import write_fig5

    result = tca.summary()
    if args.out:
        out = ensure_writable_dir(args.out)
        result["lattice"] = write_fig5(out, args.engine, log)
        write_json(out / "tca.json", result)
        log(f"results in {out}")
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        print(f"omega = {result['omega']:.12g}   (compatibility condition, Sec. IV)")
        print(f"c     = {result['c']:.12g}   (eq. (8): velocity at equal speeds / BCA's V0/2)")
