"""The fused compiled steppers (continuum._stepper) against the NumPy reference.

The reference is each PDE's ``evolution_rate`` (NumPy: sparse LU for the Rosenau mass
operator, numpy.fft for the saturated operator, py-pde's operators for KdV) stepped by
py-pde's generic loop (``backend="numpy"``).  The compiled path is an independent
implementation (twisted tridiagonal factorisation, active window, DUCC FFTs through
rocket-fft or direct sums, fused RK4), so agreement to round-off over hundreds of steps
is a real check.

Tolerance: 1e-9 of the largest value.  The two paths sum in different orders (twisted
vs plain elimination, DUCC vs pocketfft, fused stages), so each step they differ by a
few ulps, and the difference is carried and amplified by the dynamics like any
perturbation.  Measured, every case below: ≤ 2e-12 for the 200–300-step
runs of Eq. 4, Eq. 7 (both stencils, both steppers, every boundary) and KdV, 6.5e-12
for Eq. 7 periodic, 1.1e-11 for the long sonic-vacuum window run.  1e-9 leaves a
factor ~100 for other compilers and CPUs, while a real discrepancy (a wrong
coefficient, a missed face, a truncated window) changes the result by the size of the
term it affects, far above 1e-9.
"""

import re

import numpy as np
import pytest

import theory
from continuum import (
    BoussinesqPDE,
    KdVPDE,
    Medium,
    NesterenkoPDE,
    compacton,
    compacton_parameters,
    run,
    solitary_wave,
)
from continuum.solver import splitting_coefficients, splitting_method

from ._helpers import from_arrays, two_section

D = theory.PAPER_DIAMETER
DELTA0 = 1e-3 * D
RTOL = 1e-9


def _assert_close(a, b, rtol=RTOL):
    a, b = np.asarray(a), np.asarray(b)
    for x, y in zip(a, b, strict=True):
        np.testing.assert_allclose(x, y, rtol=0, atol=rtol * np.abs(y).max())


METHODS = ["position_verlet", "position_yoshida4", "verlet", "yoshida4", "blanes_moan4"]
"""Every method of theory.splitting: drift first, and kick first with the FSAL merge."""


def _both(pde, state, t_end, **kw):
    ref = run(pde, state, t_end, backend="numpy", **kw)
    fast = run(pde, state, t_end, **kw)
    assert fast["info"]["fused"] and not ref["info"]["fused"]
    return ref, fast


def _periodic_two_section(n_l, n_r, delta0, ar, ak):
    med = two_section(n_l, n_r, delta0, ar, ak)
    k = med.k.copy()
    k[-1] = k[0]  # the wrap contact closes the chain: a second interface
    return from_arrays(med.mass, k, delta0)


