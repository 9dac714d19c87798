"""hexdem at scale: a large run stage by stage, each MPI rank's peak memory and the analysis's collectives.

Usage: python benchmarks/bench_scale.py [--edges 100,200] [--ranks 1,2,4,8] [--duration 1e-4] [--before REV]
[--repeat K] [--quick]

For a hexagon of each of ``--edges`` beads per edge (100: 29,701 beads; 200: 119,401; 578:
1,000,519), run ``--duration`` seconds (default 1e-4) on each of ``--ranks`` rank counts (more ranks
than cores is fine for memory and collective counts, not for times):

* **model build** and **data file**: :func:`~hexdem.model.model_builder.build_model` with its settings, and rendering
the
  deck with its data file (``write_deck``, as rank 0 does in the run), in this process;
* **hexdem run end to end**: ``hexdem run --config FILE --out DIR --ranks N`` as a subprocess
  (Python start-up, the MPI launch, the run with its analysis inside, the result files and
  figures); from its outputs: LAMMPS's "Loop time" (which includes the sampling callback), the
  **run** (``summary.json``'s ``wall_time_s``: model, MPI job, engine and gathered results, up to
  the result files), the **results** (from ``peaks.csv``, which ``write_results`` writes first, to
  the newest result file: tables and figures), the **collectives** the analysis took
  (``summary.json``), the neighbour-list rebuilds (LAMMPS's log) and the audited samples;
* **bare LAMMPS**: ``mpiexec -n N lmp -in in.nooutput`` of the same deck without its output
  section, the yardstick: the analysis's share of the loop is hexdem's loop / the bare loop − 1,
  each round's loop over that round's bare loop (with ``--repeat``, the median of the rounds');
* **the analysis part by part inside the run**: ``summary.json``'s ``analysis_cpu_s`` (each part's
  CPU time, summed over the ranks) per bead, the tracker per sample, the audit per audited sample,
  the gathering once: measured on any rank count, more ranks than cores included;
* **the callbacks by LAMMPS's own timer**: the slowest rank's "Modify" time (the fixes, ``fix
  external``'s call into hexdem among them) less the bare deck's, and its share of the rest of
  hexdem's loop: the same share measured inside one run, free of the loop's spread between runs;
* **where the loop's excess lies**: each section of LAMMPS's timing breakdown (its average over
  the ranks, which sum to the loop), hexdem's less the bare deck's. Beside the callbacks
  ("Modify"), a rank slowed by anything else (another process on its core, caches its neighbour
  left cold) keeps the others waiting in "Comm", and data that a callback pushed out of the caches
  comes back in "Pair";
* **peak RSS per process** (:func:`harness.run_watched`): the ``hexdem run`` process (which
  also writes the results and figures) and each MPI rank, read from ``/proc``;
* **the same results on every rank count**: ``peaks.csv`` and ``beads.csv`` of each rank count
  against those of the first (default: one rank), text columns equal, numbers within
  :data:`RESULTS_RTOL` (round-off: LAMMPS sums forces in another order on other ranks).

* **before**, with ``--before REV`` (a revision of this clone, or a directory holding its unpacked
  package, :func:`baseline.baseline_tree`): the same ``hexdem run`` by that version, on the same
  machine and deck, beside the same bare loop: its loop, its analysis's share and its end to end.

Targets: at 119,401 beads on 8 ranks the largest process <= 400 MB; each rank's peak falls as
ranks are added; collectives <= one per neighbour-list rebuild + one per audited sample + 2 (the
first sample's layout and the final gather); results equal on every rank count. The analysis's
share of the loop <= :data:`SHARE_TARGET` at 29,701 and 119,401 beads on 1 and 2 ranks, and <=
:data:`MANY_RANKS_SHARE_TARGET` from :data:`MANY_RANKS` ranks on (a machine of that many cores); end
to end <= :data:`END_TO_END_FACTOR` × the bare loop + :data:`END_TO_END_OFFSET_S` at 29,701 beads on 2
ranks; a million beads' result files and figures <= :data:`MILLION_RESULTS_S`.
``--repeat K``: each row's times are the medians of K rounds (hexdem and before, the one first
in one round and the other in the next, then bare; one machine's load varies by 10 to 50 %
between runs a minute apart), its shares the medians of the rounds' own shares. ``--quick``: a
hexagon of 5 per edge for 0.2 ms on 1 and 2 ranks (the same code path, seconds).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
from baseline import baseline_tree, hexdem_command, hexdem_env
from harness import MB, NOOUTPUT_NAME, nooutput_deck, run_watched, write_config
from machine import describe

from hexdem.engines.lammps.runner import run_bare
from hexdem.engines.lammps.standalone import loop_time_s
from hexdem.experiments.run import RESULT_FILES
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings

MEMORY_TARGET = 400 * MB
#: The memory target's run: this many beads on this many ranks.
MEMORY_TARGET_RUN = (119_401, 8)
#: Collectives beside one per rebuild and one per audited sample: the first sample's layout, the final gather.
COLLECTIVES_BESIDE = 2
#: The analysis's share of the loop (hexdem's loop / the bare loop − 1), at most, on 1 and 2 ranks of
#: 29,701 and 119,401 beads, and from MANY_RANKS ranks on.
SHARE_TARGET, MANY_RANKS_SHARE_TARGET, MANY_RANKS = 0.10, 0.15, 16
SHARE_TARGET_BEADS = (29_701, 119_401)
#: End to end at 29,701 beads on 2 ranks <= this × the bare loop + this offset.
END_TO_END_FACTOR, END_TO_END_OFFSET_S, END_TO_END_RUN = 1.25, 3.0, (29_701, 2)
#: A million beads' result files and figures (the 578-per-edge hexagon), at most.
MILLION_RESULTS_S = 5.0
#: Result tables compared across rank counts, and how close their numbers must be.
TABLES, RESULTS_RTOL, RESULTS_ATOL = ("peaks.csv", "beads.csv"), 1e-9, 1e-15


def parse_list(text: str, kind=int) -> list:
    return [kind(item) for item in text.replace("_", "").split(",") if item.strip()]


def neighbour_builds(log: Path) -> int:
    """LAMMPS's "Neighbor list builds" over the runs of a log."""
    return sum(int(n) for n in re.findall(r"Neighbor list builds = (\d+)", log.read_text()))


