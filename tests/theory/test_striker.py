"""A heavy striker's solitary-wave train (theory.striker) against the discrete chain."""

import numpy as np
import pytest

import theory
from discrete import Chain, Recording, Section, WaveAt
from discrete.initial import impact
from discrete.waves import split_train
from theory import striker as St

STEEL, D = theory.PAPER_MATERIAL, theory.PAPER_DIAMETER


def test_model_obeys_both_conservation_laws():
    # Σ C_E m v_j² = ½ M v0² and Σ C_P m v_j = M v0 for the infinite geometric train, to
    # rounding; r = C_P²/(2 C_E) is the one-wave limit (ρ = 0), where v_1 =
    # √(r/(2 C_E)) v0 = v0 r/C_P; as r → ∞, v_1 → (C_P/C_E) v0.
    c = theory.sonic_vacuum_wave_constants()
    for r in (2.0, 8.0, 100.0):
        t = St.striker_train(r, 0.7)
        v = t.velocities(4000)
        assert c.energy * np.sum(v**2) == pytest.approx(0.5 * r * 0.49, rel=1e-12)
        assert c.momentum * np.sum(v) == pytest.approx(r * 0.7, rel=1e-12)
        assert t.energy_fraction == pytest.approx(c.energy * v[0] ** 2 / (0.5 * r * 0.49))
    r1 = c.momentum**2 / (2 * c.energy)
    t = St.striker_train(r1)
    assert t.ratio == pytest.approx(0.0, abs=1e-15)
    assert t.velocity_max == pytest.approx(np.sqrt(r1 / (2 * c.energy)), rel=1e-14)
    assert St.striker_train(1e9).velocity_max == pytest.approx(c.momentum / c.energy, rel=1e-8)
    assert St.striker_train(1.0).count_above(0.05) == 1


def _train(r):
    ch = Chain.from_sections([Section(600, D, STEEL)], right_wall=None)
    sim = impact(ch, 1.0, striker_mass=r * ch.mass[0]).simulation(
        record=Recording(monitor_every=10**6))
    sim.run(until=WaveAt(550), progress=False)
    waves = split_train(sim, threshold=0.01)
    return np.array([w.velocity_max for w in waves][::-1]), float(np.asarray(sim.v)[0])


@pytest.mark.parametrize("r, lead, count", [(1, 0.0056, 2), (2, 0.0029, 2), (4, 0.0300, 5),
                                            (8, 0.0734, 9), (16, 0.1221, 18)])
def test_striker_train_against_the_discrete_chain(r, lead, count):
    # A striker of r grain masses at 1 m/s on 600 uncompressed steel grains, the train
    # split when the leading wave reaches grain 550 (discrete.waves.split_train: each
    # wave's v_max is that of the exact wave of its energy, independent of its phase).
    # Measured, leading v_max over the model's minus 1 (`lead`): +0.56, +0.29, +3.0, +7.3,
    # +12.2 % (tolerance ±0.3 % about each; the model is exact for a geometric train and
    # the real head of the train is larger than geometric); number of waves above 5 % of
    # the leading one (`count`) against count_above(0.05): 2/1, 2/2, 5/5, 9/10, 18/19
    # (within one); the striker ends at ≤ 0.24 % of v0 (the model's assumption; 0.5 %);
    # the ratio of successive amplitudes rises along the train towards ρ: for r = 8 and
    # 16, 0.7216 and 0.8391 between the 8th and 9th waves against ρ = 0.7197 and 0.8493
    # (tolerance 1.5 %).
    v, striker = _train(r)
    model = St.striker_train(r)
    assert v[0] / model.velocity_max - 1 == pytest.approx(lead, abs=0.003)
    assert v[0] > model.velocity_max
    assert np.sum(v > 0.05 * v[0]) == count
    assert abs(model.count_above(0.05) - count) <= 1
    assert abs(striker) < 0.005
    if r >= 8:
        ratios = v[1:9] / v[:8]
        assert np.all(np.diff(ratios) > 0)
        assert ratios[-1] == pytest.approx(model.ratio, rel=0.015)


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="mass_ratio"):
        St.striker_train(0.5)
    with pytest.raises(ValueError, match="v0"):
        St.striker_train(2.0, 0.0)
    with pytest.raises(ValueError, match="fraction"):
        St.striker_train(4.0).count_above(1.5)
    with pytest.raises(ValueError, match="count"):
        St.striker_train(4.0).velocities(0)
