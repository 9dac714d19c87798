"""The contact law as data (hexdem.model.contact_law): its Mindlin stiffness, the friction keys'
contract and bad input, and how the LAMMPS deck renders it."""

from dataclasses import replace

import numpy as np
import pytest

from hexdem.engines.lammps.deck import DECK_NAME, pair_block, render_input
from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.contact_law import ContactLaws, Friction
from hexdem.model.materials import BRASS, DELRIN, STEEL_316, hertz_stiffness, mindlin_stiffness
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings
from hexdem.model.units import SI


def test_mindlin_over_hertz_stiffness_of_like_spheres_is_2_1_minus_nu_over_2_minus_nu():
    # dF_t/dξ = 8 G* a against dF_n/dδ = 2 E* a; for one material G* = G/(2(2 − ν)),
    # E* = E/(2(1 − ν²)), G = E/(2(1 + ν)), so the ratio is 4 G*/E* = 2(1 − ν)/(2 − ν)
    nu = STEEL_316.poisson_ratio
    ratio = (mindlin_stiffness(STEEL_316, STEEL_316) / 4) / (0.75 * hertz_stiffness(STEEL_316, STEEL_316) / 2)
    assert ratio == pytest.approx(2 * (1 - nu) / (2 - nu), rel=1e-14)
    assert ratio == pytest.approx(0.82, abs=0.01)  # the figure for steel


def test_mindlin_stiffness_of_unlike_materials_adds_compliances():
    def shear_compliance(m):
        g = m.youngs_modulus_pa / (2 * (1 + m.poisson_ratio))
        return (2 - m.poisson_ratio) / g

    expected = 8 / (shear_compliance(STEEL_316) + shear_compliance(DELRIN))
    assert mindlin_stiffness(STEEL_316, DELRIN) == pytest.approx(expected, rel=1e-14)
    assert mindlin_stiffness(DELRIN, STEEL_316) == mindlin_stiffness(STEEL_316, DELRIN)


def test_laws_of_pairs_and_walls_carry_each_contacts_own_moduli_and_mu():
    laws = ContactLaws.of((STEEL_316, BRASS), DELRIN, 0.0, 0.0, Friction(0.3, 0.5))
    assert laws.tangential
    np.testing.assert_array_equal(laws.pair_table("friction"), np.full((2, 2), 0.3))
    np.testing.assert_array_equal(laws.wall_table("friction"), [0.5, 0.5])
    assert laws.pair_table("tangential_stiffness_pa")[0, 1] == mindlin_stiffness(STEEL_316, BRASS)
    assert laws.wall_table("tangential_stiffness_pa")[1] == mindlin_stiffness(BRASS, DELRIN)
    assert not ContactLaws.of((STEEL_316,), DELRIN, 0.0, 0.0).tangential


def test_config_friction_keys_default_to_the_frictionless_model_and_wall_friction_to_friction():
    assert build_model(RunConfig(edge_beads=3)).friction == Friction()
    assert build_model(RunConfig(edge_beads=3, friction=0.2)).friction == Friction(0.2, 0.2)
    assert build_model(RunConfig(edge_beads=3, friction=0.2, wall_friction=0.0)).friction == Friction(0.2, 0.0)


@pytest.mark.parametrize(
    "keys, message",
    [
        ({"friction": -0.1}, "friction must be a coefficient >= 0"),
        ({"friction": "rough"}, "friction must be a number, got 'rough'"),
        ({"friction": float("nan")}, "friction must be a number, got nan"),
        ({"friction": True}, "friction must be a number, got True"),
        ({"friction": 0.3, "wall_friction": -1}, "wall_friction must be a coefficient >= 0"),
        ({"rolling_friction": 0.01}, "rolling_friction needs friction > 0"),
        ({"rolling_friction": -0.01}, "rolling_friction must be a coefficient >= 0"),
    ],
)
def test_bad_friction_is_refused_in_one_line(keys, message):
    with pytest.raises(HexdemError, match=message) as error:
        RunConfig(edge_beads=3, **keys)
    assert "\n" not in str(error.value)


def test_frictionless_decks_keep_fix_nve_and_no_tangential_force():
    config = RunConfig(edge_beads=3)
    model = build_model(config)
    deck = render_input(model, run_settings(config, model))
    assert "fix             integrate all nve\n" in deck
    assert "mindlin" not in deck and deck.count("tangential linear_nohistory 0.0 0.0") == len(model.walls)


def test_frictional_deck_gives_every_contact_its_own_mindlin_law_and_turns_the_spheres():
    config = RunConfig(edge_beads=4, impact="striker", striker_material="brass", friction=0.3, wall_friction=0.5)
    model = build_model(config)
    deck = render_input(model, run_settings(config, model))
    assert "fix             integrate all nve/sphere\n" in deck and "enforce2d" in deck
    pairs = [line.split() for line in pair_block(model, SI).splitlines() if line.startswith("pair_coeff")]
    kinds = {"1": STEEL_316, "2": BRASS}
    assert len(pairs) == 3
    for words in pairs:
        k_t = mindlin_stiffness(kinds[words[1]], kinds[words[2]])
        assert words[9:13] == ["mindlin", repr(k_t), "0.0", "0.3"]
    walls = [line.split() for line in deck.splitlines() if "wall/gran/region" in line]
    assert len(walls) == len(model.walls)
    for words in walls:
        assert words[words.index("mindlin") + 1 : words.index("mindlin") + 4] == [
            repr(mindlin_stiffness(STEEL_316, DELRIN)),
            "0.0",
            "0.5",
        ]


def test_one_material_with_friction_takes_one_pair_coeff():
    model = replace(build_model(RunConfig(edge_beads=3)), friction=Friction(0.25, 0.25))
    block = pair_block(model, SI)
    assert block.startswith("pair_style      granular\npair_coeff      * * hertz")
    assert block.endswith(f"tangential mindlin {mindlin_stiffness(STEEL_316, STEEL_316)!r} 0.0 0.25")


def test_settle_decks_turn_frictional_spheres_too(tmp_path):
    """The disorder preparation's decks integrate with the same rule as the impact's."""
    from hexdem.disorder.preparation import Preparation, write_stage_deck

    for friction, integrator in ((0.0, "nve"), (0.3, "nve/sphere")):
        model = build_model(RunConfig(edge_beads=3, friction=friction))
        deck = (write_stage_deck(model, "settle", Preparation(), tmp_path / str(friction)) / DECK_NAME).read_text()
        assert f"fix             integrate all {integrator}\n" in deck
        assert ("tangential mindlin" in deck) == (friction > 0)