# ---------------------------------------------------------------------------------
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("nonlinearity", ["quadratic", "hertz", "linear"])
@pytest.mark.parametrize("bc", ["free", "wall", "periodic"])
def test_rosenau_fused_equals_numpy(bc, nonlinearity, method, rng):
    """Eq. 4 (Rosenau form) on a composite chain with random smooth-ish content and
    waves hitting the ends: 300 steps, compiled == NumPy to 1e-9, energy and momentum
    records equal to 1e-9, for every splitting method (kick first: the kernel merges
    the FSAL kicks, the NumPy path reuses the cached acceleration and kicks twice;
    measured ≤ 7e-14 for all)."""
    if bc == "periodic":
        med = _periodic_two_section(14, 11, DELTA0, 2.0, 0.3)
    else:
        med = two_section(14, 11, DELTA0, 2.0, 0.3)
    pde = BoussinesqPDE(med, 3, bc=bc, nonlinearity=nonlinearity)
    u = 0.1 * DELTA0 * np.cumsum(rng.standard_normal(pde.grid.shape)) * pde.disc.h
    v = 1e-3 * rng.standard_normal(pde.grid.shape)
    state = pde.get_initial_condition(u, v)
    dt = pde.stable_dt(state)
    ref, fast = _both(pde, state, 300 * dt, dt=dt, method=method, interval=100 * dt,
                      drift_tolerance=1.0)
    _assert_close(fast["state"].data, ref["state"].data)
    np.testing.assert_allclose(fast["energy"], ref["energy"], rtol=RTOL)
    np.testing.assert_allclose(fast["momentum"], ref["momentum"], rtol=0,
                               atol=RTOL * np.abs(ref["momentum"]).max() + 1e-30)
    assert fast["info"]["method"] == method


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("model", ["eq4", "eq4-periodic", "eq7"])
def test_chunks_merge_fsal_and_split_anywhere(model, method, rng):
    """One chunk of 12 steps equals 12 chunks of one step to round-off (1e-12 of the
    largest value: the merged drifts/kicks (α_S + α_0), (β_S + β_0) are sums of the
    same terms; measured ≤ 1e-14), and costs what the method promises: S evaluations
    per step plus, kick first, one at the chunk start (the whole periodic chain is
    swept, so node-updates = evaluations × nodes exactly)."""
    m = splitting_method(method)
    if model == "eq7":
        med = two_section(40, 35, DELTA0, 0.4, 0.5)
        pde = NesterenkoPDE(med, 3, delta_floor=1e-8)
        u = np.cumsum(-2e-6 * rng.random(pde.grid.shape) + 1e-6) * pde.disc.h
    else:
        med = _periodic_two_section(14, 11, DELTA0, 2.0, 0.3)
        pde = BoussinesqPDE(med, 3, bc="periodic" if model == "eq4-periodic" else "free")
        u = 0.1 * DELTA0 * np.cumsum(rng.standard_normal(pde.grid.shape)) * pde.disc.h
    state = pde.get_initial_condition(u, 1e-3 * rng.standard_normal(pde.grid.shape))
    dt = pde.stable_dt(state)
    alpha, beta = splitting_coefficients(m)
    one, many = state.data.copy(), state.data.copy()
    work_one = pde.make_chunk_stepper(state, dt, alpha, beta)(one, 12)
    chunk = pde.make_chunk_stepper(state, dt, alpha, beta)
    work_many = sum(chunk(many, 1) for _ in range(12))
    _assert_close(one, many, rtol=1e-12)
    if model == "eq4-periodic":
        n = pde.grid.shape[0]
        extra = 1 if m.kick_first else 0
        assert work_one == (12 * m.stages + extra) * n
        assert work_many == 12 * (m.stages + extra) * n


def test_rosenau_window_is_exact_and_small():
    """A solitary wave in a long chain: the active window covers a fraction of the
    chain (fewer node-updates than steps × nodes) and the result equals the NumPy
    reference that integrates every node."""
    med = two_section(200, 400, DELTA0, 0.5, 2.0)
    pde = BoussinesqPDE(med, 3)
    state = solitary_wave(pde, 120.0, velocity_max=0.0822)
    dt = pde.stable_dt(state)
    t_end = 600 * dt  # the wave crosses the interface (200 grains at c dt = h = 1/3)
    ref, fast = _both(pde, state, t_end, dt=dt, order=4, interval=t_end / 3)
    _assert_close(fast["state"].data, ref["state"].data)
    full = fast["info"]["steps"] * 3 * pde.grid.shape[0]
    assert fast["info"]["node_updates"] < 0.75 * full  # measured 0.6


