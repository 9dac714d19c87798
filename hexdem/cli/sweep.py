"""``hexdem sweep``: a study of any run-config keys (:mod:`hexdem.experiments.sweep`).

``hexdem sweep --vary ... --out DIR`` plans the study into DIR and runs it (``--plan-only``:
plans it and lists its runs); ``hexdem sweep DIR`` runs what a planned study lacks,
``hexdem sweep DIR --run I`` its run I alone (a task of a job array), ``hexdem sweep DIR
--collect`` writes its table.
"""

from __future__ import annotations

from pathlib import Path

from hexdem.cli.options import add_launcher, add_workers_or_parsl
from hexdem.errors import HexdemError


def add_arguments(parser) -> None:
    parser.add_argument(
        "study",
        nargs="?",
        metavar="DIR",
        help="a study folder already planned (by --out DIR): run what it lacks, or --run I, or --collect",
    )
    parser.add_argument(
        "--config",
        metavar="BASE.toml",
        help="the base configuration (keys: RunConfig fields); default: the paper's 11-per-edge steel experiment",
    )
    parser.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="KEY=V1,V2,...",
        help="a key and its values (repeat for more keys: the runs are the product); KEY may be "
        "nested, e.g. regions.0.material or impacts.1.v0",
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        help="the sweep's folder: sweep.json (the plan), runs/ (one result directory per run), "
        "sweep.csv, sweep.png; rerunning the same command resumes it",
    )
    parser.add_argument(
        "--plan-only",
        action="store_true",
        help="write the plan into --out and list its runs (index and name), running none",
    )
    single = parser.add_mutually_exclusive_group()
    single.add_argument("--run", type=int, metavar="I", help="run only run I (from 0) of the study DIR, here")
    single.add_argument(
        "--collect", action="store_true", help="write the table and figure of the study DIR from the runs it holds"
    )
    add_workers_or_parsl(parser, 1, "runs at once, locally (default 1)")
    parser.add_argument(
        "--ranks-per-run",
        type=int,
        metavar="K",
        help="MPI ranks of each LAMMPS run (default: the configuration's ranks, 1; "
        "the reference engine's runs take one)",
    )
    add_launcher(parser, "-n K python -P -m hexdem.experiments.parallel JOB for each run")


def run(args) -> None:
    from hexdem.experiments import sweep
    from hexdem.experiments.executors import check_study_options

    if args.study is None:
        if args.run is not None or args.collect:
            raise HexdemError("--run and --collect need the study folder: hexdem sweep DIR --run I")
        if not args.vary or args.out is None:
            raise HexdemError("a sweep needs --vary KEY=V1,V2,... and --out DIR (or a planned study: hexdem sweep DIR)")
        run_plan(args)
        return
    if args.vary or args.config or args.out or args.plan_only:
        raise HexdemError(f"{args.study} is a planned study: --vary, --config, --out and --plan-only plan a new one")
    out = Path(args.study)
    runs, variations = sweep.planned_study(out)
    if args.run is not None:
        if args.parsl is not None:
            raise HexdemError("--run I runs here, without --parsl")
        run, ran = sweep.run_single(out, runs, args.run, args.ranks_per_run, args.launcher)
        print(f"hexdem sweep: run {args.run} ({run.name}) {'done' if ran else 'was done already: kept'}", flush=True)
    elif args.collect:
        sweep.collect(out, runs, variations)
    else:
        check_study_options(args.workers, args.launcher, args.ranks_per_run)
        sweep.run_study(out, runs, args.workers, args.parsl, args.ranks_per_run, args.launcher)
        sweep.collect(out, runs, variations)


def run_plan(args) -> None:
    from hexdem.experiments.sweep import plan_study, run_sweep
    from hexdem.experiments.sweep_plan import Variation, read_base

    variations = [Variation.parse(option) for option in args.vary]
    source = args.config or "the default configuration"
    if args.plan_only:
        for index, run in enumerate(plan_study(read_base(args.config), variations, args.out, source)):
            print(f"{index}\t{run.name}")
        return
    run_sweep(
        read_base(args.config),
        variations,
        args.out,
        args.workers,
        args.parsl,
        args.ranks_per_run,
        args.launcher,
        source=source,
    )
