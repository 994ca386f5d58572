r"""Solitary-wave profiles of a granular chain: KdV, Nesterenko compacton, exact lattice wave.

Units are SI; the strain is ξ = -u_x (dimensionless), in the chain ξ ≈ (overlap - δ0)/d.
Contact j lies between grains j-1 and j; r_j = δ0 + u_{j-1} - u_j is its overlap.
All waves travel to the right (+x); u → 0 ahead of the wave and u = D > 0 (the net
shift) behind it.

* ``kdv_soliton_*`` — sech² wave of the corrected paper Eq. 4 (docs/physics.md §2).
* ``compacton_*`` — Nesterenko's cos⁴ compacton of Eq. 7, speed Eq. 8 (docs/physics.md §3),
  and its cos^{2/(n-1)} generalisation for F = k δ^n (``exponent``).
* :func:`discrete_solitary_wave` — exact travelling wave of the lattice (Eq. 2), δ0 >= 0,
  any F = k δ^n, by Petviashvili iteration (docs/physics.md §7); ``.sample`` gives a DEM
  initial condition; :func:`sonic_vacuum_wave_constants`, the dimensionless constants of
  its self-similar δ0 = 0 form (energy, momentum, amplitude, speed per peak velocity).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from numpy.fft import irfft, rfft, rfftfreq
from numpy.typing import ArrayLike

from ._numerics import power_remainder
from ._validate import (
    check_exponent,
    check_finite,
    check_nonnegative,
    check_positive,
    check_range,
)
from .speeds import kdv_speed_exact, nesterenko_speed, sonic_vacuum_speed

__all__ = [
    "kdv_soliton_strain", "kdv_soliton_width", "kdv_soliton_motion", "compacton_strain",
    "compacton_motion", "compacton_width", "ChainState", "DiscreteSolitaryWave",
    "discrete_solitary_wave", "discrete_speed_constant", "SonicVacuumWave",
    "sonic_vacuum_wave_constants",
]  # fmt: skip


Real = float | np.ndarray  # a float for scalar input, an array otherwise


def _ret(x) -> Real:
    x = np.asarray(x, dtype=float)
    return x if x.ndim else float(x)


def _sech2(y):
    e = np.exp(-2.0 * np.abs(y))  # overflow-free sech² y = 4e^{-2|y|}/(1 + e^{-2|y|})²
    return 4.0 * e / (1.0 + e) ** 2


def kdv_soliton_width(amplitude: ArrayLike, d: ArrayLike, delta0: ArrayLike) -> Real:
    r"""Width 1/κ = √(2 δ0 d / A) of the KdV solitary wave of the corrected Eq. 4, m.

    The strain ξ = -u_x of u_tt = c0²(u_xx + a u_xxxx - b u_x u_xx), a = d²/12,
    b = d/(2δ0) (paper Eq. 4 corrected, docs/physics.md §2) obeys
    ξ_tt = c0² (ξ + a ξ_xx + (b/2) ξ²)_xx.  A wave ξ(x - Vt) decaying at ±∞ integrates
    twice to a ξ'' = (V²/c0² - 1) ξ - (b/2) ξ²; ξ = A sech²(κ y) solves it iff
    4aκ² = V²/c0² - 1 (sech² terms) and 6aκ² = bA/2 (sech⁴ terms), i.e.
    V² = c0² (1 + bA/3) (:func:`theory.speeds.kdv_speed_exact`, ≈ paper Eq. 5) and

    .. math:: κ^2 = \frac{V^2/c_0^2 - 1}{4a} = \frac{A}{2 δ_0 d}.

    Parameters
    ----------
    amplitude : float or array
        Peak strain A = ξ_max (> 0, dimensionless).
    d, delta0 : float or array
        Grain diameter and static overlap δ0, m.
    """
    a, d, delta0 = map(check_positive, ("amplitude", "d", "delta0"), (amplitude, d, delta0))
    return _ret(np.sqrt(2.0 * delta0 * d / a))


def kdv_soliton_strain(
    x: ArrayLike, amplitude: ArrayLike, d: ArrayLike, delta0: ArrayLike, x0: ArrayLike = 0.0
) -> Real:
    """Strain ξ = A sech²(κ (x - x0)) of the KdV solitary wave (corrected Eq. 4).

    κ from :func:`kdv_soliton_width`, which gives the derivation.

    Parameters
    ----------
    x, x0 : float or array
        Position and position of the peak (x0 + V t for the travelling wave), m.
    amplitude, d, delta0 : float
        Peak strain A (> 0), grain diameter (m) and static overlap (m).
    """
    inv_k = kdv_soliton_width(amplitude, d, delta0)
    y = (check_finite("x", x) - check_finite("x0", x0)) / inv_k
    return _ret(np.asarray(amplitude, dtype=float) * _sech2(y))


def kdv_soliton_motion(
    x: ArrayLike, amplitude: ArrayLike, d: ArrayLike, delta0: ArrayLike, c0_: ArrayLike,
    x0: ArrayLike = 0.0,
) -> tuple[Real, Real]:
    """Displacement and particle velocity (u, v) of the right-going KdV wave, (m, m/s).

    u(x) = ∫_x^∞ ξ dx' = (A/κ)(1 - tanh(κ (x - x0))): u → 0 ahead of the wave and
    u → 2A/κ (the net shift) behind it.  For u(x - Vt), v = u_t = -V u_x = V ξ with
    V = c0 √(1 + d A/(6 δ0)).

    Parameters
    ----------
    x, amplitude, d, delta0, x0
        As in :func:`kdv_soliton_strain`.
    c0_ : float
        Sound speed c0 of the precompressed chain, m/s (:func:`theory.speeds.c0`).
    """
    strain = np.asarray(kdv_soliton_strain(x, amplitude, d, delta0, x0))
    inv_k = kdv_soliton_width(amplitude, d, delta0)
    y = (check_finite("x", x) - check_finite("x0", x0)) / inv_k
    u = np.asarray(amplitude, dtype=float) * inv_k * (1.0 - np.tanh(y))
    return _ret(u), _ret(kdv_speed_exact(c0_, d, delta0, amplitude) * strain)


def _compacton_wavenumber(n: float) -> float:
    """The compacton's q d (ξ ∝ cos^{2/(n-1)}(q x)): (n-1)√(6/(n(n+1))), √10/5 for Hertz."""
    return (n - 1.0) * np.sqrt(6.0 / (n * (n + 1.0)))


