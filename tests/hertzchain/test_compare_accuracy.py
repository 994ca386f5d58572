"""Accuracy of the continuum against the discrete chain, through `compare`.

Precompressed (δ0/d = 1e-3, the Eq. 4 regime): every Table-2 point (M, N, P, Q) and
Fig. 5's cases a–d on reduced chains (400 | 400 grains, the paper's settled wave placed
100 grains before the interface), continuum (corrected Eq. 4, Rosenau form, 5 nodes per
grain, the defaults) started from the same grains:

* transmitted and reflected total energy (over the incident energy) within 5e-3 of the
  discrete chain's at the comparison time (measured: at most 7e-4, case b's E_R);
* transmitted front position within 0.5 grain when the discrete front is 100 grains
  past the interface (measured: at most 0.035 grain).

δ0 = 0 (Eq. 7, regularised): the continuum is a qualitative model only; the measured
differences are pinned (reported in the reproduce report and the closing note), each to
a band of about ±25 % of its value around what was measured, wide enough for changes
of the time stepper at fixed equations and regularisation, narrow enough to catch a
change of the physics.
"""

import pytest

import theory
from hertzchain.compare import compare
from hertzchain.scenario import parse_scenario

ENERGY_TOL = 5e-3
"""|ΔE_T|, |ΔE_R| in units of the incident energy."""
FRONT_TOL = 0.5
"""|Δx| of the transmitted front, grains, 100 grains past the interface."""
N_LEFT, N_RIGHT, CENTRE = 400, 400, 300


def precompressed(point: str) -> dict:
    ar, ak = theory.PAPER_POINTS[point]
    mat = theory.PAPER_MATERIAL
    d = theory.PAPER_DIAMETER
    c0 = float(theory.c0(theory.hertz_constant(d, mat), theory.grain_mass(d, mat.density), d,
                         1e-3 * d)) / d  # grains/s
    gc = float(theory.gamma_c0(ar, ak))
    # the transmitted front 140 grains past the interface (at 95 % of its sound speed)
    t_end = (N_LEFT - CENTRE) / c0 + 140 / (0.95 * min(gc, 1.0) * c0)
    return {"name": f"accuracy-{point}",
            "chain": {"delta0_over_d": 1e-3,
                      "sections": [{"n": N_LEFT}, {"n": N_RIGHT, "alpha_rho": ar,
                                                   "alpha_kn": ak}]},
            "initial": {"kind": "cut_wave", "center": CENTRE},
            "run": {"t_end": t_end}, "models": {"continuum": "auto", "samples": 40}}


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("accuracy")


@pytest.mark.parametrize("point", ["M", "N", "P", "Q",
                                   *(pytest.param(c, marks=pytest.mark.slow) for c in "abcd")])
def test_precompressed_continuum_matches_discrete(point, cache):
    cmp = compare(parse_scenario(precompressed(point)), cache=cache)
    assert cmp.run.continuum.completed and cmp.run.continuum.summary["model"] == "eq4"
    diff = cmp.differences["continuum"]
    assert abs(diff["Et_tr"][2]) <= ENERGY_TOL, diff["Et_tr"]
    assert abs(diff["Et_re"][2]) <= ENERGY_TOL, diff["Et_re"]
    assert cmp.arrival_distance == 100
    assert abs(diff["front_at_arrival"][2]) <= FRONT_TOL, diff["front_at_arrival"]
    # and the comparison is made before any wave reaches a chain end
    assert cmp.t_compare < cmp.run.continuum.valid_until


SONIC = {
    # a solitary wave of the paper's amplitude in a uniform chain
    "mono": {"chain": {"sections": [{"n": 300}]},
             "initial": {"kind": "exact_wave", "center": 40, "velocity_max": 0.6816},
             "run": {"t_end": 1.2e-3}},
    # the paper's Fig. 3 interfaces (reduced: 400 | 250 grains)
    "fig3a": {"chain": {"sections": [{"n": 400}, {"n": 250, "alpha_rho": 0.2}]},
              "initial": {"kind": "cut_wave", "center": 300}, "run": {"t_end": 1.28e-3}},
    "fig3b": {"chain": {"sections": [{"n": 400}, {"n": 250, "alpha_rho": 5.0}]},
              "initial": {"kind": "cut_wave", "center": 300}, "run": {"t_end": 3.4e-3}},
}


def _sonic(name: str, cache):
    # Eq. 7 pinned: these pin its sonic-vacuum numbers ("auto" runs the quasi-continuum)
    data = dict(SONIC[name], name=f"sonic-{name}", models={"continuum": "eq7",
                                                          "samples": 30})
    return compare(parse_scenario(data), cache=cache)


def _rel(row) -> float:
    return row[1] / row[0] - 1.0


