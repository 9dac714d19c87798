"""``hexdem scaling``: the velocity-decay scaling laws of Sec. V over a V₀ sweep.

Writes ``OUT/scaling.json`` (keys "30/30", "30/0", "0/0", "0/30": m, b, alpha, beta, gamma,
standard errors, start bead, window, V₀ range, the laws in m/s and the geometric-or-power
verdict), CSV tables and the PNGs of Figs. 6 and 7 (see :mod:`hexdem.theory.scaling`, :mod:`hexdem.theory.sweep`
and :mod:`hexdem.theory.outputs`).
"""

from __future__ import annotations

import json
import sys

from hexdem.cli.options import add_launcher, add_workers_or_parsl
from hexdem.model.config import ENGINES


def add_arguments(parser) -> None:
    from hexdem.theory.scaling import FIT_KINDS
    from hexdem.theory.sweep import SweepSettings

    d = SweepSettings()
    parser.add_argument("--out", metavar="DIR", default="scaling", help="output directory (default: scaling/)")
    parser.add_argument(
        "--engine",
        choices=ENGINES,
        default=d.engine,
        help=f"integrator (default: {d.engine}; lammps runs nondimensional decks)",
    )
    parser.add_argument(
        "--v0-min", type=float, default=d.v0_min, help=f"smallest V0, nondimensional (default {d.v0_min})"
    )
    parser.add_argument(
        "--v0-max", type=float, default=d.v0_max, help=f"largest V0, nondimensional (default {d.v0_max})"
    )
    parser.add_argument(
        "--n-v0", type=int, default=d.n_v0, help=f"number of V0 values, evenly spaced (default {d.n_v0})"
    )
    parser.add_argument(
        "--last",
        type=int,
        default=d.last,
        help=f"last bead of every fit window (default {d.last}, as in the paper's Figs. 6a and 7a)",
    )
    parser.add_argument(
        "--fit",
        choices=FIT_KINDS,
        default="loglinear",
        help="per-V0 fit of V_n = V_start c^(n - start): least squares on log V (default) or on V itself",
    )
    parser.add_argument(
        "--steps-per-contact",
        type=int,
        default=d.steps_per_contact,
        help=f"time step = contact time at V0 / this (default {d.steps_per_contact})",
    )
    parser.add_argument(
        "--duration",
        type=float,
        default=d.duration_contacts,
        metavar="CONTACT_TIMES",
        help=f"run length in contact times at V0 (default {d.duration_contacts:g})",
    )
    add_workers_or_parsl(parser, d.workers, f"runs at once, in local processes (default {d.workers})")
    add_launcher(parser, "-n 1 python -P -m hexdem.experiments.parallel JOB for each run")
    parser.add_argument("--json", action="store_true", help="also print scaling.json to stdout")


def run(args) -> None:
    from hexdem.common.io import ensure_writable_dir
    from hexdem.experiments.executors import parsl_session
    from hexdem.theory.outputs import write_outputs
    from hexdem.theory.sweep import SweepSettings, run_sweep

    settings = SweepSettings(
        v0_min=args.v0_min,
        v0_max=args.v0_max,
        n_v0=args.n_v0,
        last=args.last,
        steps_per_contact=args.steps_per_contact,
        duration_contacts=args.duration,
        engine=args.engine,
        workers=args.workers,
        launcher=args.launcher,
        parsl=args.parsl,
    )
    parsl = parsl_session(args.parsl, args.out)  # a bad file is refused before the output directory is made
    ensure_writable_dir(args.out)
    summary = write_outputs(run_sweep(settings, parsl=parsl), args.out, kind=args.fit)
    warned = summary["sweep"]["runs_that_warned"]
    if warned:
        from hexdem.theory.sweep import SCALING_WARNINGS

        names = sorted({name for run in warned for name in run["warnings"]})
        print(
            f"hexdem scaling: {len(warned)} of {len(settings.v0) * 2} runs warned (the warnings column of "
            f"peaks.csv): {'; '.join(SCALING_WARNINGS[name] for name in names)}",
            file=sys.stderr,
        )
    print(f"hexdem scaling: results in {args.out}", file=sys.stderr)
    if args.json:
        print(json.dumps(summary, indent=2))
