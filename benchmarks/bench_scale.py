"""hexdem at scale: end to end vs bare LAMMPS and vs hexdem before, peak memory per process and bytes written.

Usage: python benchmarks/bench_scale.py [--sizes 331,3151,10621,29701,52599] [--ranks 1,2] [--steps 140]
       [--before REV] [--repeats 1] [--quick]

For 331 beads (hexagon, 11 per edge), 3151 beads (half-hexagon 91/46), 10,621 and 29,701 beads
(hexagons of 60 and 100 per edge) and 52,599 beads (the front study's half-disc of radius 170 d),
each with its default run length (the largest take minutes), on 1 and 2 ranks, at each of
``--steps`` steps per contact (default today's 140), with today's hexdem and with hexdem as it
was at ``--before`` (default e8fb865, the last commit before the speed work; skipped when this
clone lacks it), alternating for each size, rank count and step (so that all see the same
machine load):

* **hexdem end to end**: ``hexdem run --config FILE --out DIR --ranks N`` as a subprocess (its
  deck's set-up checked equal to the bare deck's; the output sections differ in sampling)
  (Python start-up, imports, MPI launch, the run with its analysis inside, the result files);
  its wall time, and LAMMPS's "Loop time" inside it (which includes the sampling callback):
  the in-run analysis's share is that loop over the bare loop, minus 1.
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

Targets per row of today's hexdem: the in-run analysis <= 0.25 x the bare loop; end to end <=
1.3 x bare loop + 5 s for 3151 beads and more on 2 ranks (+ 10 s for the front study's 52,599),
and <= 500 MB per process.
``--quick``: hexagons of 5 and 7 per edge for 0.2 ms on 1 and 2 ranks (the same code path, seconds).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
from pathlib import Path

from baseline import BEFORE, baseline_tree, hexdem_command, hexdem_env
from harness import MB, NOOUTPUT_NAME, nooutput_deck, run_watched, tree_bytes, write_config
from machine import describe

from hexdem.engines.lammps.deck import DECK_NAME
from hexdem.engines.lammps.driver import split_deck
from hexdem.engines.lammps.partitions import loop_time_s
from hexdem.engines.lammps.runner import run_bare
from hexdem.model.config import STEPS_PER_CONTACT, RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings

SIZES = {331: RunConfig(shape="hexagon", edge_beads=11),
         3151: RunConfig(shape="half-hexagon", long_edge=91, short_edge=46),
         10621: RunConfig(shape="hexagon", edge_beads=60),
         29701: RunConfig(shape="hexagon", edge_beads=100),
         52599: RunConfig(shape="half-disc", radius_beads=170, v0=0.4)}
QUICK_SIZES = {61: RunConfig(shape="hexagon", edge_beads=5, duration=2e-4),
               127: RunConfig(shape="hexagon", edge_beads=7, duration=2e-4)}
TARGET_FACTOR = 1.3
#: The end-to-end allowance over 1.3 x the bare loop [s], by bead count (the front study's packing: more).
TARGET_OFFSETS_S = {3151: 5.0, 10621: 5.0, 29701: 5.0, 52599: 10.0}
MEMORY_TARGET = 500 * MB
ANALYSIS_SHARE_TARGET = 0.25


def parse_list(text: str) -> list[int]:
    return [int(item) for item in text.replace("_", "").split(",") if item.strip()]


def measure(config: RunConfig, ranks: int, steps: int, work: Path, repeat: int, tree: Path | None) -> dict:
    """hexdem end to end (the version unpacked at ``tree``, None: today's), then bare LAMMPS, on
    ``ranks`` ranks at ``steps`` steps per contact: one row's measurements."""
    config = config.replace(ranks=ranks, steps_per_contact=steps)
    model = build_model(config)
    settings = run_settings(config, model)
    tag = f"{config.n_beads()}-{ranks}-{steps}-{repeat}-{'before' if tree else 'now'}"
    config_path = write_config(config, work / f"{tag}.toml")
    deck = nooutput_deck(model, settings, work / f"bare-{tag}")
    out = work / f"hexdem-{tag}"
    watched = run_watched(hexdem_command("run", "--config", str(config_path), "--out", str(out), "--ranks", str(ranks)),
                          cwd=work, env=hexdem_env(tree)).check(f"hexdem run ({tag})")
    if split_deck((out / "deck" / DECK_NAME).read_text())[0] != split_deck(deck.input_path.read_text())[0]:
        raise SystemExit(f"hexdem run set up another run than {deck.input_path}: the comparison would be unfair")
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


def verdicts(beads: int, ranks: int, r: dict) -> str:
    """The targets of a row of today's hexdem, each met or not."""
    share = r["hexdem loop"] / r["bare loop"] - 1
    words = [f"analysis {share:.2f} {'<=' if share <= ANALYSIS_SHARE_TARGET else '>'} {ANALYSIS_SHARE_TARGET:g}"]
    if beads in TARGET_OFFSETS_S and ranks == 2:
        target = TARGET_FACTOR * r["bare loop"] + TARGET_OFFSETS_S[beads]
        words.append(f"end to end {r['wall']:.1f} {'<=' if r['wall'] <= target else '>'} {target:.1f} s")
        words.append(f"memory {r['rss'] / MB:.0f} {'<=' if r['rss'] <= MEMORY_TARGET else '>'} "
                     f"{MEMORY_TARGET / MB:.0f} MB")
    met = all("<=" in word for word in words)
    return f"{'met' if met else 'NOT met'}: " + ", ".join(words)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=parse_list, help=f"bead counts among {', '.join(map(str, SIZES))} "
                        "(default: all)")
    parser.add_argument("--ranks", type=parse_list, default=[1, 2], help="rank counts (default 1,2)")
    parser.add_argument("--steps", type=parse_list, default=[STEPS_PER_CONTACT],
                        help=f"steps per contact time (default {STEPS_PER_CONTACT})")
    parser.add_argument("--before", default=BEFORE, metavar="REV", help=f"the revision to compare with (default {BEFORE})")
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
        versions = {"now": None, "before": baseline_tree(work, args.before)}
        if versions["before"] is None:
            print(f"(this clone lacks {args.before}: today's hexdem only)")
            del versions["before"]
        for beads in sizes:
            for ranks in args.ranks:
                for steps in args.steps:
                    for version, tree in versions.items():
                        rows = [measure(table[beads], ranks, steps, work, repeat, tree) for repeat in range(args.repeats)]
                        results[beads, ranks, steps, version] = r = median_row(rows)
                        print(f"  measured {beads} beads on {ranks} rank(s), {steps} steps per contact, {version}: "
                              f"hexdem {r['wall']:.2f} s, bare loop {r['bare loop']:.2f} s", flush=True)
    finally:
        shutil.rmtree(work)
    print(f"hexdem run (CLI) vs bare lmp -in {NOOUTPUT_NAME} on the same deck, today's hexdem and at {args.before} "
          f"(before); median of {args.repeats} alternating run(s)")
    header = (f"{'beads':>6} {'ranks':>5} {'steps/τ':>7} {'version':>7} {'steps':>7} {'bare loop [s]':>13} "
              f"{'hexdem loop [s]':>15} {'analysis':>8} {'end-to-end [s]':>14} {'ratio':>6} "
              f"{'peak RSS per process [MB]':>25} {'hexdem bytes':>13} {'bare bytes':>11}")
    print(header)
    for (beads, ranks, steps, version), r in results.items():
        print(f"{beads:>6} {ranks:>5} {steps:>7} {version:>7} {r['steps']:>7.0f} {r['bare loop']:>13.2f} "
              f"{r['hexdem loop']:>15.2f} {r['hexdem loop'] / r['bare loop'] - 1:>8.2f} {r['wall']:>14.2f} "
              f"{r['wall'] / r['bare loop']:>6.2f} {r['rss'] / MB:>25.0f} {r['hexdem bytes']:>13,.0f} "
              f"{r['bare bytes']:>11,.0f}")
    print("(analysis: hexdem's loop / bare loop - 1, the in-run sampling's share; ratio: end to end / bare loop)")
    for (beads, ranks, steps, version), r in results.items():
        if version == "now":
            before = results.get((beads, ranks, steps, "before"))
            speed_up = f"; before / now {before['wall'] / r['wall']:.2f} x end to end" if before else ""
            print(f"target {beads} beads, {ranks} rank(s), {steps} steps per contact: {verdicts(beads, ranks, r)}"
                  f"{speed_up}")
    print("sampled peak RSS [MB] of the processes above 20 MB (python = the CLI or an MPI rank):")
    for (beads, ranks, steps, version), r in results.items():
        print(f"  {beads} beads, {ranks} rank(s), {steps} steps per contact, {version}: {r['breakdown']}")


if __name__ == "__main__":
    main()
