"""Regularised Eq. 7 (saturated dispersion): compacton speed (Eq. 8) and shape, sonic
vacuum without NaNs and independent of the floor, dispersion, well-posedness,
conservation, compiled vs NumPy."""

import numpy as np
import pytest
from pde.backends import get_backend
from pde.trackers import DataTracker
from scipy.optimize import curve_fit

import theory
from continuum import Medium, NesterenkoPDE, compacton, compacton_parameters, run

from ._helpers import from_arrays, peak_position, shape_change, two_section

D = theory.PAPER_DIAMETER
VMAX = 0.68  # m/s: the paper's sonic-vacuum wave for v0 = 1 m/s (v̄max/v0 = 0.6816)
KAPPA = np.sqrt(10) / 5


def _amplitude(med):
    return compacton_parameters(NesterenkoPDE(med, 1, delta_floor=0.0),
                                velocity_max=VMAX)["amplitude"]


@pytest.mark.parametrize("bc", ["free", "wall", "periodic"])
def test_numpy_and_compiled_rates_agree(bc, rng):
    """Same flux, FFTs through numba.objmode in the compiled path: agree to 1e-10."""
    if bc == "periodic":
        med = from_arrays(np.r_[np.full(8, 5e-4), np.full(7, 2e-4)],
                                       np.r_[np.full(9, 5e9), np.full(6, 2e9), 5e9], 0.0)
    else:
        med = two_section(8, 7, 0.0, 0.4, 0.5)
    pde = NesterenkoPDE(med, 3, bc=bc, delta_floor=1e-8)
    # compressed and separated contacts, some below the floor
    u = np.cumsum(-2e-6 * rng.random(pde.grid.shape) + 1e-6) * pde.disc.h
    state = pde.get_initial_condition(u, rng.standard_normal(pde.grid.shape))
    r_np = pde.evolution_rate(state).data
    r_nb = pde.make_evolution_rate(state, get_backend("numba"))(state.data.copy(), 0.0)
    assert np.all(np.isfinite(r_np))
    np.testing.assert_allclose(r_nb, r_np, rtol=1e-10, atol=1e-10 * np.abs(r_np).max())


@pytest.fixture(scope="module")
def compacton_run():
    """The paper's sonic-vacuum wave amplitude (v_max = 0.68 m/s) over 50 d, n = 5."""
    med = Medium.uniform(90, 0.0)
    amp = _amplitude(med)
    pde = NesterenkoPDE(med, 5, delta_floor=1e-2 * amp)
    par = compacton_parameters(pde, velocity_max=VMAX)
    state = compacton(pde, 15.0, velocity_max=VMAX)
    t_end = 50.0 / par["speed"]
    res = run(pde, state, t_end, interval=t_end / 10)
    return pde, par, state, res, t_end


def test_compacton_speed_is_eq8(compacton_run):
    """Speed within 2 % of Eq. 8, V = (2/√5) c_mat ξ_max^{1/4}; achieved: < 0.5 %."""
    pde, par, state, res, t_end = compacton_run
    x = pde.disc.x_nodes
    v_meas = (peak_position(x, res["state"][1].data) - 15.0) / t_end * pde.medium.diameter
    v_eq8 = theory.sonic_vacuum_speed(par["c_mat"], par["strain_max"])
    assert v_meas == pytest.approx(v_eq8, rel=0.02)
    assert v_meas == pytest.approx(v_eq8, rel=5e-3)


def test_compacton_keeps_shape(compacton_run):
    """Shape change < 5 % over 50 d, L2 over the wave (support ± 1 d, best shift) of the
    velocity profile; achieved ≈ 1 %.  The small wake of separated, slowly drifting
    grains left behind (the cos⁴ is not exactly the regularised equation's wave) is
    bounded too: whole-domain L2 < 10 %."""
    pde, par, state, res, t_end = compacton_run
    x = pde.disc.x_nodes
    vv = res["state"][1].data
    half = np.pi / (2 * KAPPA)

    def prof(y):
        return par["velocity_max"] * np.where(np.abs(y) <= half, np.cos(KAPPA * y) ** 4, 0.0)

    err, _ = shape_change(x, vv, prof, peak_position(x, vv), window=half + 1.0)
    assert err < 0.05
    assert err < 0.02
    err_all, _ = shape_change(x, vv, prof, peak_position(x, vv))
    assert err_all < 0.10


def test_energy_conservation(compacton_run):
    """Conserved functional (kinetic + Hertz + dispersive): drift < 1e-5 (achieved 1e-6)."""
    assert compacton_run[3].energy_drift < 1e-5


@pytest.mark.parametrize("space_order", [2, 4])
def test_sonic_vacuum_floor_does_not_change_speed(space_order):
    """δ → 0 handling: no NaNs ahead of or behind the wave (gaps open there), and the
    speed is the same within 1e-3 for floors of 3e-3, 1e-2 and 3e-2 of the peak.  Ahead
    of the wave the vacuum stays at rest: exactly beyond 3 grains from the peak with the
    second-order stencil; the fourth-order one (weights 27/24 and -1/24 over four nodes)
    reaches two nodes further and leaves a precursor below 1e-7 of the peak velocity
    there (measured 9e-9), exactly zero beyond 6 grains."""
    med = Medium.uniform(45, 0.0)
    amp = _amplitude(med)
    speeds = []
    for rel in (3e-3, 1e-2, 3e-2):
        pde = NesterenkoPDE(med, 3, delta_floor=rel * amp, space_order=space_order)
        state = compacton(pde, 10.0, velocity_max=VMAX)
        par = compacton_parameters(pde, velocity_max=VMAX)
        t_end = 20.0 / par["speed"]
        res = run(pde, state, t_end, interval=t_end / 2)
        u, v = (f.data for f in res["state"])
        assert np.all(np.isfinite(u)) and np.all(np.isfinite(v))
        x = pde.disc.x_nodes
        speeds.append((peak_position(x, v) - 10.0) / t_end / par["speed"])
        if space_order == 2:
            assert np.all(np.abs(v[x > peak_position(x, v) + 3]) < 1e-40)  # vacuum at rest
        else:
            assert np.all(np.abs(v[x > peak_position(x, v) + 3]) < 1e-7 * VMAX)
            assert np.all(v[x > peak_position(x, v) + 6] == 0.0)
    assert np.ptp(speeds) < 1e-3