@pytest.mark.slow
def test_sonic_vacuum_uniform_chain(cache):
    # measured: the continuum's wave is 1.1 % slower than the discrete one (it reshapes
    # the discrete wave into its own compacton) and its grain-sampled energy 2.7 % lower;
    # Eq. 8 at the wave's peak grain velocity is 0.8 % faster than the chain
    cmp = _sonic("mono", cache)
    assert cmp.run.continuum.summary["model"] == "eq7"
    d, c = cmp.series["discrete"].speeds, cmp.series["continuum"].speeds
    assert -0.014 < c["incident"] / d["incident"] - 1 < -0.008
    assert 0.006 < cmp.differences["theory"]["speed_incident"][2] < 0.010
    assert -0.034 < cmp.differences["continuum"]["Et_re"][2] < -0.020
    # the compacton of Eq. 8 at the paper's peak velocity has a higher peak strain than
    # the exact discrete wave (the notebooks' +8 %), and a speed within 1 %
    import continuum

    mat, dd = theory.PAPER_MATERIAL, theory.PAPER_DIAMETER
    k, m = theory.hertz_constant(dd, mat), theory.grain_mass(dd, mat.density)
    w = theory.discrete_solitary_wave(k, m, dd, 0.0, velocity_max=0.6816)
    pde = continuum.NesterenkoPDE(continuum.Medium.uniform(50, 0.0), 5,
                                  delta_floor=1e-2 * w.amplitude)
    cp = continuum.compacton_parameters(pde, velocity_max=0.6816)
    assert 0.06 < cp["strain_max"] / (w.amplitude / dd) - 1 < 0.10
    assert 0.006 < cp["speed_m_s"] / w.speed - 1 < 0.010


@pytest.mark.slow
def test_sonic_vacuum_heavy_light_interface(cache):
    # α_ρ = 0.2 (Fig. 3a, fracture): the continuum's leading transmitted pulse is 1.1 %
    # slower (3.2 grains behind when the discrete one is 100 grains past the interface),
    # 3.0 % of the incident energy less is transmitted, its peak within a few %; the
    # linear theory transmits 15 % too little
    cmp = _sonic("fig3a", cache)
    c = cmp.differences["continuum"]
    assert -0.014 < c["speed_transmitted"][2] < -0.008
    assert -4.1 < c["front_at_arrival"][2] < -2.4
    assert -0.038 < c["Et_tr"][2] < -0.022
    assert -0.03 < _rel(c["peak_transmitted"]) < 0.06
    assert -0.19 < cmp.differences["theory"]["Et_tr"][2] < -0.11


@pytest.mark.slow
def test_sonic_vacuum_light_heavy_interface(cache):
    # α_ρ = 5 (Fig. 3b): the reflected wave is where the continuum fails most — 29 % less
    # reflected energy (0.26 vs 0.37 of E_in), a 32 % lower leading reflected pulse,
    # 6 % slower; the transmitted front speed agrees to 0.2 %, its energy is 0.07 high
    cmp = _sonic("fig3b", cache)
    c = cmp.differences["continuum"]
    assert -0.36 < _rel(c["Et_re"]) < -0.22
    assert -0.40 < _rel(c["peak_reflected"]) < -0.24
    assert -0.08 < c["speed_reflected"][2] < -0.048
    assert abs(c["speed_transmitted"][2]) < 0.005
    assert 0.053 < c["Et_tr"][2] < 0.09


@pytest.mark.slow
def test_table2_continuum_column_through_the_run_path(tmp_path):
    # `hertzchain reproduce table2`'s continuum column: a continuum-only run of each
    # point's scenario through hertzchain.models (same cut wave as the discrete chain),
    # read through the continuum's own conserved energy when its transmitted peak is
    # 100 grains past the interface.  Measured: within 2.06e-3 of the paper for all 24
    # ratios (N's Ek_tr: the Rosenau term's share of a wave ~5 grains wide); the old
    # path (continuum.energy_ratios, its own sech² wave) gave 1.98e-3.  Its energy is
    # conserved: Et_tr + Et_re = 1 to the stepper's drift (< 1e-5 here).
    from hertzchain.paper import TABLE2, TABLE2_KEYS
    from hertzchain.reproduce import table2
    from hertzchain.reproduce.common import Context

    ctx = Context(tmp_path, progress=False)
    s = ctx.pick(table2.QUICK, table2.FULL)
    worst = 0.0
    for point in table2.POINTS:
        got, note = table2._continuum(ctx, point, s)
        assert got is not None, note
        assert got["measured_past_interface"] == s["continuum_distance"]
        assert got["Et_tr"] + got["Et_re"] == pytest.approx(1.0, abs=1e-5)
        worst = max(worst, *(abs(got[k] - TABLE2[point][k]) for k in TABLE2_KEYS))
    assert worst < 2.5e-3
    # each point's continuum file is in runs/ and counted, like every simulation
    assert len([p for p in ctx.computed if "table2-continuum" in p.name]) == 4
