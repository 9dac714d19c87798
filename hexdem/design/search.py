"""The search over sets of N sensors among the candidates, at each striker speed.

Where the sets number at most :data:`EXHAUSTIVE_LIMIT`, every one is scored. Otherwise a greedy
start (each sensor added where it gains the most) is improved by exchange (Fedorov's): each
sensor in turn is swapped for the candidate that raises the criterion most, until a whole pass
improves nothing. Exchange finds a set that no single swap improves; a better set that differs in
two sensors or more at once can be missed. Every set scored on the way is kept for the ranking.
"""

from __future__ import annotations

from itertools import combinations
from math import comb

#: The most sets of N sensors that are all scored.
EXHAUSTIVE_LIMIT = 20_000
#: Exchange passes at most (each ends where no swap helps).
EXCHANGE_PASSES = 10


def search(score, candidates: int, sensors: int) -> tuple[str, dict[tuple[int, ...], float]]:
    """(how it searched, {sorted set of candidate indices: criterion}) of ``score`` (a set →
    criterion) over sets of ``sensors`` among ``candidates``."""
    if comb(candidates, sensors) <= EXHAUSTIVE_LIMIT:
        return "exhaustive", {design: score(design) for design in combinations(range(candidates), sensors)}
    scored: dict[tuple[int, ...], float] = {}

    def value(design) -> float:
        design = tuple(sorted(design))
        if design not in scored:
            scored[design] = score(design)
        return scored[design]

    chosen: list[int] = []
    for _ in range(sensors):
        best = max((c for c in range(candidates) if c not in chosen), key=lambda c: value([*chosen, c]))
        chosen.append(best)
    for _ in range(EXCHANGE_PASSES):
        improved = False
        for position in range(sensors):
            others = chosen[:position] + chosen[position + 1 :]
            best = max((c for c in range(candidates) if c not in others), key=lambda c: value([*others, c]))
            if value([*others, best]) > value(chosen) + 1e-12:
                chosen, improved = [*others, best], True
        if not improved:
            break
    return "greedy and exchange", scored
