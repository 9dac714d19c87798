"""``hexdem`` entry point: subcommands as modules with ``add_arguments`` and ``run``.

Subcommand modules are imported lazily (only the one asked for), following ASE's CLI.
Every :class:`~hexdem.errors.HexdemError` is printed as one line, ``hexdem: error: ...``;
``--traceback`` shows the full traceback instead. The exit status tells what went wrong
(:data:`EXIT_CODES`): 2 for a usage error (argparse's), 3 for input or an environment that
hexdem refused (or a check of its results that failed), 4 for a simulation that started and failed
(:class:`~hexdem.errors.RunFailed`), 130 for an interrupt (SIGINT, Ctrl-C) and 143 for SIGTERM
(:mod:`hexdem.common.interrupt`); 1 is left to an unexpected error, a bug, which Python reports
with its traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from hexdem.common.interrupt import (
    Interrupted,
    ignore_stops,
    raise_if_stopped,
    shielded,
    stop_on_signals,
    stop_received,
)
from hexdem.common.process_end import skip_final_collections
from hexdem.errors import HexdemError, RunFailed

#: Exit status → what it means (also in the CLI reference).
EXIT_CODES = {
    0: "success",
    1: "an unexpected error (a bug: Python prints its traceback)",
    2: "a usage error: an unknown command or option, a value of the wrong form",
    3: "refused: input or an environment hexdem cannot use, or a check that failed (the engines "
    "disagree), named in one line",
    4: "a simulation that started and failed (LAMMPS stopped, the energy drifted, a packing did not settle)",
    130: "interrupted (Ctrl-C, SIGINT): the run stopped, nothing unfinished kept",
    143: "stopped (SIGTERM, as kill and batch schedulers send): the run stopped, nothing unfinished kept",
}
REFUSED, FAILED, INTERRUPTED = 3, 4, 130

#: name → (module, one-line help)
COMMANDS = {
    "run": ("hexdem.cli.run", "simulate one impact (default: the paper's 11-per-edge experiment)"),
    "preview": ("hexdem.cli.preview", "draw a packing (beads, walls, impacts, observation lines) without running it"),
    "analyse": ("hexdem.cli.analyse", "result files from the dump of a deck run by hand (lmp -in in.hexdem)"),
    "compare": ("hexdem.cli.compare", "run one configuration through LAMMPS and the reference integrator"),
    "signals": ("hexdem.cli.signals", "measured accelerometer signals beside a run's sensor particles"),
    "tca": ("hexdem.cli.tca", "ternary collision approximation: omega, c, pulse speeds (Sec. IV)"),
    "scaling": ("hexdem.cli.scaling", "velocity-decay scaling laws over a V0 sweep (Sec. V)"),
    "ensemble": ("hexdem.cli.ensemble", "weakly disordered ensembles with striker impacts (Sec. VI)"),
    "snapshots": ("hexdem.cli.snapshots", "wavefront speed maps at chosen times (Figs. 3 and 4)"),
    "sweep": ("hexdem.cli.sweep", "a study of any run-config keys, each run a full result directory"),
    "calibrate": ("hexdem.cli.calibrate", "the model's parameters from measured sensor records, with uncertainties"),
    "design": ("hexdem.cli.design", "which beads to instrument, and at which striker speed, for a calibration"),
    "paper": ("hexdem.cli.paper", "the whole paper: every published number beside hexdem's, in one report"),
}


def build_parser(argv) -> argparse.ArgumentParser:
    """The parser, with full options only for the subcommand named in ``argv``."""
    from hexdem.cli.version import VersionAction  # here, so that the command catches its signals at once

    wanted = next((token for token in argv if token in COMMANDS), None)
    parser = argparse.ArgumentParser(prog="hexdem", description="Impulses in 2D hexagonal granular crystals.")
    parser.add_argument("--version", action=VersionAction)
    parser.add_argument("--traceback", action="store_true", help="show full tracebacks on errors")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, (module_name, help_text) in COMMANDS.items():
        module = importlib.import_module(module_name) if name == wanted else None
        command = sub.add_parser(name, help=help_text, description=help_text)
        command.set_defaults(_parser=command)
        if module is not None:
            module.add_arguments(command)
            command.set_defaults(_module=module)
    return parser


def exit_status(error: HexdemError) -> int:
    """The exit status of a command (or workflow script) that ended with ``error``: a run that
    failed, or input refused (:data:`EXIT_CODES`)."""
    return FAILED if isinstance(error, RunFailed) else REFUSED


@shielded
def main(argv=None) -> int:
    command = list(sys.argv) if argv is None else ["hexdem", *argv]
    argv = command[1:]
    try:
        from hexdem.experiments.provenance import running_command

        parser = build_parser(argv)
        args, unknown = parser.parse_known_args(argv)
        if unknown:  # after the command's name, an unknown option is refused with the command's usage
            after = argv.index(unknown[0]) > argv.index(args.command)
            (args._parser if after else parser).error(f"unrecognized arguments: {' '.join(unknown)}")
        raise_if_stopped()  # a stop that arrived while the command's modules loaded
        with running_command(command):
            args._module.run(args)
    except HexdemError as exc:
        if (stop := stop_received()) is not None:  # the stop ended what failed (a Ctrl-C that reached the ranks too)
            return interrupted(Interrupted(stop))
        if "--traceback" in argv:
            raise
        print(f"hexdem: error: {exc}", file=sys.stderr)
        return exit_status(exc)
    except KeyboardInterrupt as exc:
        return interrupted(exc)
    return 0


@shielded
def interrupted(stop: KeyboardInterrupt) -> int:
    """Say in one line that the command was stopped by ``stop``; return its exit status."""
    signal = stop.name if isinstance(stop, Interrupted) else "SIGINT"
    print(f"hexdem: interrupted by {signal}: the run was stopped and nothing unfinished was kept", file=sys.stderr)
    return stop.exit_status if isinstance(stop, Interrupted) else INTERRUPTED


@shielded
def command() -> int:
    """The ``hexdem`` command: :func:`main` in a process that ends with it (see
    :mod:`hexdem.common.process_end`) and that SIGTERM and SIGINT stop
    (:mod:`hexdem.common.interrupt`) until its work has ended."""
    stop_on_signals()
    code = main()
    ignore_stops()
    skip_final_collections()
    return code


if __name__ == "__main__":
    sys.exit(command())
