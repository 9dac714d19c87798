"""The names of :mod:`hexdem.api`, which ``import hexdem`` offers and imports on first use."""

API_NAMES = (
    "RunConfig",
    "ImpactResult",
    "LineResult",
    "simulate_impact",
    "tca",
    "SweepSettings",
    "scaling_laws",
    "Posterior",
    "calibrate",
)