#: The sections of LAMMPS's timing breakdown, which sum to its loop time.
SECTIONS = ("Pair", "Neigh", "Comm", "Output", "Modify", "Other")


def section_times_s(log: Path) -> dict[str, float]:
    """Each section's time [s] over the runs of a LAMMPS log, from its timing breakdown: the ranks'
    average (``Other`` has no other), and as ``"slowest Modify"`` the slowest rank's "Modify" (the
    fixes' time, hexdem's sampling callback included, as ``fix external`` calls it in ``post_force``)."""
    text = log.read_text()
    times = {name: sum(float(t) for t in re.findall(rf"^{name}\s*\|[^|]*\|\s*(\S+)", text, re.M)) for name in SECTIONS}
    times["slowest Modify"] = sum(float(t) for t in re.findall(r"^Modify\s*\|[^|]*\|[^|]*\|\s*(\S+)", text, re.M))
    return times


def audited_samples(table: Path) -> int:
    """The samples the energy audit measured: the distinct times of ``energy_regions.csv``."""
    with open(table, newline="") as fh:
        return len({row["time"] for row in csv.DictReader(fh)})


def read_table(path: Path) -> np.ndarray:
    """A result table as a structured array (a field per column, text or number)."""
    return np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="utf-8")


def table_mismatch(table: np.ndarray, reference: np.ndarray) -> float:
    """The largest |a - b| / (atol + rtol |b|) over the numbers of two result tables: <= 1 is
    round-off. A NaN (no complete pulse) may face a value within atol of zero (a bead that stayed
    at rest to round-off in one run and moved by round-off, 1e-33 m/s, in the other); inf where a
    text, the shape or any other NaN differs."""
    if table.shape != reference.shape or table.dtype.names != reference.dtype.names:
        return np.inf
    worst = 0.0
    for name in table.dtype.names:
        a, b = table[name], reference[name]
        if a.dtype.kind not in "fiu":
            worst = worst if np.array_equal(a, b) else np.inf
            continue
        a, b = a.astype(float), b.astype(float)
        odd = np.isnan(a) != np.isnan(b)
        if np.any(np.abs(np.where(np.isnan(a), b, a)[odd]) > RESULTS_ATOL):
            return np.inf
        seen = ~np.isnan(a) & ~np.isnan(b)
        worst = max(
            worst,
            float(np.max(np.abs(a[seen] - b[seen]) / (RESULTS_ATOL + RESULTS_RTOL * np.abs(b[seen])), initial=0.0)),
        )
    return worst


