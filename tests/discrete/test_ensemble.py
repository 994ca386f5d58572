"""The ensemble kernel: bit for bit the single-chain runs, a NumPy reference, statistics.

``discrete.ensemble.run_ensemble`` integrates many realisations together in the batch
kernel (grains × realisations).  Every realisation must end exactly where
``Simulation.run`` ends it (state, running maxima, energy: ``array_equal``, no
tolerance), whatever the batch size and order; the times of the maxima (which the
single runs do not record) must not depend on the batch, and agree with a plain NumPy
loop over ``discrete.integrators.step``; the statistics must be NumPy's.
"""

import warnings

import numpy as np
import pytest

import discrete
import theory
from discrete import Chain, Disorder, Recording, Section
from discrete.ensemble import (
    amplitude_decay,
    ensemble_statistics,
    nanquantiles,
    reference_ensemble,
    run_ensemble,
)
from discrete.initial import impact

STEEL = theory.Material(7800.0, 2e11, 0.3)


def _sims(seeds, n=60, *, delta0=5e-6, v0=0.1, law=None, integrator="verlet",
          left_wall="paper"):
    out = []
    for s in seeds:
        sec = Section(n, 5e-3, STEEL, disorder=Disorder(mass=0.09, stiffness=0.05, seed=s))
        chain = Chain.from_sections([sec], delta0=delta0, left_wall=left_wall,
                                    exponent=1.5 if law is None else law.exponent)
        out.append(impact(chain, v0).simulation(record=Recording(maxima=True), law=law,
                                                integrator=integrator))
    return out


def _t_end(sims, steps=400):
    return steps * min(s.dt for s in sims)


@pytest.mark.parametrize("kw", [
    {},  # precompressed impact, velocity Verlet
    {"delta0": 0.0, "left_wall": None},  # sonic vacuum, a free left end: gaps open
    {"integrator": "blanes_moan4"},  # a 4-stage method
])
def test_bitwise_equal_to_single_runs(kw):
    sims = _sims(range(5), **kw)
    t_end = _t_end(sims)
    res = run_ensemble(sims, t_end, batch=3)  # two batches, uneven
    assert len(set(res.steps.tolist())) > 1  # own time steps: different step counts
    for q, sim in enumerate(_sims(range(5), **kw)):
        e0 = sim.energy()
        sim.run(t_end, progress=False)
        assert res.steps[q] == sim.steps and res.t[q] == sim.t
        for name in ("u", "v", "a"):
            assert np.array_equal(getattr(res, name)[q], getattr(sim, name)), name
        assert np.array_equal(res.vmax[q], sim.record.vmax)
        assert res.energy0[q] == e0 and res.energy[q] == sim.energy()
    assert np.all(res.vmax[:, -1] >= 0)


def _moved_sims(seeds, n=50, window=True):
    """States that start away from the struck end: a pulse in the middle (grains 20-24
    moving left and right), some with the right wall pushed in (its contact out of
    equilibrium from the start), so the kernel's front starts inside the chain."""
    out = []
    for s in seeds:
        sec = Section(n, 5e-3, STEEL, disorder=Disorder(mass=0.09, stiffness=0.05, seed=s))
        chain = Chain.from_sections([sec], delta0=5e-6)
        v = np.zeros(n)
        v[20:25] = 0.05 * np.array([1.0, -0.5, 0.7, 0.0, 0.3])
        wr = -2e-7 if s % 2 else 0.0
        out.append(discrete.Simulation(chain, np.zeros(n), v, wall_right=wr,
                                       record=Recording(maxima=True),
                                       active_window=window))
    return out


def test_front_and_times_variants_bitwise():
    """The front (grains right of it inert) and the variant without the times of the
    maxima change no bit: same final state and maxima as whole-chain single runs."""
    sims = _moved_sims(range(4))
    t_end = _t_end(sims, 500)
    with_t = run_ensemble(sims, t_end, times=True)
    without = run_ensemble(sims, t_end)
    assert without.vmax_time is None
    for name in ("u", "v", "a", "vmax", "energy"):
        assert np.array_equal(getattr(with_t, name), getattr(without, name)), name
    for q, sim in enumerate(_moved_sims(range(4), window=False)):
        sim.run(t_end, progress=False)
        for name in ("u", "v", "a"):
            assert np.array_equal(getattr(without, name)[q], getattr(sim, name)), name
        assert np.array_equal(without.vmax[q], sim.record.vmax)
    # the pushed-in right wall moves the last grain from the start
    assert without.v[1, -1] != 0.0 and with_t.vmax_time[1, -1] > 0


def test_batches_do_not_interact():
    """The same realisations in any batch size give the same bits (times included)."""
    sims = _sims(range(7))
    t_end = _t_end(sims, 300)
    whole = run_ensemble(sims, t_end, batch=7, times=True)
    for b in (1, 2, 4):
        part = run_ensemble(sims, t_end, batch=b, times=True)
        for name in ("u", "v", "a", "vmax", "vmax_time", "energy"):
            assert np.array_equal(getattr(part, name), getattr(whole, name)), (b, name)
    one = run_ensemble(sims[4:5], t_end, times=True)
    assert np.array_equal(one.vmax_time[0], whole.vmax_time[4])


