"""hexdem at scale: end to end vs bare LAMMPS, peak memory per process and bytes written.

Usage: python benchmarks/bench_scale.py [--sizes 331,3151,29701] [--ranks 1,2] [--steps 700,140] [--repeats 1] [--quick]

For 331 beads (hexagon, 11 per edge), 3151 beads (half-hexagon 91/46) and 29,701 beads
(hexagon, 100 per edge), each with its default run length (the 29,701-bead run takes
minutes), on 1 and 2 ranks, at each of ``--steps`` steps per contact (default: the former
default 700 beside today's 140, in one run), alternating for each size, rank count and step
(so that all see the same machine load):

* **hexdem end to end**: ``hexdem run --config FILE --out DIR --ranks N`` as a subprocess
  (Python start-up, imports, MPI launch, the run with its analysis inside, the result files);
  its wall time, and LAMMPS's "Loop time" inside it (which includes the sampling callback).
* **bare LAMMPS**: ``mpiexec -n N lmp -in in.nooutput`` (``run_bare``) of the same deck,
  rendered with ``write_deck`` into a scratch directory, without its output section; its
  "Loop time" is the yardstick.
* **peak RSS per process**: while ``hexdem run`` runs, ``VmHWM`` of it and of every
  descendant (the MPI launcher, its proxies, each rank) is read from ``/proc/<pid>/status``
  every 0.2 s, and checked against the ``ru_maxrss`` that ``wait4`` returns for the whole
  tree (its largest single process; what ``/usr/bin/time -v`` prints as "Maximum resident
  set size"): the larger is printed, the sampled processes above 20 MB below the table.
* **bytes written**: all files in hexdem's output directory after the run (deck, log,
  results, figures), and in the bare deck directory (deck, ``in.nooutput``, log).

Targets per row: end to end <= 1.3 x bare loop + 2 s; for 29,701 beads on 2 ranks at the
default step also end to end <= 3 min and <= 500 MB per process.
``--quick``: hexagons of 5 and 7 per edge for 0.2 ms on 1 and 2 ranks (the same code path, seconds).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
from pathlib import Path

from harness import MB, NOOUTPUT_NAME, nooutput_deck, run_watched, tree_bytes, write_config
from machine import describe

from hexdem.engines.lammps.deck import DECK_NAME
from hexdem.engines.lammps.library import environment_command
from hexdem.engines.lammps.partitions import loop_time_s
from hexdem.engines.lammps.runner import run_bare
from hexdem.model.config import STEPS_PER_CONTACT, RunConfig

SIZES = {331: RunConfig(shape="hexagon", edge_beads=11),
         3151: RunConfig(shape="half-hexagon", long_edge=91, short_edge=46),
         29701: RunConfig(shape="hexagon", edge_beads=100)}
QUICK_SIZES = {61: RunConfig(shape="hexagon", edge_beads=5, duration=2e-4),
               127: RunConfig(shape="hexagon", edge_beads=7, duration=2e-4)}
TARGET_FACTOR, TARGET_OFFSET_S = 1.3, 2.0
#: The large-run targets: (beads, ranks) → (end-to-end seconds, bytes per process).
LARGE_TARGETS = {(29701, 2, STEPS_PER_CONTACT): (180.0, 500 * MB)}


def parse_list(text: str) -> list[int]:
    return [int(item) for item in text.replace("_", "").split(",") if item.strip()]


def measure(config: RunConfig, ranks: int, steps: int, work: Path, repeat: int) -> dict:
    """hexdem end to end, then bare LAMMPS, on ``ranks`` ranks at ``steps`` steps per contact: one
    row's measurements."""
    config = config.replace(ranks=ranks, steps_per_contact=steps)
    model = config.model()
    settings = config.settings(model)
    tag = f"{config.n_beads()}-{ranks}-{steps}-{repeat}"
    config_path = write_config(config, work / f"{tag}.toml")
    deck = nooutput_deck(model, settings, work / f"bare-{tag}")
    out = work / f"hexdem-{tag}"
    watched = run_watched([environment_command("hexdem"), "run", "--config", str(config_path), "--out", str(out),
                           "--ranks", str(ranks)]).check(f"hexdem run ({tag})")
    if (out / "deck" / DECK_NAME).read_text() != deck.input_path.read_text():
        raise SystemExit(f"hexdem run wrote another deck than {deck.input_path}: the comparison would be unfair")
    hexdem_loop = loop_time_s(out / "deck" / "log.lammps")
    hexdem_bytes = tree_bytes(out)
    shutil.rmtree(out)
    bare = run_bare(deck, ranks, NOOUTPUT_NAME)
    row = {"wall": watched.wall_s, "hexdem loop": hexdem_loop, "bare wall": bare.wall_time_s,
           "bare loop": loop_time_s(deck.log_path), "rss": watched.peak_per_process,
           "hexdem bytes": hexdem_bytes, "bare bytes": tree_bytes(deck.directory),
           "steps": settings.n_steps, "breakdown": watched.breakdown()}
    shutil.rmtree(deck.directory)
    return row


