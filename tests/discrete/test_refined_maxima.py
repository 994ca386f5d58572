"""Refined maxima: between the steps, at the integrator's order.

``record.vmax`` stays the largest *sampled* velocity (what the figures read, O(h²) off
the true maximum); ``record.vmax_refined`` is the maximum of the cubic Hermite
interpolant of (v, a) between the steps (discrete.kernels, "Refined maxima").  These
tests check the kernel's gated search against an exhaustive plain-NumPy reference, the
convergence orders, the one-step-back search, and the record's consistency check.
"""

import math

import numpy as np
import pytest

import theory
from discrete import Chain, Recording, Section, integrators
from discrete import reference as R
from discrete.initial import exact_wave, impact
from discrete.interpolation import hermite_max, hermite_max_from
from discrete.recording import Record

MAT = theory.PAPER_MATERIAL
D = 5e-3
REFINED = Recording(maxima=True, refined_maxima=True)


def _impact(n=100):
    return impact(Chain.from_sections([Section(n, D, MAT)], delta0=0.0), 1.0)


@pytest.mark.parametrize("integrator,factor", [("verlet", 2.0), ("blanes_moan4", 4.0),
                                               ("yoshida4", 2.0)])
def test_kernel_matches_numpy_reference(integrator, factor):
    # The kernel searches only the steps beside a grain's largest samples; the reference
    # searches every step of every grain.  Same trajectory up to rounding (the kernels
    # subtract the static force, here 0, and fuse the passes): measured differences
    # ≤ 1e-15 m/s for the samples and the refined values after 1,200 steps; 1e-13 m/s
    # (v0 = 1 m/s) leaves room for rounding, not for a missed step (the refined values
    # exceed the samples by 1e-6 .. 1e-3 m/s at these steps).  Times: 1e-9 of a step
    # (measured 7e-13).
    init = _impact()
    dt = init.simulation(integrator=integrator).dt * factor
    sim = init.simulation(integrator=integrator, dt=dt, check_dt=False, record=REFINED)
    nsteps = 1200
    sim.run(max_steps=nsteps, progress=False)
    vm, vr, tr = integrators.refined_maxima(init.chain, init.u, init.v, dt, nsteps,
                                            integrator=integrator)
    rec = sim.record
    assert np.max(np.abs(rec.vmax - vm)) <= 1e-13
    # grains whose peak has passed (a grain still rising holds a pending search)
    done = (sim.v < 0.5 * vr) & (vr > 0.01)
    assert done.sum() >= 10
    assert np.max(np.abs(rec.vmax_refined - vr)[done]) <= 1e-13
    assert np.max(np.abs(rec.vmax_time - tr)[done]) <= 1e-9 * dt
    assert np.max((vr - vm)[done]) > 1e-6  # the refinement is not a no-op here
    assert np.all(rec.vmax_refined >= rec.vmax)


def _solitary():
    chain = Chain.from_sections([Section(300, D, MAT)], delta0=1e-3 * D,
                                left_wall="paper", right_wall="paper")
    return exact_wave(chain, 40, strain_max=5e-4)


@pytest.mark.parametrize("integrator,refined_order", [("blanes_moan4", 4.0),
                                                      ("yoshida4", 4.0), ("verlet", 2.0)])
def test_refined_maxima_converge_at_the_integrators_order(integrator, refined_order):
    # A solitary wave on a precompressed chain (smooth forces: the methods reach their
    # order; δ0 = 0 impacts limit every method to ~2.5 by contacts closing from zero
    # overlap).  Errors against a run at 1/4 of the finest step (its error is 4^-p of
    # the finest's), over the grains the peak has passed.  Measured orders: refined 4.00,
    # 4.00 / 4.00, 4.00 (BM4 / Yoshida-4), 2.00, 2.00 (Verlet); sampled 1.97-2.05.
    # Bounds ±0.35 around the order: a missed step would leave O(h²) (order 2), a
    # wrong derivative O(h³).
    init = _solitary()
    dt0 = init.simulation(integrator=integrator).dt
    t_end = 8e-4

    def run(dt):
        sim = init.simulation(integrator=integrator, dt=dt, check_dt=False, record=REFINED)
        sim.run(t_end=t_end, progress=False)
        return sim

    ref = run(dt0 / 4)
    vr = ref.record.vmax_refined
    done = (ref.v < 0.5 * vr) & (vr > 0.1 * vr.max())
    done[:60] = False  # away from the initial wave's grains
    assert done.sum() > 80
    err_s, err_r = [], []
    for f in (4.0, 2.0, 1.0):
        rec = run(dt0 * f).record
        err_s.append(np.max(np.abs(rec.vmax - vr)[done]))
        err_r.append(np.max(np.abs(rec.vmax_refined - vr)[done]))
    orders_s = [math.log2(err_s[i] / err_s[i + 1]) for i in range(2)]
    orders_r = [math.log2(err_r[i] / err_r[i + 1]) for i in range(2)]
    assert all(1.8 <= p <= 2.2 for p in orders_s), orders_s
    assert all(abs(p - refined_order) <= 0.35 for p in orders_r), orders_r
    if refined_order == 4.0:  # at the default step: measured 7e-3 (Yoshida-4's larger
        assert err_r[-1] < 2e-2 * err_s[-1]  # error constant), BM4 far less