def test_against_numpy_reference():
    """The plain NumPy loop (another force arithmetic): equal to round-off.

    Tolerances: 1e-12 of the largest value for u, v, vmax (a few hundred steps of
    round-off ~1e-16 each); the times of the maxima exactly where the maximum is
    well above the round-off of the velocities (1e-6 of the largest), since there a
    one-ulp difference cannot move the step that raised it.
    """
    sims = _sims(range(3), n=40)
    t_end = _t_end(sims, 3000)
    res = run_ensemble(sims, t_end, times=True)
    ref = reference_ensemble(sims, t_end)
    assert np.array_equal(res.steps, ref.steps)
    for name in ("u", "v", "vmax"):
        x, y = getattr(res, name), getattr(ref, name)
        assert np.max(np.abs(x - y)) <= 1e-12 * np.max(np.abs(y)), name
    big = ref.vmax > 1e-6 * ref.vmax.max()
    assert big.sum() > 20
    assert np.array_equal(res.vmax_time[big], ref.vmax_time[big])
    # the peak time is when the pulse passes: increasing along the chain (grain 0, the
    # struck one, has its maximum at the start)
    assert res.vmax_time[0, 0] == 0.0 and np.all(np.diff(res.vmax_time[0, 1:12]) > 0)


def test_bad_input():
    sims = _sims(range(2))
    with pytest.raises(ValueError, match="one size"):
        run_ensemble(sims + _sims([3], n=61), 1e-6)
    with pytest.raises(ValueError, match="batch"):
        run_ensemble(sims, 1e-6, batch=0)
    with pytest.raises(ValueError, match="non-empty"):
        run_ensemble([], 1e-6)
    rec = _sims([0])[0]
    rec.run(rec.dt, progress=False)
    with pytest.raises(ValueError, match="freshly built"):
        run_ensemble([rec], 1e-6)
    # a state that is not finite at the end raises (never a silent NaN result)
    blown = _sims(range(3))
    blown[1].v[3] = np.inf  # (after the constructor's checks)
    with pytest.raises(discrete.InstabilityError, match=r"sims\[1\]"):
        run_ensemble(blown, _t_end(blown, 50))


def test_amplitude_decay_exact():
    """An exactly exponential profile gives its rate; none gives 0, an unreached grain NaN."""
    i = np.arange(50)
    a = np.stack([2.0 * np.exp(-(i - 5) / 17.0), np.ones(50), np.r_[np.ones(49), 0.0]])
    rate, a0 = amplitude_decay(a, 5)
    assert rate[0] == pytest.approx(1 / 17.0, rel=1e-12)
    assert a0[0] == pytest.approx(2.0, rel=1e-12)
    assert rate[1] == 0.0 and np.isnan(rate[2])
    with pytest.raises(ValueError, match="first"):
        amplitude_decay(a, 49, 49)


def test_statistics_equal_numpy():
    rng = np.random.default_rng(3)
    x = rng.lognormal(size=(200, 4))
    x[5, 1] = np.nan
    st = ensemble_statistics(x, n_boot=50, seed=1)
    col = x[:, 1][np.isfinite(x[:, 1])]
    assert st["n"][1] == 199 and st["n"][0] == 200
    assert st["mean"][1] == pytest.approx(np.mean(col), rel=1e-14)
    assert st["std"][0] == pytest.approx(np.std(x[:, 0], ddof=1), rel=1e-14)
    assert st["sem"][0] == pytest.approx(np.std(x[:, 0], ddof=1) / np.sqrt(200), rel=1e-14)
    assert st["q50"][2] == pytest.approx(np.median(x[:, 2]), rel=1e-14)
    assert st["q95"][3] == pytest.approx(np.quantile(x[:, 3], 0.95), rel=1e-14)
    # bootstrap error of the median: NumPy's own resampling with the same generator
    pick = np.random.default_rng(1).integers(0, 200, size=(50, 200))
    boot = np.quantile(x[pick, 0], 0.5, axis=1)
    assert st["q50_err"][0] == pytest.approx(np.std(boot, ddof=1), rel=1e-12)
    # the median's bootstrap error is of the order of the mean's standard error
    assert 0.3 < st["q50_err"][0] / st["sem"][0] < 3
    with pytest.raises(ValueError, match="quantiles"):
        ensemble_statistics(x, quantiles=(1.5,))


@pytest.mark.parametrize("shape", [(7,), (1,), (40, 6), (13, 5, 3)])
def test_nanquantiles_bitwise_numpy(shape):
    """nanquantiles is np.nanquantile(axis=0) bit for bit: NaNs anywhere, all-NaN
    columns (NaN), ties, one value, quantiles at the ends and between the points."""
    rng = np.random.default_rng(len(shape))
    x = np.round(rng.normal(size=shape), 1)  # ties
    x[rng.random(shape) < 0.2] = np.nan
    if x.ndim > 1:
        x[:, 0] = np.nan
    qs = (0.0, 0.05, 0.25, 0.5, 0.75, 0.95, 1.0, 1 / 3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # NumPy's all-NaN slice warning
        ref = np.nanquantile(x, qs, axis=0)
    got = nanquantiles(x, qs)
    assert got.shape == ref.shape
    assert np.array_equal(got, ref, equal_nan=True)
