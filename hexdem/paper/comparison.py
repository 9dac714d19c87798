"""Every published number beside hexdem's: the rows of ``published_vs_computed.csv``.

One row per number of :data:`~hexdem.paper.published.PUBLISHED`. ω and c come from the TCA
(:func:`hexdem.theory.tca.summary`); m, b, α, β, γ from the scaling step's ``scaling.json``,
fitted with the protocol the paper states (its start bead anchored at the measured peak,
beads up to 12, log-linear, every V₀ of the sweep). ``difference`` is computed − published;
``protocol`` says how the computed number was obtained. The protocol closest to the
published (m, b) is in ``fit_protocols.json`` and the report.
"""

from __future__ import annotations

from hexdem.paper.published import PUBLISHED

#: Columns of ``published_vs_computed.csv`` (a contract).
COMPARISON_COLUMNS = ("item", "quantity", "combination", "published", "computed", "difference", "protocol")

TCA_PROTOCOLS = {
    "omega": "TCA: real root of the compatibility condition 2 + w^(3/2) = (1/2 + 3/2 w^(3/2))/w",
    "c": "TCA: speed of beads 0 and 1 when equal, over the BCA's V0/2 (independent of V0)",
}


def comparison_rows(tca_summary: dict, scaling: dict, protocols: dict) -> list[tuple]:
    """Rows of ``published_vs_computed.csv`` from the TCA summary, ``scaling.json`` and
    ``fit_protocols.json``."""
    sweep = scaling["sweep"]
    sweep_text = (
        f"{sweep['engine']} engine, hexagon of {sweep['hexagon_edge']} per edge without walls, "
        f"V0 {min(sweep['v0']):g}..{max(sweep['v0']):g} ({len(sweep['v0'])} values)"
    )
    rows = []
    for p in PUBLISHED:
        if not p.combination:
            computed, protocol = float(tca_summary[p.quantity]), TCA_PROTOCOLS[p.quantity]
        else:
            law = scaling[p.combination]
            computed = float(law[p.quantity])
            if p.quantity in ("m", "b"):
                protocol = f"{protocols[p.combination]['stated']['description']}; {sweep_text}"
            else:
                protocol = f"least squares of V_{law['start_bead']}/V0 over every V0, law {law['law']}; {sweep_text}"
        rows.append((p.item, p.quantity, p.combination, p.value, computed, computed - p.value, protocol))
    return rows


def largest_differences(rows: list[tuple], count: int = 3) -> list[tuple]:
    """The ``count`` rows with the largest relative differences |computed/published − 1|."""
    return sorted(rows, key=lambda r: -abs(r[5] / r[3]))[:count]
