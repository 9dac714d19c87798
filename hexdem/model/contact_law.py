"""Contact laws as data: what every contact of a model does, read alike by both engines.

A law is made of sub-models, in the spirit of LAMMPS's ``pair_style granular``:

* normal: Hertz, F_n = k_n sqrt(R_eff δ) δ with k_n = (4/3) E* (:func:`~hexdem.model.materials.hertz_stiffness`),
  plus Tsuji's damping α (:mod:`hexdem.model.dissipation`; 0: undamped);
* tangential: Mindlin's no-slip stiffness with history (Mindlin, J. Appl. Mech. 16, 259 (1949)),
  F_t = −k_t a ξ with k_t = 8 G*, G* = 1/((2 − ν₁)/G₁ + (2 − ν₂)/G₂), a = sqrt(R_eff δ) the contact
  radius and ξ the tangential displacement of the contact points accumulated while the bodies
  touch (kept in the tangent plane as the contact turns), capped by Coulomb's |F_t| ≤ μ |F_n|: on
  slip, ξ is set back to the displacement whose force is the cap (LAMMPS's ``tangential mindlin``);
  none when μ = 0 (the paper's frictionless spheres, which never rotate);
* rolling: rolling resistance μ_r (0: none).

The bead–bead laws depend on the pair's materials, the bead–wall laws on the bead's material and
the wall's (each contact with its own E* and G*: LAMMPS issue 4141).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from hexdem.common.checks import is_number
from hexdem.errors import HexdemError
from hexdem.model.materials import Material, hertz_stiffness, mindlin_stiffness


@dataclass(frozen=True)
class Friction:
    """The frictional parameters of a model: Coulomb μ between bodies (``friction``) and against
    the walls (``wall_friction``), and the rolling-resistance coefficient ``rolling_friction``.
    All 0: frictionless spheres without rotation."""

    friction: float = 0.0
    wall_friction: float = 0.0
    rolling_friction: float = 0.0

    def __post_init__(self):
        for field in fields(self):
            value = getattr(self, field.name)
            if not (is_number(value) and value >= 0):
                raise HexdemError(f"{field.name} must be a coefficient >= 0, got {value!r}")
        if self.rolling_friction > 0 and self.friction == 0:
            raise HexdemError("rolling_friction needs friction > 0 (rolling resistance acts on frictional contacts)")
        if self.rolling_friction > 0:
            raise HexdemError("rolling_friction > 0 is not modelled yet: leave it at 0")

    @classmethod
    def of(cls, friction, wall_friction, rolling_friction) -> Friction:
        """The configuration keys' friction, ``wall_friction`` None meaning ``friction``."""
        return cls(friction, friction if wall_friction is None else wall_friction, rolling_friction)


NO_FRICTION = Friction()


@dataclass(frozen=True)
class ContactLaw:
    """One kind of contact (see the module docstring): ``normal_stiffness_pa`` k_n = (4/3) E* [Pa],
    ``damping`` Tsuji's α, ``tangential_stiffness_pa`` Mindlin's k_t = 8 G* [Pa] (the force is
    k_t a ξ), ``friction`` μ (0: no tangential force), ``rolling_friction`` μ_r."""

    normal_stiffness_pa: float
    damping: float
    tangential_stiffness_pa: float
    friction: float
    rolling_friction: float

    @property
    def tangential(self) -> bool:
        """Whether the contact has a tangential force (and turns the bodies)."""
        return self.friction > 0.0


def contact_law(a: Material, b: Material, damping: float, friction: float, rolling_friction: float) -> ContactLaw:
    """The law of a contact between bodies of materials ``a`` and ``b``."""
    return ContactLaw(hertz_stiffness(a, b), damping, mindlin_stiffness(a, b), friction, rolling_friction)


@dataclass(frozen=True)
class ContactLaws:
    """Every law of a model: ``pairs`` (K × K) between its materials by id, ``walls`` (K) of each
    material against the wall (empty without walls)."""

    pairs: tuple[tuple[ContactLaw, ...], ...]
    walls: tuple[ContactLaw, ...]

    @classmethod
    def of(
        cls,
        materials,
        wall: Material | None,
        pair_damping: float,
        wall_damping: float,
        friction: Friction = NO_FRICTION,
    ) -> ContactLaws:
        """The laws of bodies of ``materials`` (by id) touching each other and the ``wall``."""
        pairs = tuple(
            tuple(contact_law(a, b, pair_damping, friction.friction, friction.rolling_friction) for b in materials)
            for a in materials
        )
        walls = (
            ()
            if wall is None
            else tuple(
                contact_law(a, wall, wall_damping, friction.wall_friction, friction.rolling_friction) for a in materials
            )
        )
        return cls(pairs, walls)

    @property
    def tangential(self) -> bool:
        """Whether any contact has a tangential force: the bodies then rotate."""
        return any(law.tangential for law in (*self.walls, *(law for row in self.pairs for law in row)))

    def pair_table(self, name: str) -> np.ndarray:
        """(K, K) the parameter ``name`` of every pair of materials."""
        return np.array([[getattr(law, name) for law in row] for row in self.pairs], dtype=float)

    def wall_table(self, name: str) -> np.ndarray:
        """(K,) the parameter ``name`` of each material's contact with the wall."""
        return np.array([getattr(law, name) for law in self.walls], dtype=float)