def results_span_s(out: Path) -> float:
    """Seconds from ``peaks.csv`` (the first result file written) to the newest result file."""
    stamps = [(out / name).stat().st_mtime for name in RESULT_FILES if (out / name).exists()]
    return max(stamps) - (out / "peaks.csv").stat().st_mtime


def paired_share(loops_s, bare_loops_s) -> float:
    """The analysis's share of the loop from rounds of loops and bare loops: the median of each
    round's loop / its own bare loop, minus 1. A round runs them a few seconds apart, so a slow
    spell of the machine, which lasts minutes, falls on both; a ratio of medians would pair loops
    from different rounds."""
    return float(np.median(np.asarray(loops_s) / np.asarray(bare_loops_s))) - 1


def run_before(config_file: Path, ranks: int, work: Path, tag: str, before: Path) -> dict:
    """The earlier version's ``hexdem run`` of ``config_file``: its end to end ("before wall") and loop."""
    earlier = work / f"before-{tag}"
    wall = (
        run_watched(
            hexdem_command("run", "--config", str(config_file), "--out", str(earlier), "--ranks", str(ranks)),
            cwd=work,
            env=hexdem_env(before),
        )
        .check(f"hexdem run before ({tag})")
        .wall_s
    )
    loop = loop_time_s(earlier / "deck" / "log.lammps")
    shutil.rmtree(earlier)
    return {"before wall": wall, "before loop": loop}