def test_hermite_max_one_step_back_is_exact_for_cubics():
    # The interpolant is exact for a cubic; a maximum in the step *before* the data's
    # interval (s in (-1, 0)) is found with s_lo = -1, and only then.
    def cubic(t):
        return -(t + 0.4) ** 2 * (1.0 + 0.3 * t) + 2.0  # maximum near t = -0.4

    def dcubic(t):
        return -2.0 * (t + 0.4) * (1.0 + 0.3 * t) - 0.3 * (t + 0.4) ** 2

    h = 1.0
    s, val = hermite_max_from(h, cubic(0.0), cubic(1.0), dcubic(0.0), dcubic(1.0), -1.0)
    ts = np.linspace(-1.0, 1.0, 200_001)
    assert abs(val - np.max(cubic(ts))) <= 1e-12
    assert abs(s - ts[np.argmax(cubic(ts))]) <= 1e-5
    s0, val0 = hermite_max(h, cubic(0.0), cubic(1.0), dcubic(0.0), dcubic(1.0))
    assert s0 == 0.0 and val0 == cubic(0.0)  # [0, 1] alone: the left end
    # the NumPy reference agrees with the compiled one on random cubics
    rng = np.random.default_rng(1)
    y0, y1, d0, d1 = rng.normal(size=(4, 2000))
    s_ref, v_ref = R.hermite_max(0.7, y0, y1, d0, d1)
    got = np.array([hermite_max(0.7, *x) for x in zip(y0, y1, d0, d1, strict=True)])
    assert np.max(np.abs(got[:, 1] - v_ref)) <= 1e-12


def test_record_check_rejects_inconsistent_refined_maxima():
    rec = Record(series_grains=np.zeros(0, np.int64), vmax=np.ones(3), umax=np.zeros(3),
                 vmax_refined=np.ones(3), vmax_time=np.zeros(3), peak_state=np.zeros((5, 3)))
    rec.check(3, Recording())
    rec.vmax_refined = np.array([1.0, 0.5, 1.0])  # below the sampled maximum
    with pytest.raises(ValueError, match="vmax_refined must be >="):
        rec.check(3, Recording())
    rec.vmax_refined = np.ones(3)
    rec.peak_state = np.zeros((4, 3))
    with pytest.raises(ValueError, match="must come together"):
        rec.check(3, Recording())


def test_refined_maxima_are_kept_with_rtol_or_when_asked():
    # default (None): only with a step chosen for rtol (whose accuracy they carry)
    init = _impact(60)
    assert init.simulation().record.vmax_refined is None
    assert init.simulation(record=REFINED).record.vmax_refined is not None
    sim = init.simulation(rtol=1e-3)
    assert sim.time_step.source == "rtol" and sim.record.vmax_refined is not None
    off = Recording(maxima=True, refined_maxima=False)
    assert init.simulation(rtol=1e-3, record=off).record.vmax_refined is None
    with pytest.raises(ValueError, match="needs maxima"):
        Recording(maxima=False, refined_maxima=True).validate(60)
    with pytest.raises(ValueError, match="vmax_refined missing"):
        init.simulation().record.check(60, REFINED)


@pytest.mark.parametrize("kw", [{"law": "kk"}, {"drag": 50.0}])
def test_velocity_dependent_forces_refuse_refined_maxima(kw):
    # With a dissipative law or drag the split step stores the elastic acceleration,
    # not dv/dt (discrete.kernels, "Dissipation"): a Hermite interpolant of (v, a)
    # would not be the velocity between the steps.  True is refused naming the key;
    # None (the default, on with rtol) means off there, the sampled maxima stay.
    from discrete import Simulation
    from theory.laws import ViscoelasticHertz

    kw = {"law": ViscoelasticHertz(1e-5)} if "law" in kw else kw
    init = _impact(60)
    with pytest.raises(ValueError, match="refined_maxima"):
        Simulation(init.chain, u=init.u, v=init.v, record=REFINED, **kw)
    sim = Simulation(init.chain, u=init.u, v=init.v, rtol=1e-3,
                     record=Recording(maxima=True), **kw)
    assert sim.record.vmax_refined is None
    sim.run(max_steps=200, progress=False)
    assert np.all(np.isfinite(sim.record.vmax)) and sim.record.vmax_refined is None