def _compacton_phase(x, d, x0, n=1.5):
    q = _compacton_wavenumber(n) / check_positive("d", d)
    theta = q * (check_finite("x", x) - check_finite("x0", x0))
    return np.clip(theta, -np.pi / 2, np.pi / 2), q


def compacton_width(d: ArrayLike, exponent: float = 1.5) -> Real:
    r"""Support width π/q of the compacton, m: 5πd/√10 ≈ 4.97 d for Hertz.

    q = (n-1)√(6/(n(n+1)))/d (:func:`compacton_strain`), so the width is
    :math:`\pi d/((n-1)\sqrt{6/(n(n+1))})`, independent of the amplitude
    (Nesterenko 2001, §1.2).

    Parameters
    ----------
    d : float or array
        Grain diameter, m.
    exponent : float
        n of F = k δ^n, in (1, 10].
    """
    n = check_exponent(exponent, closed_low=False)
    return _ret(np.pi * check_positive("d", d) / _compacton_wavenumber(n))


def compacton_strain(x: ArrayLike, amplitude: ArrayLike, d: ArrayLike, x0: ArrayLike = 0.0,
                     exponent: float = 1.5) -> Real:
    r"""Nesterenko's compacton ξ = A cos^{2/(n-1)}(q (x - x0)), zero for |q (x - x0)| > π/2.

    Travelling wave of the conservative long-wave equation for F = k δ^n
    (docs/physics.md §3 and "Long waves for a power-law contact"; Nesterenko 2001, §1.2):
    u(x - Vt) in :math:`u_{tt} = -c^2\partial_x[\xi^n + a\,\xi^{(n-1)/2}
    (\xi^{(n+1)/2})_{xx}]`, a = n d²/(6(n+1)), integrates to
    :math:`V^2\xi = c^2[\xi^n + a\,\xi^{(n-1)/2}(\xi^{(n+1)/2})'']`, solved with
    q = (n-1)√(6/(n(n+1)))/d and V² = 2c²A^{n-1}/(n+1)
    (:func:`theory.speeds.sonic_vacuum_speed`).  Hertz (n = 3/2, Eq. 7): ξ = A
    cos⁴(√10 (x - x0)/(5d)); with θ = √10 x/(5d), ξ^{1/4}(ξ^{5/4})'' = A^{3/2}
    (10/(25d²)) (20 cos⁴θ - 25 cos⁶θ), so the bracket is (4/5) A^{3/2} cos⁴θ and
    V = (2/√5) c_mat A^{1/4} (paper Eq. 8).  Support width :func:`compacton_width`.

    Parameters
    ----------
    x, x0 : float or array
        Position and position of the peak, m.
    amplitude, d : float
        Peak strain A (> 0) and grain diameter (m).
    exponent : float
        n of F = k δ^n, in (1, 10].
    """
    n = check_exponent(exponent, closed_low=False)
    amplitude, (theta, _) = check_positive("amplitude", amplitude), _compacton_phase(x, d, x0, n)
    return _ret(np.where(np.abs(theta) < np.pi / 2,
                         amplitude * np.cos(theta) ** (2.0 / (n - 1.0)), 0.0))