@pytest.mark.parametrize("space_order", [2, 4])
@pytest.mark.parametrize("order", [2, 4, "blanes_moan4"])
@pytest.mark.parametrize("bc", ["free", "wall", "periodic"])
@pytest.mark.parametrize("precompressed", [False, True])
def test_nesterenko_fused_equals_numpy(bc, precompressed, order, space_order, rng):
    """Eq. 7 (saturated dispersion) on a composite chain, with and without
    precompression, both stencils (space_order 2 and 4) and both steppers:
    compressed and separated contacts, some below the floor; 200 steps.  Exercises the
    periodic circulant, the direct sum over compressed faces and (precompressed: every
    face) the zero-padded FFT."""
    d0 = DELTA0 if precompressed else 0.0
    if bc == "periodic":
        med = _periodic_two_section(40, 35, d0, 0.4, 0.5)
    else:
        med = two_section(40, 35, d0, 0.4, 0.5)
    pde = NesterenkoPDE(med, 3, bc=bc, delta_floor=1e-8, space_order=space_order)
    u = np.cumsum(-2e-6 * rng.random(pde.grid.shape) + 1e-6) * pde.disc.h
    state = pde.get_initial_condition(u, 1e-3 * rng.standard_normal(pde.grid.shape))
    dt = pde.stable_dt(state)
    kw = {"order": order} if isinstance(order, int) else {"method": order}
    ref, fast = _both(pde, state, 200 * dt, dt=dt, interval=50 * dt, drift_tolerance=1.0,
                      **kw)
    _assert_close(fast["state"].data, ref["state"].data)
    np.testing.assert_allclose(fast["energy"], ref["energy"], rtol=RTOL)


def test_nesterenko_sonic_vacuum_window():
    """A compacton in the sonic vacuum: the window (nodes that move or touch a
    compressed contact) follows the wave and its wake; the long run (FFT over the
    window once the wake has many compressed contacts) equals the NumPy reference, and
    the vacuum ahead is still exactly at rest."""
    med = Medium.uniform(150, 0.0)
    amp = compacton_parameters(NesterenkoPDE(med, 1, delta_floor=0.0), velocity_max=0.68)
    pde = NesterenkoPDE(med, 3, delta_floor=1e-2 * amp["amplitude"])
    state = compacton(pde, 20.0, velocity_max=0.68)
    t_end = 80.0 / amp["speed"]
    ref, fast = _both(pde, state, t_end, interval=t_end / 2)
    _assert_close(fast["state"].data, ref["state"].data)
    x = pde.disc.x_nodes
    ahead = x > 110.0
    assert np.all(fast["state"][1].data[ahead] == 0.0)
    assert fast["info"]["node_updates"] < 0.6 * fast["info"]["steps"] * x.size


@pytest.mark.parametrize("frame", [0.0, 1.0])
def test_kdv_fused_equals_numpy(frame):
    """KdV (RK4, central differences) in the laboratory and the co-moving frame."""
    pde = KdVPDE.for_medium(Medium.uniform(5, DELTA0))
    pde.frame_speed = frame * pde.speed
    grid = KdVPDE.grid(60, 3)
    s0 = pde.soliton(grid, 0.09 * DELTA0, 20.0)
    dt = pde.stable_dt(s0)
    ref, fast = _both(pde, s0, 400 * dt, dt=dt, interval=100 * dt)
    np.testing.assert_allclose(fast["state"].data, ref["state"].data, rtol=0,
                               atol=RTOL * np.abs(ref["state"].data).max())
    np.testing.assert_allclose(fast["energy"], ref["energy"], rtol=RTOL)