def median_row(rows: list[dict]) -> dict:
    merged = {key: statistics.median(row[key] for row in rows) for key, value in rows[0].items()
              if isinstance(value, (int, float))}
    merged["rss"] = max(row["rss"] for row in rows)
    merged["breakdown"] = rows[-1]["breakdown"]
    return merged


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=parse_list, help=f"bead counts among {', '.join(map(str, SIZES))} "
                        "(default: all)")
    parser.add_argument("--ranks", type=parse_list, default=[1, 2], help="rank counts (default 1,2)")
    parser.add_argument("--steps", type=parse_list, default=[700, STEPS_PER_CONTACT],
                        help=f"steps per contact time (default 700,{STEPS_PER_CONTACT}: the former default beside today's)")
    parser.add_argument("--repeats", type=int, default=1, help="alternating repeats per row (default 1)")
    parser.add_argument("--quick", action="store_true", help="5- and 7-per-edge hexagons for 0.2 ms (seconds)")
    args = parser.parse_args()
    table = QUICK_SIZES if args.quick else SIZES
    sizes = args.sizes if args.sizes and not args.quick else list(table)
    unknown = [n for n in sizes if n not in table]
    if unknown:
        parser.error(f"unknown size(s) {unknown}; choose among {', '.join(map(str, table))}")
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-scale-"))
    results = {}
    try:
        for beads in sizes:
            for ranks in args.ranks:
                for steps in args.steps:
                    rows = [measure(table[beads], ranks, steps, work, repeat) for repeat in range(args.repeats)]
                    results[beads, ranks, steps] = r = median_row(rows)
                    print(f"  measured {beads} beads on {ranks} rank(s), {steps} steps per contact: hexdem "
                          f"{r['wall']:.2f} s, bare loop {r['bare loop']:.2f} s", flush=True)
    finally:
        shutil.rmtree(work)
    print(f"hexdem run (CLI) vs bare lmp -in {NOOUTPUT_NAME} on the same deck; median of {args.repeats} "
          f"alternating run(s); target: end to end <= {TARGET_FACTOR:g} x loop + {TARGET_OFFSET_S:g} s")
    header = (f"{'beads':>6} {'ranks':>5} {'steps/τ':>7} {'steps':>7} {'bare loop [s]':>13} {'bare wall [s]':>13} "
              f"{'hexdem loop [s]':>15} {'end-to-end [s]':>14} {'ratio':>6} {'target [s]':>10} {'met':>4} "
              f"{'peak RSS per process [MB]':>25} {'hexdem bytes':>13} {'bare bytes':>11}")
    print(header)
    for (beads, ranks, steps), r in results.items():
        target = TARGET_FACTOR * r["bare loop"] + TARGET_OFFSET_S
        print(f"{beads:>6} {ranks:>5} {steps:>7} {r['steps']:>7.0f} {r['bare loop']:>13.2f} {r['bare wall']:>13.2f} "
              f"{r['hexdem loop']:>15.2f} {r['wall']:>14.2f} {r['wall'] / r['bare loop']:>6.2f} {target:>10.2f} "
              f"{'yes' if r['wall'] <= target else 'NO':>4} {r['rss'] / MB:>25.0f} {r['hexdem bytes']:>13,.0f} "
              f"{r['bare bytes']:>11,.0f}")
    print("sampled peak RSS [MB] of the processes above 20 MB (hexdem = the CLI, python = an MPI rank):")
    for (beads, ranks, steps), r in results.items():
        print(f"  {beads} beads, {ranks} rank(s), {steps} steps per contact: {r['breakdown']}")
    for (beads, ranks, steps), (seconds, memory) in LARGE_TARGETS.items():
        if (beads, ranks, steps) in results:
            r = results[beads, ranks, steps]
            met = r["wall"] <= seconds and r["rss"] <= memory
            print(f"target {beads} beads on {ranks} ranks, {steps} steps per contact: <= {seconds / 60:g} min and "
                  f"<= {memory / MB:.0f} MB per process: {r['wall'] / 60:.2f} min, {r['rss'] / MB:.0f} MB: "
                  f"{'met' if met else 'NOT met'}")


if __name__ == "__main__":
    main()