@pytest.mark.parametrize("space_order", [2, 4])
@pytest.mark.parametrize("j", [4, 8, 16])
def test_dispersion_about_precompression(j, space_order):
    """Linearised about δ0 (uniform, periodic): ω² = (K/m) D_h(k) (1 - c_h min(k², 10)/12)
    to 1e-4 — positive for every k (well-posed), equal to the long-wave Eq. 7 for
    |k| ≤ √10 ⊃ Brillouin zone up to the stencil's error.  Second order:
    D_h = (4/h²) sin²(kh/2) and c_h = 1 - h² (the scheme's dispersive coefficient
    (d² - h²)/10 cancels the O(h²) of D_h); fourth order: D_h = ((54 sin(kh/2) -
    2 sin(3kh/2))/(24h))² and c_h = 1."""
    delta0 = 1e-3 * D
    med = Medium.uniform(20, delta0)
    pde = NesterenkoPDE(med, 5, bc="periodic", delta_floor=0.0, space_order=space_order)
    x = pde.disc.x_nodes
    k = 2 * np.pi * j / 20
    mode = np.cos(k * (x + 0.5))
    state = pde.get_initial_condition(1e-6 * delta0 * mode)
    h = pde.disc.h
    c2 = pde.disc.stiffness[0] / pde.disc.mass[0]
    if space_order == 2:
        dh, ch = (2 / h * np.sin(k * h / 2)) ** 2, 1 - h * h
    else:
        dh, ch = ((54 * np.sin(k * h / 2) - 2 * np.sin(3 * k * h / 2)) / (24 * h)) ** 2, 1.0
    omega_th = np.sqrt(c2 * dh * (1 - ch * min(k * k, 10.0) / 12))
    t_end = 3 * 2 * np.pi / omega_th
    tracker = DataTracker(lambda s: float(s[0].data @ mode / (mode @ mode)),
                          interrupts=t_end / 120)
    pde.solve(state, t_range=t_end, dt=t_end / 1200, solver="verlet", order=4,
              tracker=[tracker], backend="numba")
    t, a = np.asarray(tracker.times), np.asarray(tracker.data)
    (omega,), _ = curve_fit(lambda t, w: a[0] * np.cos(w * t), t, a, p0=[omega_th])
    assert omega == pytest.approx(omega_th, rel=1e-4)


def test_grid_scale_noise_does_not_grow(rng):
    """Well-posedness on a precompressed chain: grid-scale noise, 5,000 steps at the
    default step; energy error bounded (< 5 %), amplitude bounded (< 3x)."""
    delta0 = 1e-3 * D
    pde = NesterenkoPDE(Medium.uniform(30, delta0), 5, bc="periodic", delta_floor=0.0)
    u0 = 1e-2 * delta0 * rng.standard_normal(pde.grid.shape)
    u0 -= u0.mean()
    state = pde.get_initial_condition(u0)
    dt = pde.stable_dt(state)
    res = run(pde, state, 5000 * dt, dt=dt, interval=500 * dt, drift_tolerance=1.0)
    assert res.energy_drift < 0.05
    assert np.abs(res["state"][0].data).max() < 3 * np.abs(u0).max()


@pytest.mark.parametrize(("alpha_rho", "alpha_kn"), [(0.2, 1.0), (5.0, 1.0)])
def test_sonic_vacuum_interface_conserves(alpha_rho, alpha_kn):
    """A compacton through a sonic-vacuum interface (paper Fig. 3 set-ups, heavy–light
    and light–heavy): no NaNs, momentum conserved to 1e-12, the functional to 1e-3 at
    safety 0.1 (measured 4e-4 at n = 3, 5e-5 at n = 5), and Et_tr + Et_re = 1 within
    1e-3 when measured with the functional."""
    from continuum.scattering import _functional_sections

    med = two_section(30, 40, 0.0, alpha_rho, alpha_kn)
    amp = _amplitude(med)
    pde = NesterenkoPDE(med, 3, delta_floor=1e-2 * amp)
    state = compacton(pde, 15.0, velocity_max=VMAX)
    par = compacton_parameters(pde, velocity_max=VMAX)
    t_end = 40.0 / par["speed"]
    res = run(pde, state, t_end, dt=pde.stable_dt(state, safety=0.1), interval=t_end / 5)
    assert np.all(np.isfinite(res["state"].data))
    mom = np.asarray(res["momentum"])
    assert np.max(np.abs(mom - mom[0])) < 1e-12 * abs(mom[0])
    assert res.energy_drift < 1e-3
    e_in = _functional_sections(pde, state, 30)["left"]["total"]
    sec = _functional_sections(pde, res["state"], 30)
    assert (sec["left"]["total"] + sec["right"]["total"]) / e_in == pytest.approx(1, abs=1e-3)