def compacton_motion(
    x: ArrayLike, amplitude: ArrayLike, d: ArrayLike, c_mat_: ArrayLike, x0: ArrayLike = 0.0,
    exponent: float = 1.5,
) -> tuple[Real, Real]:
    r"""Displacement and particle velocity (u, v) of the right-going compacton, (m, m/s).

    u(x) = ∫_x^∞ ξ dx' = (A/q)(G(π/2) - G(θ)) with G a primitive of cos^p, p = 2/(n-1),
    θ clipped to [-π/2, π/2]: :math:`G(\theta) = \mathrm{sgn}\,\theta\,\tfrac12
    B(\tfrac12, \tfrac{p+1}2)\,I_{\sin^2\theta}(\tfrac12, \tfrac{p+1}2)` (the
    regularised incomplete beta function; substitute s = sin²t), for Hertz (p = 4)
    G(θ) = 3θ/8 + sin 2θ/4 + sin 4θ/32 and the net shift behind the wave 3π√10 d A/16.
    v = V ξ with V from :func:`theory.speeds.sonic_vacuum_speed`.

    Parameters
    ----------
    x, amplitude, d, x0, exponent
        As in :func:`compacton_strain`.
    c_mat_ : float
        Material speed c = √(k_n d^{n+1}/m), m/s (:func:`theory.speeds.c_mat`).
    """
    n = check_exponent(exponent, closed_low=False)
    strain = np.asarray(compacton_strain(x, amplitude, d, x0, n))
    theta, q = _compacton_phase(x, d, x0, n)
    p = 2.0 / (n - 1.0)
    if p == 4.0:
        def prim(th):
            return 3.0 * th / 8.0 + np.sin(2.0 * th) / 4.0 + np.sin(4.0 * th) / 32.0
    else:
        from scipy.special import beta, betainc

        b = 0.5 * (p + 1.0)

        def prim(th):
            return np.sign(th) * 0.5 * beta(0.5, b) * betainc(0.5, b, np.sin(th) ** 2)

    u = np.asarray(amplitude, dtype=float) / q * (prim(np.pi / 2) - prim(theta))
    return _ret(u), _ret(sonic_vacuum_speed(c_mat_, amplitude, exponent=n) * strain)


def _nonlinear(w, rho0, exponent=1.5):
    """N(w) = (ρ0 + w)_+^n - ρ0^n - n ρ0^{n-1} w for ρ0 ∈ {0, 1}, without cancellation.

    ρ0 = 0: N(w) = w_+^n.  ρ0 = 1: for Hertz (n = 3/2) exactly e²(3/2 + e) with
    e = √(1+w) - 1, else :func:`theory._numerics.power_remainder`.  For w < -1 (a gap)
    N = -1 - n w.
    """
    if rho0 == 0.0:
        return np.maximum(w, 0.0) ** exponent
    if exponent != 1.5:
        return power_remainder(w, exponent)
    wc = np.maximum(w, -1.0)
    e = wc / (1.0 + np.sqrt(1.0 + wc))  # √(1+w) - 1;  then N = e² (3/2 + e) exactly
    return np.where(w >= -1.0, e * e * (1.5 + e), -1.0 - 1.5 * w)


def _petviashvili(sigma2, rho0, n_dom, ppg, w, tol, max_iter, exponent=1.5):
    """Solve σ² w = Λ∗[(ρ0+w)_+^n - ρ0^n] on a periodic grid; return (w, history).

    ρ0 ∈ {0, 1}; n the exponent of the force law (3/2: Hertz).
    """
    n = n_dom * ppg
    q = 2.0 * np.pi * rfftfreq(n, d=1.0 / ppg)
    p_op = np.sinc(q / (2.0 * np.pi)) ** 2  # Λ̂(q) = [sin(q/2)/(q/2)]²
    lin = sigma2 - exponent * rho0 ** (exponent - 1.0) * p_op  # > 0 iff σ² > n ρ0^{n-1}
    wt = np.where((q == 0) | ((n % 2 == 0) & (q == q[-1])), 1.0, 2.0)  # Parseval weights
    gamma = exponent / (exponent - 1.0) if rho0 == 0.0 else 2.0  # p/(p-1), degree p = n or 2
    history, first, best = [], None, (w, np.inf, 0)
    for it in range(max_iter + 16):
        w_hat = rfft(w)
        pn_hat = p_op * rfft(_nonlinear(w, rho0, exponent))
        res = irfft(lin * w_hat - pn_hat, n=n)
        history.append(float(np.max(np.abs(res)) / (sigma2 * np.max(np.abs(w)))))
        if history[-1] < best[1]:
            best = (w, history[-1], it)
        if history[-1] < tol:  # converged; polish until the round-off floor stalls it
            first = it if first is None else first
            if it > first and history[-1] > 0.9 * history[-2]:
                break
        elif it >= max_iter - 1:
            break
        m_fac = np.sum(wt * lin * np.abs(w_hat) ** 2) / np.sum(wt * (np.conj(w_hat) * pn_hat).real)
        w = irfft(m_fac**gamma * pn_hat / lin, n=n)
    if first is None:
        raise RuntimeError(f"Petviashvili iteration did not reach tol={tol:g} in "
                           f"max_iter={max_iter} iterations (residual {history[-1]:.3g})")
    return best[0], np.array(history[: best[2] + 1])