def measure(config: RunConfig, ranks: int, work: Path, before: Path | None = None, repeat: int = 1) -> dict:
    """One row: the stages, each process's peak memory and the collectives of ``config`` on ``ranks``;
    with ``before`` (an earlier version's package tree), that version's loop and end to end too. The
    times are medians of ``repeat`` rounds, each round hexdem and the earlier version (in turn
    first, so that neither always follows the bare loop), then the bare loop (so that a slow
    spell of the machine falls on all three alike)."""
    config = config.replace(ranks=ranks)
    tag = f"{config.edge_beads}-{ranks}"
    start = time.perf_counter()
    model = build_model(config)
    settings = run_settings(config, model)
    built = time.perf_counter()
    deck = nooutput_deck(model, settings, work / f"bare-{tag}")
    written = time.perf_counter()
    out = work / f"hexdem-{tag}"
    config_file = write_config(config, work / f"{tag}.toml")
    rounds: dict[str, list[float]] = {}
    for round_index in range(repeat):
        before_first = before is not None and round_index % 2 == 1
        earlier = run_before(config_file, ranks, work, tag, before) if before_first else {}
        watched = run_watched(
            hexdem_command("run", "--config", str(config_file), "--out", str(out), "--ranks", str(ranks)), cwd=work
        ).check(f"hexdem run ({tag})")
        summary = json.loads((out / "summary.json").read_text())
        log = out / "deck" / "log.lammps"
        times = {
            "hexdem loop": loop_time_s(log),
            **{f"hexdem {name}": t for name, t in section_times_s(log).items()},
            "run": summary["wall_time_s"],
            "results": results_span_s(out),
            "wall": watched.wall_s,
        }
        if before is not None:
            times.update(earlier or run_before(config_file, ranks, work, tag, before))
        run_bare(deck, ranks, NOOUTPUT_NAME)
        times["bare loop"] = loop_time_s(deck.log_path)
        times.update({f"bare {name}": t for name, t in section_times_s(deck.log_path).items()})
        for name, seconds in times.items():
            rounds.setdefault(name, []).append(seconds)
        print(
            f"  {model.n_bodies} beads on {ranks} rank(s), round {len(rounds['wall'])}: "
            + ", ".join(
                f"{name} {seconds:.2f} s" for name, seconds in times.items() if name.rsplit(" ", 1)[-1] not in SECTIONS
            ),
            flush=True,
        )
        if len(rounds["wall"]) < repeat:
            shutil.rmtree(out)
    rank_peaks = sorted(
        (
            rss
            for pid, (name, rss) in watched.peaks.items()
            if name.startswith("python") and (pid != watched.pid or ranks == 1)
        ),
        reverse=True,
    )
    row = {
        "beads": model.n_bodies,
        "steps": settings.n_steps,
        "model": built - start,
        "data file": written - built,
        **{name: float(np.median(seconds)) for name, seconds in rounds.items()},
        **{
            f"{way}share": paired_share(rounds[f"{way}loop"], rounds["bare loop"])
            for way in ("hexdem ", "before ")
            if f"{way}loop" in rounds
        },
        "largest": watched.peak_per_process,
        "ranks rss": rank_peaks,
        "cli rss": watched.peaks.get(watched.pid, ("", 0))[1],
        "collectives": summary["collectives"],
        "cpu": summary["analysis_cpu_s"],
        "samples": summary["n_samples"],
        "rebuilds": neighbour_builds(log),
        "audited": audited_samples(out / "energy_regions.csv"),
        "tables": {name: read_table(out / name) for name in TABLES},
    }
    shutil.rmtree(out)
    shutil.rmtree(deck.directory)
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--edges", type=parse_list, default=[100, 200], help="hexagon edges in beads (default 100,200)")
    parser.add_argument("--ranks", type=parse_list, default=[1, 2, 4, 8], help="rank counts (default 1,2,4,8)")
    parser.add_argument("--duration", type=float, default=1e-4, help="simulated time [s] (default 1e-4)")
    parser.add_argument("--before", help="also time hexdem of this revision (or unpacked package tree) side by side")
    parser.add_argument("--repeat", type=int, default=1, help="rounds per row; its times are their medians (default 1)")
    parser.add_argument("--quick", action="store_true", help="a 5-per-edge hexagon for 0.2 ms on 1 and 2 ranks")
    args = parser.parse_args()
    edges, ranks, duration = ([5], [1, 2], 2e-4) if args.quick else (args.edges, args.ranks, args.duration)
    print(
        f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}; times: medians of {args.repeat} round(s)",
        flush=True,
    )
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-scale-"))
    results = {}
    try:
        before = None
        if args.before is not None:
            before = Path(args.before) if Path(args.before).is_dir() else baseline_tree(work, args.before)
            if before is None:
                raise SystemExit(f"bench_scale.py: this clone holds no revision {args.before}")
        for edge in edges:
            for n in ranks:
                results[edge, n] = r = measure(
                    RunConfig(shape="hexagon", edge_beads=edge, duration=duration), n, work, before, args.repeat
                )
                print(
                    f"  measured {r['beads']} beads on {n} rank(s): end to end {r['wall']:.1f} s, "
                    f"largest process {r['largest'] / MB:.0f} MB",
                    flush=True,
                )
    finally:
        shutil.rmtree(work)
    print(f"hexdem run (CLI) of hexagons for {duration:g} s, stage by stage [s], beside bare lmp -in {NOOUTPUT_NAME}")
    print(
        f"{'beads':>9} {'ranks':>5} {'steps':>6} {'model [s]':>9} {'data file [s]':>13} {'bare loop [s]':>13} "
        f"{'hexdem loop [s]':>15} {'analysis':>8} {'run [s]':>8} {'results [s]':>11} {'end-to-end [s]':>14}"
    )
    for (_edge, n), r in results.items():
        print(
            f"{r['beads']:>9,} {n:>5} {r['steps']:>6} {r['model']:>9.2f} {r['data file']:>13.2f} "
            f"{r['bare loop']:>13.2f} {r['hexdem loop']:>15.2f} {r['hexdem share']:>8.2f} "
            f"{r['run']:>8.2f} {r['results']:>11.2f} {r['wall']:>14.2f}"
        )
    print(
        "(analysis: the median of the rounds' hexdem loop / bare loop - 1; run: summary.json's wall_time_s, "
        "to the result files; results: the result tables and figures)"
    )
    print(
        "the sampling callbacks by LAMMPS's own timer (slowest rank's Modify: hexdem's less the bare deck's), "
        "and their share of the rest of hexdem's loop"
    )
    print(
        f"{'beads':>9} {'ranks':>5} {'modify hexdem [s]':>17} {'modify bare [s]':>15} {'callbacks [s]':>13} "
        f"{'callback share':>14}"
    )
    for (_edge, n), r in results.items():
        callbacks = r["hexdem slowest Modify"] - r["bare slowest Modify"]
        print(
            f"{r['beads']:>9,} {n:>5} {r['hexdem slowest Modify']:>17.2f} {r['bare slowest Modify']:>15.2f} "
            f"{callbacks:>13.2f} {callbacks / (r['hexdem loop'] - callbacks):>14.2f}"
        )
    print(
        "where hexdem's loop exceeds the bare loop: each section of LAMMPS's timing breakdown (the ranks' average), "
        "hexdem's less the bare deck's [s]"
    )
    print(f"{'beads':>9} {'ranks':>5} {'loop':>6} " + " ".join(f"{name:>7}" for name in SECTIONS))
    for (_edge, n), r in results.items():
        print(
            f"{r['beads']:>9,} {n:>5} {r['hexdem loop'] - r['bare loop']:>6.2f} "
            + " ".join(f"{r[f'hexdem {name}'] - r[f'bare {name}']:>7.2f}" for name in SECTIONS)
        )
    print(
        "the analysis part by part inside the run (summary.json's analysis_cpu_s, CPU time summed over the ranks), "
        "per bead: tracker per sample, audit per audited sample, gathering once [ns]"
    )
    print(f"{'beads':>9} {'ranks':>5} {'tracker':>8} {'audit':>8} {'gathering':>9}")
    for (_edge, n), r in results.items():
        per_bead = 1e9 / r["beads"]
        print(
            f"{r['beads']:>9,} {n:>5} {r['cpu']['tracker'] * per_bead / r['samples']:>8.1f} "
            f"{r['cpu']['audit'] * per_bead / r['audited']:>8.1f} {r['cpu']['gathering'] * per_bead:>9.0f}"
        )
    if args.before is not None:
        print(f"before ({args.before}) and now, side by side on the same deck and bare loop")
        print(
            f"{'beads':>9} {'ranks':>5} {'bare loop [s]':>13} {'loop before':>11} {'loop now':>8} "
            f"{'analysis before':>15} {'analysis now':>12} {'end-to-end before':>17} {'end-to-end now':>14}"
        )
        for (_edge, n), r in results.items():
            print(
                f"{r['beads']:>9,} {n:>5} {r['bare loop']:>13.2f} {r['before loop']:>11.2f} {r['hexdem loop']:>8.2f} "
                f"{r['before share']:>15.2f} {r['hexdem share']:>12.2f} "
                f"{r['before wall']:>17.2f} {r['wall']:>14.2f}"
            )
    for (_edge, n), r in results.items():
        limit = MANY_RANKS_SHARE_TARGET if n >= MANY_RANKS else SHARE_TARGET if n <= 2 else None
        if limit is None or (n <= 2 and r["beads"] not in SHARE_TARGET_BEADS):
            continue
        share = r["hexdem share"]
        print(
            f"target analysis share, {r['beads']:,} beads on {n} rank(s): {share:.3f} "
            f"{'<=' if share <= limit else '>'} {limit:g}: {'met' if share <= limit else 'NOT met'}"
        )
    beads, n = END_TO_END_RUN
    row = next((r for (edge, m), r in results.items() if r["beads"] == beads and m == n), None)
    if row is not None:
        bound = END_TO_END_FACTOR * row["bare loop"] + END_TO_END_OFFSET_S
        print(
            f"target end to end, {beads:,} beads on {n} ranks: {row['wall']:.2f} "
            f"{'<=' if row['wall'] <= bound else '>'} "
            f"{END_TO_END_FACTOR:g} x bare loop + {END_TO_END_OFFSET_S:g} s = {bound:.2f}: "
            f"{'met' if row['wall'] <= bound else 'NOT met'}"
        )
    for (_edge, n), r in results.items():
        if r["beads"] >= 1_000_000:
            print(
                f"target million-bead result files, {r['beads']:,} beads on {n} ranks: {r['results']:.2f} s "
                f"{'<=' if r['results'] <= MILLION_RESULTS_S else '>'} {MILLION_RESULTS_S:g} s: "
                f"{'met' if r['results'] <= MILLION_RESULTS_S else 'NOT met'}"
            )
    print(
        f"{'beads':>9} {'ranks':>5} {'largest process [MB]':>20} {'hexdem run [MB]':>15} "
        f"{'collectives':>11} {'rebuilds':>8} {'audited':>7}  peak RSS per rank [MB]"
    )
    for (_edge, n), r in results.items():
        per_rank = ", ".join(f"{rss / MB:.0f}" for rss in r["ranks rss"])
        print(
            f"{r['beads']:>9,} {n:>5} {r['largest'] / MB:>20.0f} {r['cli rss'] / MB:>15.0f} "
            f"{r['collectives']:>11} {r['rebuilds']:>8} {r['audited']:>7}  {per_rank}"
        )
    for (_edge, n), r in results.items():
        bound = r["rebuilds"] + r["audited"] + COLLECTIVES_BESIDE
        print(
            f"target collectives, {r['beads']:,} beads on {n} rank(s): {r['collectives']} "
            f"{'<=' if r['collectives'] <= bound else '>'} {bound} (rebuilds + audited + {COLLECTIVES_BESIDE}): "
            f"{'met' if r['collectives'] <= bound else 'NOT met'}"
        )
    for edge in edges:
        rising = sorted(ranks)  # (the order of --ranks is the order of the runs, not of the target)
        peaks = [max(results[edge, n]["ranks rss"]) for n in rising]
        falling = all(b < a for a, b in zip(peaks, peaks[1:]))
        print(
            f"target per-rank memory falls with ranks, {results[edge, ranks[0]]['beads']:,} beads: largest rank "
            f"{' -> '.join(f'{p / MB:.0f}' for p in peaks)} MB on {', '.join(map(str, rising))} ranks: "
            f"{'met' if falling else 'NOT met'}"
        )
    for (_edge, n), r in results.items():
        if n == ranks[0]:
            continue
        reference = results[edge, ranks[0]]["tables"]
        worst = max(table_mismatch(r["tables"][name], reference[name]) for name in TABLES)
        print(
            f"target results, {r['beads']:,} beads on {n} vs {ranks[0]} rank(s): {' and '.join(TABLES)} within "
            f"{worst:.2g} of round-off (rtol {RESULTS_RTOL:g}): {'met' if worst <= 1 else 'NOT met'}"
        )
    beads, n = MEMORY_TARGET_RUN
    row = next((r for (edge, m), r in results.items() if r["beads"] == beads and m == n), None)
    verdict = (
        "not measured (--edges 200 --ranks 8)"
        if row is None
        else f"{row['largest'] / MB:.0f} {'<=' if row['largest'] <= MEMORY_TARGET else '>'} "
        f"{MEMORY_TARGET / MB:.0f} MB: {'met' if row['largest'] <= MEMORY_TARGET else 'NOT met'}"
    )
    print(f"target largest process, {beads:,} beads on {n} ranks: {verdict}")


if __name__ == "__main__":
    main()