def test_fft_size_is_the_smallest_fast_length():
    """fft_size(n): the smallest m >= n that is a multiple of 8 with no prime factor
    above 5 — checked against a brute-force search for every n up to 5,000 (a length
    below n would truncate the zero padding and wrap the Toeplitz product around)."""
    from continuum._stepper import fft_size

    def smooth(r):
        for p in (2, 3, 5):
            while r % p == 0:
                r //= p
        return r == 1

    fast = [m for m in range(8, 6000, 8) if smooth(m // 8)]
    for n in range(1, 5001):
        assert fft_size(n) == next(m for m in fast if m >= n), n


# ---------------------------------------------------------------------------------
@pytest.mark.parametrize("model", ["eq4", "eq7", "kdv"])
def test_no_allocation_per_step(model):
    """numba's runtime allocation counter moves as much for a chunk of 2,000 steps as for
    one of 10 (only the arrays passed in from Python are registered): the compiled loop
    keeps everything in preallocated arrays."""
    import numba as nb
    from numba.core.runtime import nrt, rtsys

    was_enabled = nrt._nrt.memsys_stats_enabled()
    nrt._nrt.memsys_enable_stats()

    if model == "kdv":
        pde = KdVPDE.for_medium(Medium.uniform(5, DELTA0))
        state = pde.soliton(KdVPDE.grid(40, 3), 0.09 * DELTA0, 20.0)
        chunk = pde.make_chunk_stepper(state, pde.stable_dt(state))
    else:
        if model == "eq4":
            pde = BoussinesqPDE(two_section(40, 40, DELTA0, 2.0, 1.0), 3)
            state = solitary_wave(pde, 20.0, velocity_max=0.0822)
        else:
            med = Medium.uniform(80, 0.0)
            amp = compacton_parameters(NesterenkoPDE(med, 1, delta_floor=0.0),
                                       velocity_max=0.68)["amplitude"]
            pde = NesterenkoPDE(med, 3, delta_floor=1e-2 * amp)
            state = compacton(pde, 20.0, velocity_max=0.68)
        alpha, beta = splitting_coefficients(4)
        chunk = pde.make_chunk_stepper(state, pde.stable_dt(state), alpha, beta)
    data = state.data.copy()

    @nb.njit
    def allocating(n):  # positive control: the counter sees an allocation per call
        return np.empty(n)

    try:
        chunk(data, 5)  # compile
        allocating(3)
        before = rtsys.get_allocation_stats().alloc
        allocating(3)
        assert rtsys.get_allocation_stats().alloc == before + 1
        before = rtsys.get_allocation_stats().alloc
        chunk(data, 10)
        short = rtsys.get_allocation_stats().alloc - before
        before = rtsys.get_allocation_stats().alloc
        chunk(data, 2000)
        assert rtsys.get_allocation_stats().alloc - before == short
    finally:
        if not was_enabled:
            nrt._nrt.memsys_disable_stats()
    assert np.all(np.isfinite(data))


@pytest.mark.parametrize("model", ["eq4-free", "eq4-wall", "eq7-free", "eq7-periodic",
                                   "eq7-pre", "kdv"])
def test_compiled_monitor_equals_numpy(model, rng):
    """The compiled energy/momentum (or KdV invariants) equal pde.invariants (NumPy)."""
    if model == "kdv":
        pde = KdVPDE.for_medium(Medium.uniform(5, DELTA0))
        state = pde.soliton(KdVPDE.grid(60, 3), 0.09 * DELTA0, 20.0)
        pde.make_chunk_stepper(state, 1e-7)
    else:
        kind, bc = model.split("-")
        if kind == "eq4":
            pde = BoussinesqPDE(two_section(20, 15, DELTA0, 2.0, 0.5), 3, bc=bc)
        elif bc == "pre":
            pde = NesterenkoPDE(two_section(20, 15, DELTA0, 2.0, 0.5), 3,
                                delta_floor=1e-3 * DELTA0)
        else:
            med = (_periodic_two_section(20, 15, 0.0, 2.0, 0.5) if bc == "periodic"
                   else two_section(20, 15, 0.0, 2.0, 0.5))
            pde = NesterenkoPDE(med, 3, bc=bc, delta_floor=1e-8)
        u = np.cumsum(-2e-6 * rng.random(pde.grid.shape) + 1e-6) * pde.disc.h
        state = pde.get_initial_condition(u, 1e-3 * rng.standard_normal(pde.grid.shape))
    e_c, p_c = pde.make_monitor()(state.data)
    e_n, p_n = pde.invariants(state)
    assert e_c == pytest.approx(e_n, rel=1e-12)
    assert p_c == pytest.approx(p_n, rel=1e-12, abs=1e-300)


def test_nesterenko_precompressed_chain_at_rest_stays_at_rest():
    """A precompressed Eq. 7 chain at rest is an equilibrium: the compiled stepper's
    dispersive flux y ∝ ζ(δ) − ζ(δ0) must vanish exactly, so ζ(δ0) is formed with the
    kernel's own arithmetic (δ·√√δ; δ0^{5/4} differs by an ulp for ~30 % of δ0, which
    had set the chain moving at ~4e-17 m/s within 100 steps)."""
    for d0 in (1.005e-3 * D, DELTA0, 0.7e-3 * D):
        pde = NesterenkoPDE(Medium.uniform(200, d0), 3, delta_floor=1e-8)
        state = pde.get_initial_condition(np.zeros(pde.grid.shape), np.zeros(pde.grid.shape))
        dt = pde.stable_dt(state)
        out = run(pde, state, 100 * dt, dt=dt, interval=50 * dt)
        assert out["info"]["fused"]
        assert np.all(out["state"].data == 0.0), d0


def test_unfused_numba_refuses_kick_first_methods():
    """py-pde's compiled single step cannot carry the kick-first FSAL cache (a Python
    dict): fused=False with the numba backend is refused for those methods with an error
    naming the parameters (was a numba TypingError)."""
    from continuum.solver import VerletSolver

    pde = BoussinesqPDE(Medium.uniform(30, DELTA0), 3, bc="periodic")
    state = solitary_wave(pde, 15.0, velocity_max=0.0822)
    with pytest.raises(ValueError, match="fused=False with backend 'numba'.*'blanes_moan4'"):
        VerletSolver(pde, backend="numba", fused=False, method="blanes_moan4").make_stepper(
            state, pde.stable_dt(state))
    # (the check can pass: the same method fused, or drift first unfused, is accepted)
    for kw in ({"method": "blanes_moan4"}, {"method": "position_verlet", "fused": False}):
        VerletSolver(pde, backend="numba", **kw).make_stepper(state, pde.stable_dt(state))


@pytest.mark.parametrize("nonlinearity", ["linear", "quadratic", "hertz"])
@pytest.mark.parametrize("bc", ["free", "wall"])
def test_rosenau_pass_solves_the_mass_operator_on_any_window(bc, nonlinearity, rng):
    """One pass of the compiled Rosenau kernel without drift kicks the window's nodes
    [L, R] by β (M⁻¹ r_w) there, M the whole chain's mass operator and r_w the flux
    divergence on the window, zero outside it (the active window's premise: the medium
    is at rest there; the factors are the whole chain's, so elimination from either
    side of the window is exact): checked against a dense solve (numpy.linalg) for windows that
    start and end inside and outside the constant runs of the factors (both ends, the
    interface of a three-section chain), of lengths 1 to 300 — every path of the
    four-node links (:func:`continuum._stepper._eliminate4`) and their remainders, for
    each flux (the quadratic one has a sweep of its own).  Tolerance 1e-12 of the
    largest kick: both are backward-stable solves of a matrix
    with condition number < 10 (the links differ from the one-step recurrence by a
    few ulp, measured ≤ 2e-16)."""
    from continuum import _kernels, _stepper

    sec = two_section(30, 40, DELTA0, 3.0, 0.5)
    med = from_arrays(np.r_[sec.mass, sec.mass[:30] * 0.25],
                      np.r_[sec.k, sec.k[1:31]], DELTA0)
    pde = BoussinesqPDE(med, 3, bc=bc, nonlinearity=nonlinearity)
    n = pde.grid.shape[0]
    h = pde.disc.h
    fac = _stepper.rosenau_factors(*pde._bands)[0]
    runs = _stepper.constant_runs(fac)
    window_pass = _stepper.rosenau_kernels(pde.law, pde._nl_code).window_pass
    assert runs[0].max() > 40 and runs[3].max() > 40  # long runs: the links are used
    kk, bb, kh, d0, f0 = pde._kernel_arrays()
    diag, off, _ = pde._bands
    mat = np.diag(diag) + np.diag(off, 1) + np.diag(off, -1)
    u = 0.1 * DELTA0 * np.cumsum(rng.standard_normal(n)) * h
    code = _kernels.WALL if bc == "wall" else _kernels.FREE
    windows = [(0, n - 1), (0, 0), (n - 1, n - 1), (5, 7), (3, 93), (17, 122), (89, 91),
               (60, 209), (0, 299), (n - 300, n - 1)]
    windows += [tuple(sorted(rng.integers(0, n, 2))) for _ in range(20)]
    for lo, hi in windows:
        v = rng.standard_normal(n)
        v0 = v.copy()
        y = np.zeros(n)
        win = np.zeros(2, np.int64)
        window_pass(u, v, y, lo, hi, 0.0, 0.7, h, code, kk, bb, kh, d0, f0, fac, runs,
                    0.0, np.inf, win)
        # flux divergence on the window: faces lo..hi+1 (outer ones from u beyond it)
        s = np.empty(hi - lo + 2)
        for j, q in enumerate(range(lo, hi + 2)):
            if q == 0:
                s[j] = -2.0 * u[0] / h if bc == "wall" else 0.0
            elif q == n:
                s[j] = 2.0 * u[-1] / h if bc == "wall" else 0.0
            else:
                s[j] = (u[q - 1] - u[q]) / h
        s_all = np.zeros(n + 1)
        s_all[lo:hi + 2] = s
        flux = pde.flux(s_all)[lo:hi + 2]  # the NumPy path's P(s) of the nonlinearity
        r = (flux[:-1] - flux[1:]) / h
        rhs = np.zeros(n)
        rhs[lo:hi + 1] = r
        x = np.linalg.solve(mat, rhs)[lo:hi + 1]
        kick = v[lo:hi + 1] - v0[lo:hi + 1]
        np.testing.assert_allclose(kick, 0.7 * x, rtol=0,
                                   atol=1e-12 * np.abs(0.7 * x).max() + 1e-300)
        assert np.array_equal(v[:lo], v0[:lo]) and np.array_equal(v[hi + 1:], v0[hi + 1:])


def test_rosenau_kernels_compile_only_their_flux():
    """The Rosenau kernels are built per flux code (``nl`` a constant of the closure):
    numba drops the other codes' branches before typing, so the quadratic flux's
    kernels (what every Eq. 4 run of ``reproduce --quick`` uses) contain no evaluation
    of the Hertz law's force or energy — no square root, log1p or expm1 anywhere in the
    compiled chunk and monitor — while the full law's kernels do (r√r; √r, log1p and
    expm1 in its energy).  A code outside {0, 1, 2} is refused by name."""
    import numba

    from continuum import _stepper

    med = Medium.uniform(30, DELTA0)
    for nonlinearity, code in (("quadratic", 1), ("hertz", 2)):
        pde = BoussinesqPDE(med, 3, nonlinearity=nonlinearity)
        run(pde, solitary_wave(pde, 10.0, velocity_max=0.05), 2e-6)
        kern = _stepper.rosenau_kernels(pde.law, code)
        ir = ""
        for f in (kern.chunk, kern.monitor):
            # compiled afresh (not loaded from the disk cache): its LLVM module, callees
            # linked in
            (sig,) = f.signatures
            fresh = numba.njit(f.py_func)
            fresh.compile(sig)
            ir += fresh.inspect_llvm(sig)
        law_calls = re.findall(r"@(llvm\.sqrt\.f64|sqrt|log1p|expm1)\b", ir)
        assert bool(law_calls) == (code == 2), (nonlinearity, sorted(set(law_calls)))
    with pytest.raises(ValueError, match="nl must be"):
        _stepper.rosenau_kernels(med.law, 3)