def _trig_eval(f, ppg):
    """g(x, order): derivative of the trig interpolant of samples f at x = 0, 1/ppg, ..."""
    c = np.fft.fft(f) / f.size
    k = 2.0 * np.pi * np.fft.fftfreq(f.size, d=1.0 / ppg)
    if f.size % 2 == 0:
        c[f.size // 2] = 0.0  # the Nyquist mode of a resolved profile is round-off
    return lambda x, order=0: float(np.sum((1j * k) ** order * c * np.exp(1j * k * x)).real)


def _trig_max(f, ppg):
    """Maximum of the trigonometric interpolant of periodic samples f (Newton from argmax)."""
    g = _trig_eval(f, ppg)
    x = np.argmax(f) / ppg
    for _ in range(20):
        d2 = g(x, 2)
        step = float(np.clip(-g(x, 1) / d2, -1.0 / ppg, 1.0 / ppg)) if d2 < 0 else 0.0
        x += step
        if abs(step) < 1e-15:
            break
    return g(x)


def _velocity_profile(w, ppg):
    """-U'(ζ) on the grid, U(ζ) = Σ_{n≥1} w(ζ+n) (u_i = U(i - c - s t))."""
    q = 2.0 * np.pi * rfftfreq(w.size, d=1.0 / ppg)
    wp = irfft(1j * q * rfft(w), n=w.size).reshape(-1, ppg)
    return -(np.cumsum(wp[::-1], axis=0)[::-1] - wp).ravel()  # Σ over later grains


@lru_cache(maxsize=8)
def _sonic_vacuum_wave(ppg, tol, max_iter, exponent=1.5):
    """Normalised δ0 = 0 wave, σ = 1, w = Λ∗w_+^n: (w, history, w_max, ṽ_max).

    The tail is doubly exponential, w_{j+1} ~ w_j^n grain by grain beyond the core
    (English & Pego 2005): the domain covers the compacton's half-width π/(2q) plus
    log 40/log n grains on each side (24 grains for Hertz: w/w_max < 1e-15 at 5 grains
    from the peak), and a tail above 1e-15 of the peak at its ends is an error.
    """
    q = _compacton_wavenumber(exponent)
    n_dom = max(24, 2 * int(np.ceil(np.pi / (2.0 * q) + np.log(40.0) / np.log(exponent))))
    theta = q * (np.arange(n_dom * ppg) - n_dom * ppg // 2) / ppg
    w0 = np.where(np.abs(theta) < np.pi / 2,  # compacton guess
                  np.cos(np.clip(theta, -np.pi / 2, np.pi / 2)) ** (2.0 / (exponent - 1.0)),
                  0.0)
    w, hist = _petviashvili(1.0, 0.0, n_dom, ppg, w0, tol, max_iter, exponent)
    edge = max(np.max(np.abs(w[: 2 * ppg])), np.max(np.abs(w[-2 * ppg :])))
    if edge > 1e-15 * np.max(w):
        raise RuntimeError(f"solitary-wave tail not resolved by the periodic domain of "
                           f"{n_dom} grains (exponent {exponent:g})")
    w.flags.writeable = hist.flags.writeable = False  # cached: shared between calls
    return w, hist, _trig_max(w, ppg), _trig_max(_velocity_profile(w, ppg), ppg)


@lru_cache(maxsize=4)
def _precompressed_wave(target, kind, ppg, tol, max_iter, exponent=1.5):
    """δ0 > 0 (R = δ0 ρ, s² = (k/m) δ0^{n-1} σ²): secant search in y = log(σ²/n - 1).

    Matches ``kind`` "amplitude" (ε = w_max) or "velocity" (σ ṽ_max) to ``target``.
    Cached (as :func:`_sonic_vacuum_wave`; arrays read-only, shared between calls): a
    map's interfaces share their incident wave (``reproduce --full``'s validity map
    solves each of its 3 precompressed waves for 16 points; a solve takes a fraction of
    a second).
    Four entries: a wave is at most 2^22 points (32 MB), in practice ≤ 1e5.
    """
    w, hist, total, n_dom, sigma2 = _solve_precompressed(target, kind, ppg, tol, max_iter,
                                                         exponent)
    w.flags.writeable = hist.flags.writeable = False  # cached: shared between calls
    return w, hist, total, n_dom, sigma2


def _solve_precompressed(target, kind, ppg, tol, max_iter, exponent=1.5):
    """:func:`_precompressed_wave`, uncached."""
    n = exponent
    eps = target  # nesterenko_speed(1, 1, ε, n) is σ of the long-wave relation
    if kind == "velocity":  # long-wave estimate v ≈ V ξ  →  σ ε ≈ target
        for _ in range(30):
            eps = target / nesterenko_speed(1.0, 1.0, eps, exponent=n)
    from scipy.fft import next_fast_len  # lazy: importing scipy is slow, keep it off start-up
    from scipy.optimize import brentq

    mu = nesterenko_speed(1.0, 1.0, eps, exponent=n) ** 2 / n - 1.0
    # tail e^{-κ|z|}: σ² = n (sinh(κ/2)/(κ/2))², evaluated at a smaller σ for margin
    kappa = 2 * brentq(lambda x: np.sinh(x) / x - np.sqrt(1 + 0.7 * mu), 1e-12, 60, xtol=1e-14)
    n_dom = 2 * next_fast_len(int(np.ceil(8.0 + 45.0 / kappa)))
    if n_dom * ppg > 2**22:
        raise ValueError("amplitude too small relative to delta0 (the wave is wider than "
                         f"{2**22 // ppg} grains); raise it or lower points_per_grain")
    # KdV guess: κ² = (n - 1) ε per grain² (docs/physics.md §2; ε/2 for Hertz)
    w = eps * _sech2(min(np.sqrt((n - 1.0) * eps), 1.0)
                     * (np.arange(n_dom * ppg) / ppg - n_dom / 2))

    def quantity(y, w):
        sigma2 = n * (1.0 + np.exp(y))
        w, hist = _petviashvili(sigma2, 1.0, n_dom, ppg, w, tol, max_iter, n)
        val = _trig_max(w, ppg)
        if kind == "velocity":
            val = np.sqrt(sigma2) * _trig_max(_velocity_profile(w, ppg), ppg)
        return np.log(val / target), w, hist, sigma2

    f0, w, hist, sigma2 = quantity(y0 := np.log(mu), w)
    total, y1 = hist.size, y0 - f0 / (1.0 + eps / (1.0 + eps))  # dlog ε/dlog μ ∈ (1, 2)
    for _ in range(40):
        f1, w, hist, sigma2 = quantity(y1, w)
        total += hist.size
        if abs(f1) < 1e-13 or (abs(f1) < 1e-9 and abs(f1) >= abs(f0)):
            break  # converged, or stalled at the conditioning limit (~1e-16/μ)
        y0, y1, f0 = y1, y1 - f1 * (y1 - y0) / (f1 - f0), f1
    else:
        raise RuntimeError("secant iteration for the wave speed did not converge")
    edge = max(np.max(np.abs(w[: 2 * ppg])), np.max(np.abs(w[-2 * ppg :])))
    if edge > max(tol, 1e-15 / (sigma2 / n - 1.0)) * np.max(w):  # round-off ∝ 1/μ
        raise RuntimeError("solitary-wave tail not resolved by the periodic domain")
    return w, hist, total, n_dom, sigma2


@dataclass(frozen=True, eq=False)
class ChainState:
    """Per-grain state of a chain of n identical grains (a DEM initial condition).

    Attributes
    ----------
    displacement : ndarray, shape (n,)
        u_i from static equilibrium, m (u → 0 ahead of the wave, net shift behind).
    velocity : ndarray, shape (n,)
        v_i = du_i/dt, m/s.
    overlap : ndarray, shape (n + 1,)
        Contact overlaps, m (contact 0: left wall, contact n: right wall), with
        overlap_j = δ0 + u_{j-1} - u_j, u_{-1} and u_n the wall displacements below.
    wall_displacement : tuple of float
        (u_{-1}, u_n), m: the wall positions consistent with the wave.  With the wave well
        inside the chain u_{-1} = net shift D (shift the left wall by it) and u_n = 0.
    """

    displacement: np.ndarray
    velocity: np.ndarray
    overlap: np.ndarray
    wall_displacement: tuple[float, float]


@dataclass(frozen=True, eq=False)
class DiscreteSolitaryWave:
    """Exact travelling solitary wave of the lattice (:func:`discrete_solitary_wave`).

    Attributes
    ----------
    k_n, mass, d, delta0 : float
        Contact constant (N/m^n; Hertz: N/m^{3/2}), grain mass (kg), diameter (m), static
        overlap (m).
    speed, grain_rate : float
        Wave speed V (m/s) and s = V/d (grains/s).
    amplitude, velocity_max, net_shift : float
        Peak dynamic overlap r_max - δ0 (m); peak grain velocity, the maximum over time of
        v_i (m/s); D = ∫ (R - δ0) dz, the displacement of the grains behind the wave (m).
    z, overlap : ndarray
        Periodic grid in grains (peak at z = 0) and R(z), m: r_j(t) = R(j - c - s t).
    residual, residual_history : float, ndarray
        Max-norm residual of σ² w - Λ∗G(w) relative to σ² max|w|: final, and at each
        iteration of the final solve (warm-started for δ0 > 0).
    iterations, points_per_grain : int
        Total Petviashvili iterations (all solves of the speed search for δ0 > 0); grid
        points per grain.
    exponent : float
        n of the contact law F = k [r]_+^n (3/2: Hertz).
    """

    k_n: float
    mass: float
    d: float
    delta0: float
    speed: float
    grain_rate: float
    amplitude: float
    velocity_max: float
    net_shift: float
    z: np.ndarray = field(repr=False)
    overlap: np.ndarray = field(repr=False)
    residual: float
    iterations: int
    residual_history: np.ndarray = field(repr=False)
    points_per_grain: int
    exponent: float = 1.5

    @property
    def strain_max(self) -> float:
        """Peak dynamic strain ξ_max = (r_max - δ0)/d."""
        return self.amplitude / self.d

    @property
    def speed_constant(self) -> float:
        """V / (c ξ_max^{(n-1)/2}), c = √(k d^{n+1}/m): amplitude independent at δ0 = 0.

        The long-wave compacton gives √(2/(n+1)) (2/√5 for Hertz, paper Eq. 8).
        """
        n = self.exponent
        c_mat = np.sqrt(self.k_n * self.d ** (n + 1.0) / self.mass)
        return float(self.speed / (c_mat * self.strain_max ** (0.5 * (n - 1.0))))

    def momentum(self) -> float:
        """Momentum Σ_i m v_i of the wave, kg·m/s: exactly m s D.

        Behind the wave every grain is shifted by D, ahead of it by 0, and the wave moves
        s grains per second, so d/dt Σ_i u_i = s D whatever the phase.
        """
        return float(self.mass * self.grain_rate * self.net_shift)

    def energy(self, phase: float = 0.0) -> float:
        r"""Energy of the wave, J: :math:`\sum_i \tfrac12 m v_i^2 + \sum_j [U(r_j) - U(\delta_0)]`.

        U(r) = k r^{n+1}/(n+1) the contact's elastic energy (docs/physics.md §6: the
        wave energy of the chain, linear term kept).  Evaluated on the grains with the
        peak at fractional position ``phase`` (in [0, 1)); the exact wave's energy is
        conserved, so independent of the phase up to the spectral sampling's round-off
        (7e-15 relative).
        """
        n_dom = self.z.size // self.points_per_grain
        st = self.sample(n_dom, n_dom // 2 + float(phase))
        n1 = self.exponent + 1.0
        r = st.overlap

        def pot(x):
            return self.k_n * np.maximum(x, 0.0) ** n1 / n1

        return float(0.5 * self.mass * np.sum(st.velocity**2)
                     + np.sum(pot(r) - pot(self.delta0)))

    def width(self, level: float = 0.5) -> float:
        """Full width in grains of the region where R - δ0 > level × amplitude (0.5: FWHM)."""
        from scipy.optimize import brentq

        level = float(check_range("level", level, 0.0, 1.0))
        w = (self.overlap - self.delta0) / self.amplitude
        g, i = _trig_eval(w, self.points_per_grain), np.nonzero(w > level)[0][-1]
        return 2.0 * brentq(lambda x: g(x - self.z[0]) - level, self.z[i], self.z[i + 1])

    def sample(self, n_grains: int, center: float, t: float = 0.0) -> ChainState:
        """Per-grain displacements, velocities and contact overlaps at time t.

        Contact j's overlap is r_j(t) = R(j - center - s t): ``center`` is the (real)
        contact index of the peak at t = 0.  With w = R - δ0 and ζ_i = i - center - s t,
        u_i - u_{i+1} = w(ζ_i + 1), so u_i = Σ_{n≥1} w(ζ_i + n) (u → 0 ahead) and
        v_i = -s Σ_{n≥1} w'(ζ_i + n), w' spectral; off-grid values by an exact spectral
        sub-grid shift (all ζ_i share one fractional part).

        Parameters
        ----------
        n_grains : int
            Number of grains (>= 1).
        center, t : float
            Contact index of the peak at t = 0; time, s.
        """
        if int(n_grains) != n_grains or n_grains < 1:
            raise ValueError(f"n_grains must be an integer >= 1 (got {n_grains!r})")
        ppg, n_tot = self.points_per_grain, self.z.size
        phi = -(float(check_finite("center", center)) + self.grain_rate * float(
            check_finite("t", t))) * ppg  # ζ_0 - z_0 = (n_tot/2 + phi)/ppg
        base = np.floor(phi)
        q = 2.0 * np.pi * rfftfreq(n_tot, d=1.0 / ppg)
        w_hat = rfft(self.overlap - self.delta0) * np.exp(1j * q * (phi - base) / ppg)
        k_base = n_tot // 2 + int(base)  # grid index of ζ_0 after the sub-grid shift
        col = k_base % ppg
        w = irfft(w_hat, n=n_tot).reshape(-1, ppg)[:, col]  # w(ζ_0 + g - g0), g = 0, 1, ..
        wp = irfft(1j * q * w_hat, n=n_tot).reshape(-1, ppg)[:, col]
        g = np.arange(-1, int(n_grains) + 1) + (k_base - col) // ppg  # row of ζ_j
        gc = np.clip(g + 1, 0, w.size)  # U(ζ_g) = Σ_{g' > g} w_{g'}
        u = np.append(np.cumsum(w[::-1])[::-1], 0.0)[gc]
        # Σ_{g' >= g} w'_{g'}, summed from the quiet side nearer to row g: ahead of the peak
        # from the right, behind it from the left as -Σ_{g' < g} w'_{g'} (equal: the exact
        # wave has no Fourier content at multiples of 2π per grain, Σ_g w'_g = 0).  A sum
        # from the right alone gave every grain behind the domain the round-off of the
        # whole sum as its velocity (3.6e-12 of the peak at strain/δ0 = 1e-3, 2,430
        # grains), so such a wave could not be placed (exact_wave's 1e-12 tail check).
        suffix = np.append(np.cumsum(wp[::-1])[::-1], 0.0)
        prefix = -np.concatenate(([0.0], np.cumsum(wp)))
        behind = np.arange(w.size + 1) <= int(np.argmax(np.abs(w)))
        vel = -self.grain_rate * np.where(behind, prefix, suffix)[gc]
        r = self.delta0 + np.where((g >= 0) & (g < w.size), w[np.clip(g, 0, w.size - 1)], 0)
        return ChainState(displacement=u[1:-1], velocity=vel[1:-1], overlap=r[1:],
                          wall_displacement=(float(u[0]), float(u[-1])))


def discrete_solitary_wave(
    k_n: float, mass: float, d: float, delta0: float = 0.0, *,
    amplitude: float | None = None, velocity_max: float | None = None,
    points_per_grain: int = 32, tol: float = 1e-13, max_iter: int = 500,
    exponent: float = 1.5,
) -> DiscreteSolitaryWave:
    r"""Exact solitary wave of the chain with F = k[r]_+^n, δ0 = 0 or δ0 > 0 (Petviashvili + FFT).

    Derivation (Friesecke & Wattis 1994; MacKay 1999; English & Pego 2005; Ahnert &
    Pikovsky 2009, PRE 79, 026209).  The overlaps obey m r̈_j = F(r_{j-1}) - 2F(r_j)
    + F(r_{j+1}), F(r) = k [r]_+^n (paper Eqs. 1-2 for Hertz, n = 3/2; any power law,
    Nesterenko 2001, *Dynamics of Heterogeneous Materials*, §1.1).  A travelling wave
    r_j(t) = R(j - s t), s = V/d, satisfies s² R'' = (k/m) Δ₂F(R); in Fourier space
    R̂ = (k/(m s²)) sinc²(q/2) F̂(R), i.e. R = (k/(m s²)) Λ∗F(R), Λ the hat function.
    With R = λρ and s² = (k/m) λ^{n-1} σ²:

    * δ0 = 0 (σ = 1, λ free): ρ = Λ∗ρ_+^n, homogeneous of degree p = n; solved once and
      rescaled (English & Pego, Proc. AMS 133 (2005) 1763), A ∝ λ, V ∝ λ^{(n-1)/2},
      v_max ∝ λ^{(n+1)/2}, hence V ∝ v_max^{(n-1)/(n+1)} (1/5 for Hertz: V ∝ A^{1/4})
      and γ = n/(n-1) (3 for Hertz).
    * δ0 > 0 (λ = δ0, w = ρ - 1): σ² w = Λ∗(K w + N(w)), K = n (K = n k δ0^{n-1} in
      units), N = (1+w)^n - 1 - K w.  L = σ² - K sinc²(q/2) is positive iff σ² > n,
      i.e. V > c0 (:func:`theory.speeds.c0`); σ is found by a secant search matching A
      (or v_max), started from the long-wave speed (:func:`theory.speeds.nesterenko_speed`).

    Petviashvili iteration ŵ ← M^γ Λ̂ N̂(w)/L, M = ⟨w, L w⟩/⟨w, Λ∗N(w)⟩ (Pelinovsky &
    Stepanyants 2004, SIAM J. Numer. Anal. 42, 1110), γ = p/(p-1): n/(n-1) for δ0 = 0,
    2 for δ0 > 0 (quadratic leading order); past ``tol`` it goes on while the residual
    falls.  The periodic grid covers the tail: doubly exponential at δ0 = 0, e^{-κ|z|}
    with σ² = n (sinh(κ/2)/(κ/2))² for δ0 > 0 (wide for small amplitudes).

    Parameters
    ----------
    k_n, mass : float
        Contact constant (N/m^n; Hertz: N/m^{3/2}) and grain mass (kg).
    d, delta0 : float
        Grain diameter (> 0) and static overlap (>= 0), m.
    amplitude, velocity_max : float, optional
        Exactly one: peak dynamic overlap r_max - δ0 (m) or peak grain velocity (m/s).
    points_per_grain, tol, max_iter : int, float, int
        Grid points per grain, in [8, 256]; relative max-norm residual required, in
        (0, 1e-6]; maximum Petviashvili iterations per solve.
    exponent : float
        n of the contact law F = k[r]_+^n, in (1, 10] (3/2: Hertz).

    Returns
    -------
    DiscreteSolitaryWave
    """
    k_n, mass, d = map(float, map(check_positive, ("k_n", "mass", "d"), (k_n, mass, d)))
    delta0 = float(check_nonnegative("delta0", delta0))
    if (amplitude is None) == (velocity_max is None):
        raise ValueError("give exactly one of amplitude (m, > 0) or velocity_max (m/s, > 0)")
    use_amp = amplitude is not None
    target = float(check_positive(*(("amplitude", amplitude) if use_amp else
                                    ("velocity_max", velocity_max))))
    for name, val, lo, hi in (("points_per_grain", points_per_grain, 8, 256),
                              ("max_iter", max_iter, 1, 10**6)):
        if int(val) != val or not lo <= val <= hi:
            raise ValueError(f"{name} must be an integer in [{lo}, {hi}] (got {val!r})")
    ppg, max_iter = int(points_per_grain), int(max_iter)
    tol = float(check_range("tol", tol, 0.0, 1e-6, closed=(False, True)))
    n = check_exponent(exponent, closed_low=False)
    rate = np.sqrt(k_n / mass)  # s² = rate² λ^{(n-1)} σ²;  v = s λ ṽ
    if delta0 == 0.0:
        w, hist, w_max, v_max = _sonic_vacuum_wave(ppg, tol, max_iter, n)
        lam = target / w_max if use_amp else (target / (rate * v_max)) ** (2.0 / (n + 1.0))
        sigma, n_dom, total = 1.0, w.size // ppg, hist.size
    else:
        lam, kind = delta0, "amplitude" if use_amp else "velocity"
        target /= delta0 if use_amp else rate * delta0 ** (0.5 * (n + 1.0))
        w, hist, total, n_dom, sigma2 = _precompressed_wave(target, kind, ppg, tol, max_iter,
                                                            n)
        sigma = np.sqrt(sigma2)
        w_max, v_max = _trig_max(w, ppg), _trig_max(_velocity_profile(w, ppg), ppg)
    s = rate * lam ** (0.5 * (n - 1.0)) * sigma
    return DiscreteSolitaryWave(
        k_n=k_n, mass=mass, d=d, delta0=delta0, speed=float(s * d), grain_rate=float(s),
        amplitude=float(lam * w_max), velocity_max=float(s * lam * v_max),
        net_shift=float(lam * np.sum(w) / ppg),
        z=(np.arange(n_dom * ppg) - n_dom * ppg // 2) / ppg, overlap=delta0 + lam * w,
        residual=float(hist[-1]), iterations=int(total), residual_history=hist,
        points_per_grain=ppg, exponent=n,
    )


def discrete_speed_constant(points_per_grain: int = 32, exponent: float = 1.5) -> float:
    """V / (c ξ_max^{(n-1)/2}) of the exact lattice wave at δ0 = 0 (cf. √(2/(n+1)) of Eq. 8).

    With R = λρ, V = d √(k/m) λ^{(n-1)/2} and ξ_max = λ ρ_max/d, it is
    ρ_max^{-(n-1)/2} of the normalised solution ρ = Λ∗ρ_+^n (see
    :func:`discrete_solitary_wave`); for Hertz ρ_max^{-1/4}, against the compacton's 2/√5.
    """
    return discrete_solitary_wave(1, 1, 1, amplitude=1, points_per_grain=points_per_grain,
                                  exponent=exponent).speed_constant


@dataclass(frozen=True)
class SonicVacuumWave:
    """Dimensionless constants of the exact lattice solitary wave at δ0 = 0, F = k r^n.

    For grains of mass m (kg) and spacing d (m), contact constant k (N/m^n), and a wave of
    peak grain velocity v (m/s), with u = v √(m/k) (m^{(n+1)/2}):

    * energy E = ``energy`` · m v² (J), momentum P = ``momentum`` · m v (kg m/s);
    * peak dynamic overlap A = ``amplitude`` · u^{2/(n+1)} (m), peak force k A^n (N);
    * speed V = ``rate`` · d √(k/m) u^{(n-1)/(n+1)} (m/s);
    * phase-averaged kinetic energy = ``kinetic_fraction`` · E;
    * ``kk_integral`` = ∫ R^{1/2} R′² dz and ``dashpot_integral`` = ∫ R′² dz over the
      profile R(z) (m^{5/2} and m²; z in grains) of the wave with k = m = 1, v = 1:
      the power dissipated by a Kuwabara–Kono or a linear dashpot in the wave
      (:mod:`theory.dissipation`).

    Attributes
    ----------
    exponent, energy, momentum, amplitude, rate, kinetic_fraction, kk_integral,
    dashpot_integral : float
    """

    exponent: float
    energy: float
    momentum: float
    amplitude: float
    rate: float
    kinetic_fraction: float
    kk_integral: float
    dashpot_integral: float


@lru_cache(maxsize=16)
def sonic_vacuum_wave_constants(exponent: float = 1.5) -> SonicVacuumWave:
    """Constants of the exact lattice wave at δ0 = 0 (:class:`SonicVacuumWave`).

    Computed once per exponent from :func:`discrete_solitary_wave` with k = m = d = 1
    and v_max = 1 (the wave is self-similar: r = λρ, s ∝ λ^{(n-1)/2}, v ∝ λ^{(n+1)/2};
    Nesterenko 2001 §1.1; English & Pego 2005), energy and momentum by
    :meth:`DiscreteSolitaryWave.energy` / ``momentum``, the kinetic energy averaged
    over 16 phases between two grains, the integrals spectrally on the profile's grid.
    For Hertz: energy 1.0693, momentum 1.6700.  The kinetic fraction is (n+1)/(n+3)
    (5/9 for Hertz): the virial theorem for a homogeneous potential of degree n+1,
    2⟨K⟩ = (n+1)⟨U⟩ averaged over the passage of a grain (Landau & Lifshitz, *Mechanics*,
    §10), which the computed wave satisfies to 1e-14.  ``rate`` divided by
    ``amplitude`` to the power (n-1)/2 is :func:`discrete_speed_constant`.  Used by the
    adiabatic taper wave, the striker's
    train and the damped waves (:mod:`theory.tapers`, :mod:`theory.striker`,
    :mod:`theory.dissipation`).

    Parameters
    ----------
    exponent : float
        n of F = k r^n, in (1, 10].
    """
    n = check_exponent(exponent, closed_low=False)
    w = discrete_solitary_wave(1.0, 1.0, 1.0, velocity_max=1.0, exponent=n)
    kin = np.mean([0.5 * np.sum(w.sample(w.z.size // w.points_per_grain,
                                         w.z.size // (2 * w.points_per_grain) + ph).velocity**2)
                   for ph in np.arange(16) / 16])
    energy = w.energy()
    r = np.maximum(w.overlap, 0.0)
    q = 2 * np.pi * rfftfreq(r.size, d=1.0 / w.points_per_grain)
    dr = irfft(1j * q * rfft(r), n=r.size)
    dz = 1.0 / w.points_per_grain
    return SonicVacuumWave(exponent=n, energy=float(energy), momentum=float(w.momentum()),
                           amplitude=float(w.amplitude), rate=float(w.grain_rate),
                           kinetic_fraction=float(kin / energy),
                           kk_integral=float(np.sum(np.sqrt(r) * dr**2) * dz),
                           dashpot_integral=float(np.sum(dr**2) * dz))
