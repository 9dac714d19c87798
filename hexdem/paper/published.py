"""Every number the paper publishes that hexdem computes, as printed in the paper's text.

Sec. IV (the TCA): ω ≈ 0.382 (compatibility condition) and c ≈ 0.8452 (decay rate,
eq. (8)). Sec. V (fitted laws, nondimensional A = d = M = 1): m and b of c(V₀) = m V₀ + b
and α, β, γ of V_s/V₀ for the four strike/observation combinations, eqs. (9), (10),
(11). Each value keeps the digits it was printed with, since half a unit of its last
digit is as close as it can be compared.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Published:
    """One published number: ``item`` (where it stands), ``quantity`` (omega, c, m, b, alpha,
    beta, gamma), ``combination`` ("30/30", "30/0", "0/0", "0/30" or ""), and ``text`` as printed."""

    item: str
    quantity: str
    combination: str
    text: str

    @property
    def value(self) -> float:
        return float(self.text)

    @property
    def rounding(self) -> float:
        """Half a unit of the last printed digit."""
        decimals = len(self.text.split(".")[1]) if "." in self.text else 0
        return 0.5 * 10.0**-decimals


def _law(combination: str, equation: str, **values: str) -> list[Published]:
    return [
        Published(f"eq. ({equation}), {combination}", quantity, combination, text) for quantity, text in values.items()
    ]


#: The paper's numbers, in the order they appear.
PUBLISHED: tuple[Published, ...] = (
    Published("TCA compatibility condition (Sec. IV)", "omega", "", "0.382"),
    Published("TCA decay rate, eq. (8)", "c", "", "0.8452"),
    *_law("30/30", "9", m="0.257", b="0.832", alpha="0.206", beta="0.629"),
    *_law("30/0", "10", m="0.3039", b="0.8756", alpha="-0.4788", beta="-0.0256", gamma="0.1936"),
    *_law("0/0", "10", m="0.1766", b="0.8878", alpha="-0.2643", beta="-0.0969", gamma="0.2152"),
    *_law("0/30", "11", m="0.1484", b="0.8393", alpha="-0.1182", beta="0.0203", gamma="0.5192"),
)


def published(quantity: str, combination: str = "") -> Published:
    """The published value of ``quantity`` for ``combination``."""
    return next(p for p in PUBLISHED if p.quantity == quantity and p.combination == combination)
