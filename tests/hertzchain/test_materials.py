"""The material library (theory.MATERIALS) and materials by name in scenarios.

Values are checked against the literature they cite where the citation gives numbers
(Daraio et al. 2005, 2006: stainless steel 316 and PTFE beads), against physical ranges
(units: a density in g/cm³ or a modulus in GPa by mistake is caught), and the ratios
against an independent computation from the grain masses and Hertz constants.
"""

from __future__ import annotations

import numpy as np
import pytest

import theory
from theory import MATERIALS, get_material, material_ratios


def test_every_material_has_units_in_range_and_a_source():
    assert len(MATERIALS) >= 10
    for key, entry in MATERIALS.items():
        m = entry.material
        assert entry.key == key and entry.source, key
        assert 500 < m.density < 25_000, key  # kg/m³ (not g/cm³)
        assert 1e8 < m.youngs_modulus < 1.2e12, key  # Pa (not GPa)
        assert 0 < m.poisson_ratio < 0.5, key


@pytest.mark.parametrize(("name", "rho", "e", "nu"), [
    ("stainless_steel_316", 8000.0, 193e9, 0.30),  # Daraio et al., PRE 73, 026610 (2006)
    ("ptfe", 2200.0, 1.46e9, 0.46),  # Daraio et al., PRE 72, 016603 (2005)
    ("paper", 7900.0, 193e9, 0.30),  # the paper's Table 1 with ν = 0.30 (physics §1)
    ("table1", 7900.0, 193e9, 0.25),  # the paper's Table 1 as printed
])
def test_literature_values(name, rho, e, nu):
    m = get_material(name)
    assert (m.density, m.youngs_modulus, m.poisson_ratio) == (rho, e, nu)


def test_aliases_and_did_you_mean():
    assert get_material("steel") is MATERIALS["stainless_steel_316"].material
    assert get_material("Teflon") is MATERIALS["ptfe"].material
    assert get_material("soda-lime glass") is MATERIALS["soda_lime_glass"].material
    with pytest.raises(ValueError, match=r"unknown material 'brss'; did you mean 'brass'"):
        get_material("brss")


@pytest.mark.parametrize("d", [2e-3, 5e-3, 19e-3])
def test_material_ratios_are_mass_and_hertz_constant_ratios(d):
    """α_ρ = m_R/m_L and α_kn = k_R/k_L at equal diameters, from grain_mass and
    hertz_constant (Johnson 1985, Eq. 4.22), for every pair of the library."""
    for left in MATERIALS.values():
        for right in MATERIALS.values():
            a_rho, a_kn = material_ratios(left.material, right.material)
            ml = theory.grain_mass(d, left.material.density)
            mr = theory.grain_mass(d, right.material.density)
            kl = theory.hertz_constant(d, left.material)
            kr = theory.hertz_constant(d, right.material)
            assert a_rho == pytest.approx(mr / ml, rel=1e-14)
            assert a_kn == pytest.approx(kr / kl, rel=1e-14)


def test_scenario_by_name_builds_the_library_material():
    """``material = "brass"`` in a section builds grains of brass: mass and contact
    constant from the library's values (independent of the scenario code)."""
    from hertzchain.runner import build_chain
    from hertzchain.scenario import parse_scenario

    sc = parse_scenario({"chain": {"material": "steel", "sections": [
        {"n": 20}, {"n": 20, "material": "brass"}]}, "run": {"t_end": 1e-4}})
    chain = build_chain(sc.chain)
    d = 5e-3
    steel, brass = get_material("steel"), get_material("brass")
    assert chain.mass[0] == pytest.approx(theory.grain_mass(d, steel.density), rel=1e-14)
    assert chain.mass[-1] == pytest.approx(theory.grain_mass(d, brass.density), rel=1e-14)
    assert chain.k[5] == pytest.approx(theory.hertz_constant(d, steel), rel=1e-14)
    assert chain.k[35] == pytest.approx(theory.hertz_constant(d, brass), rel=1e-14)
    # the interface contact: steel against brass (Johnson's E*)
    assert chain.k[20] == pytest.approx(theory.hertz_constant(d, steel, d, brass), rel=1e-14)
    a_rho, a_kn = material_ratios(steel, brass)
    assert chain.mass[-1] / chain.mass[0] == pytest.approx(a_rho, rel=1e-14)
    assert chain.k[35] / chain.k[5] == pytest.approx(a_kn, rel=1e-14)
    # the values are recorded with the run, under their name
    assert sc.chain.sections[1].material["name"] == "brass"
    assert sc.to_input()["chain"]["material"]["youngs_modulus"] == 193e9


def test_paper_materials_keep_their_names():
    from hertzchain.scenario import parse_scenario

    for name in ("paper", "table1"):
        sc = parse_scenario({"chain": {"material": name, "sections": [{"n": 10}]},
                             "run": {"t_end": 1e-4}})
        assert sc.chain.material == name


def test_material_table_names_units_when_incomplete():
    from hertzchain.scenario import ScenarioError, parse_scenario

    with pytest.raises(ScenarioError, match=r"youngs_modulus \(Pa\) is required"):
        parse_scenario({"chain": {"material": {"density": 7800, "poisson_ratio": 0.3},
                                  "sections": [{"n": 10}]}, "run": {"t_end": 1e-4}})
    sc = parse_scenario({"chain": {"material": {"name": "my steel", "density": 7800,
                                                "youngs_modulus": 2e11,
                                                "poisson_ratio": 0.3},
                                   "sections": [{"n": 10}]}, "run": {"t_end": 1e-4}})
    assert sc.chain.material["name"] == "my steel"


def test_scenario_docs_give_the_units():
    import hertzchain.scenario as S

    doc = S.__doc__ + S.schema_reference()
    assert "kg/m³" in doc and "youngs_modulus (Pa)" in doc
    assert np.isclose(get_material("glass").density, 2500.0)
