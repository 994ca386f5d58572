r"""Vertical chains under gravity: static load, local speeds, arrival times along the depth.

A vertical chain of N identical grains (mass m, diameter d), grain 0 on top, stands on a
floor; contact j (between grains j-1 and j, j = 1 … N-1) carries the weight of the j
grains above it and the force F_top on the top grain (Sinkovits & Sen, Phys. Rev. Lett.
74 (1995) 2686):

.. math:: F_j = F_{top} + j\,m g, \qquad k\,\delta_{0,j}^{\,n} = F_j .

A wave launched downward meets a precompression that grows with depth.  Two regimes:

* **Solitary wave** (an impact strong enough that the pulse is a solitary wave on the
  local load): the local speed is Nesterenko's long-wave speed for exponent n at the
  local δ0 and the local amplitude (:func:`theory.speeds.nesterenko_speed`); the
  amplitude follows adiabatically from the conservation of the wave's energy
  (:func:`solitary_wave_energy`, :func:`solitary_wave_descent`).  The energy conserved
  is that of the disturbance, :math:`E = \sum_i \tfrac12 m v_i^2 + \sum_j [U(r_j) -
  U(\delta_{0,j}) - F_j (r_j - \delta_{0,j})]` with U(r) = k r^{n+1}/(n+1): with
  m ü_i = F(r_i) - F(r_{i+1}) + m g and F_{j+1} - F_j = m g its time derivative vanishes
  exactly (the work of gravity on the displaced grains is the linear term), so E is an
  exact invariant of the chain and, to leading order in the slow variation, of the
  solitary wave.
* **Weak pulse** (ξ_max ≪ ξ0 from the start): the pulse is a linear dispersive front
  whose amplitude falls as a power of the depth (Hong, Ji & Kim, Phys. Rev. Lett. 82
  (1999) 3058: phase speed ∝ h^{(1-1/n)/2}, grain velocity ∝ h^{-(1/3+1/n)/4},
  :func:`weak_wave_depth_exponents`); its leading peak trails the sound-speed travel
  time by the Airy delay of the lattice dispersion (:func:`weak_pulse_arrival_times`).

The local sound speed is :func:`theory.speeds.c0` at the local δ0: with F_top = 0,
δ0 ∝ depth^{1/n}, so c0 ∝ depth^{(n-1)/(2n)}, depth^{1/6} for Hertz (Sinkovits & Sen
1995; Hong et al. 1999).  Arrival times against the discrete chain: docs/physics.md §14.

The long-wave relations for exponent n live in :mod:`theory.speeds` (speeds) and
:mod:`theory.profiles` (the compacton's width); this module adds the wave's energy
(:func:`solitary_wave_energy`, :func:`solitary_wave_amplitude`), which does not depend on
gravity either.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ._numerics import power_remainder
from ._validate import check_nonnegative, check_positive, check_range
from .precompression import static_overlap
from .speeds import c0, c_mat, nesterenko_speed

__all__ = [
    "static_forces_under_gravity",
    "static_overlaps_under_gravity",
    "solitary_wave_energy",
    "solitary_wave_amplitude",
    "DepthExponents",
    "weak_wave_depth_exponents",
    "VerticalWave",
    "solitary_wave_descent",
    "weak_pulse_arrival_times",
]

EXPONENT_RANGE = (1.0, 10.0)
"""Allowed contact-law exponents n of F = k δ^n: (1, 10] (n = 1 has no solitary wave)."""

AIRY_PEAK = 1.0187929716474715
"""s = 1.01879…: Ai(-s) has its first maximum there (first zero of Ai′, Abramowitz & Stegun
10.4.95; a literal, not ``scipy.special.ai_zeros`` at import, which would load SciPy on
every start-up; tests check it against ``ai_zeros``)."""


def _ret(x):
    x = np.asarray(x, dtype=float)
    return x if x.ndim else float(x)


def _exponent(exponent) -> float:
    return float(check_range("exponent", exponent, *EXPONENT_RANGE, closed=(False, True)))


# ------------------------------------------------------------------ static load
def static_forces_under_gravity(n_grains: int, mass: float, g: float, *,
                                top_force: float = 0.0) -> np.ndarray:
    """Static contact forces of a vertical chain, N (Sinkovits & Sen 1995).

    Returns F_j = F_top + j m g for the contacts j = 0 … N: contact 0 is the top wall (it
    carries F_top), contact j ≥ 1 lies below grain j-1, contact N is the floor.

    Parameters
    ----------
    n_grains : int
        Number of grains N (>= 1).
    mass : float
        Grain mass m, kg (> 0).
    g : float
        Acceleration of gravity along the chain, m/s² (>= 0).
    top_force : float
        Force pressing on the top grain, N (>= 0).
    """
    if int(n_grains) != n_grains or n_grains < 1:
        raise ValueError(f"n_grains must be an integer >= 1 (got {n_grains!r})")
    m = float(check_positive("mass", mass))
    g = float(check_nonnegative("g", g))
    f_top = float(check_nonnegative("top_force", top_force))
    return f_top + m * g * np.arange(int(n_grains) + 1, dtype=float)


def static_overlaps_under_gravity(n_grains: int, mass: float, k: float, g: float, *,
                                  exponent: float = 1.5, top_force: float = 0.0) -> np.ndarray:
    """Static overlaps δ0_j = (F_j/k)^{1/n} of the contacts j = 0 … N of a vertical chain, m.

    F_j from :func:`static_forces_under_gravity`; k in N/m^n (> 0), the same at every
    contact (a floor of another constant: rescale its entry).
    """
    forces = static_forces_under_gravity(n_grains, mass, g, top_force=top_force)
    return static_overlap(forces, float(check_positive("k", k)), exponent=_exponent(exponent))


_N_NODES = 96
_GL_X, _GL_W = np.polynomial.legendre.leggauss(_N_NODES)
_PHI = (_GL_X + 1.0) * np.pi / 4.0  # x = sin²φ on [0, π/2]
_W_PHI = _GL_W * np.pi / 4.0


def _energy_integral(a: np.ndarray, n: float) -> np.ndarray:
    r"""ε(a) = E/(k δ0^{n+1}) of the long-wave solitary wave of amplitude a = A/δ0 > 0.

    Nesterenko's long-wave equation for F ∝ δ^n in the strain ξ = δ/d (Nesterenko,
    *Dynamics of Heterogeneous Materials*, 2001, ch. 1; docs/physics.md §15),
    ξ_tt = c²[ξ^n + (n d²/(6(n+1))) ξ^{(n-1)/2}(ξ^{(n+1)/2})_xx]_xx, c² = k d^{n+1}/m,
    has travelling waves ξ(x - Vt) → ξ0 with V² = 2 c² ξ0^{n-1} h(a)/a²,
    h(y) = ((1+y)^{n+1} - 1)/(n+1) - y (:func:`theory.speeds.nesterenko_speed`; h without
    cancellation by :func:`theory._numerics.power_remainder`).  With ξ = ξ0(1 + a x), x ∈ [0, 1],
    H = ξ0^{n+1} h(ax), G = ξ0^{n+1} g(x), g(x) = h(a) x² - h(ax) (g(1) = 0 is the speed
    relation), the profile has ξ′² = 24 G ξ^{1-n}/(n d²) and the energy
    density per grain is m c² (G + 2H) (kinetic ½ m V² (ξ-ξ0)² = m c²(G + H), potential
    m c² H), so

    .. math:: ε(a) = 2\sqrt{n/24}\; a \int_0^1 \frac{(g + 2h(ax))\,(1+ax)^{(n-1)/2}}
              {\sqrt{g}}\,dx,

    evaluated with x = sin²φ (which removes the 1/√(1-x) end point) by Gauss–Legendre;
    g/(1-x) is summed as a series for a < 1/2 (no cancellation for weak waves).
    """
    a = np.atleast_1d(np.asarray(a, dtype=float))[:, None]
    x = np.sin(_PHI) ** 2
    one_m_x = np.cos(_PHI) ** 2
    hax = power_remainder(a * x, n + 1.0) / (n + 1.0)  # h(ax)
    # q = g / (1 - x): direct for a >= 1/2, series Σ_j c_j a^j x² (1 - x^{j-2})/(1 - x)
    # (c_j = C(n+1, j)/(n+1), the Taylor coefficients of h) below
    j = np.arange(3, 64)
    from scipy.special import binom  # lazy: importing scipy costs start-up

    cj = binom(n + 1, j) / (n + 1)
    geo = -np.expm1((j - 2) * np.log(x)[:, None]) / one_m_x[:, None]  # (nodes, terms)
    asmall = np.minimum(a, 0.5)
    q_ser = (asmall[..., None] ** j * cj * geo).sum(axis=-1) * x**2
    q_dir = (power_remainder(a, n + 1.0) / (n + 1.0) * x**2 - hax) / one_m_x
    q = np.where(a < 0.5, q_ser, q_dir)
    f = (q * one_m_x + 2.0 * hax) * (1.0 + a * x) ** ((n - 1) / 2)
    integral = np.sum(f * 2.0 * np.sin(_PHI) / np.sqrt(q) * _W_PHI, axis=1)
    return 2.0 * np.sqrt(n / 24.0) * a[:, 0] * integral


def _energy_sonic_vacuum(n: float) -> float:
    r"""E/(k A^{n+1}) of the long-wave wave at δ0 = 0 (the compacton), closed form.

    With ξ = ξ_m x: g = (x² - x^{n+1})/(n+1), h = x^{n+1}/(n+1), and the integral of
    :func:`_energy_integral` becomes Beta functions (y = x^{n-1}):
    2√(n/(24(n+1))) [B((n+3)/(2n-2), 1/2) + B((3n+1)/(2n-2), 1/2)]/(n-1).
    """
    from scipy.special import beta as beta_fn  # lazy: importing scipy costs start-up

    b = beta_fn((n + 3) / (2 * (n - 1)), 0.5) + beta_fn((3 * n + 1) / (2 * (n - 1)), 0.5)
    return float(2.0 * np.sqrt(n / (24.0 * (n + 1))) * b / (n - 1))


@lru_cache(maxsize=16)
def _energy_table(n: float):
    """Splines of log ε against log a and back, a ∈ [1e-10, 1e10] (600 points)."""
    from scipy.interpolate import CubicSpline  # (lazy: scipy.* costs start-up where unused)
    la = np.linspace(np.log(1e-10), np.log(1e10), 600)
    le = np.log(_energy_integral(np.exp(la), n))
    return CubicSpline(la, le), CubicSpline(le, la), la, le


def solitary_wave_energy(k, delta0, amplitude, *, exponent: float = 1.5):
    r"""Energy of the long-wave solitary wave of dynamic overlap A at static overlap δ0, J.

    The disturbance energy Σ ½ m v² + Σ [U(r) - U(δ0) - F0 (r - δ0)] (U = k r^{n+1}/(n+1),
    the linear term subtracted: the part paid by the walls or by gravity) of the
    travelling wave of :func:`theory.speeds.nesterenko_speed`, integrated over its profile
    (:func:`_energy_integral`):

    .. math:: E = k\,\delta_0^{n+1}\,ε_n(A/\delta_0), \qquad
              E \xrightarrow{\delta_0 \to 0} k A^{n+1} ε_n^{(0)},

    ε_n^{(0)} in Beta functions (1.03227 for Hertz), and E → (4n/(3√(n-1))) k δ0^{n+1}
    (A/δ0)^{3/2} as A/δ0 → 0 (the KdV sech² wave).  Mass and spacing drop out.  Against
    the exact lattice wave for Hertz (same amplitude): −1.4 % at δ0 = 0, +0.01 % at
    A = 0.01 δ0, +0.5 % at A = δ0.

    Parameters
    ----------
    k : float or array
        Contact constant, N/m^n (> 0).
    delta0 : float or array
        Static overlap, m (>= 0).
    amplitude : float or array
        Dynamic overlap A, m (> 0).
    exponent : float
        n, in (1, 10].
    """
    n = _exponent(exponent)
    k = check_positive("k", k)
    amp = check_positive("amplitude", amplitude)
    delta0 = check_nonnegative("delta0", delta0)
    k, delta0, amp = np.broadcast_arrays(k, delta0, amp)
    out = np.array(k * amp ** (n + 1) * _energy_sonic_vacuum(n), dtype=float)
    pre = delta0 > 0
    if np.any(pre):
        a = amp[pre] / delta0[pre]
        big = a > 1e10  # the sonic-vacuum limit (relative error < 1e-9 there)
        e = np.empty(a.shape)
        e[~big] = k[pre][~big] * delta0[pre][~big] ** (n + 1) * _energy_integral(a[~big], n)
        e[big] = out[pre][big]
        out[pre] = e
    return _ret(out)


def solitary_wave_amplitude(energy, k, delta0, *, exponent: float = 1.5):
    """Dynamic overlap A of the long-wave solitary wave of a given energy, m.

    Inverse of :func:`solitary_wave_energy` (monotonic in A): closed form at δ0 = 0,
    A = (E/(k ε_n^{(0)}))^{1/(n+1)}; for δ0 > 0 a spline of log ε_n against log a on
    a ∈ [1e-10, 1e10] (relative error < 1e-7), the KdV and sonic-vacuum power laws beyond.

    Parameters
    ----------
    energy : float or array
        Wave energy, J (> 0).
    k : float or array
        Contact constant, N/m^n (> 0).
    delta0 : float or array
        Static overlap, m (>= 0).
    exponent : float
        n, in (1, 10].
    """
    n = _exponent(exponent)
    energy = check_positive("energy", energy)
    k = check_positive("k", k)
    delta0 = check_nonnegative("delta0", delta0)
    energy, k, delta0 = np.broadcast_arrays(energy, k, delta0)
    e0 = _energy_sonic_vacuum(n)
    out = np.array((energy / (k * e0)) ** (1 / (n + 1)), dtype=float)
    pre = delta0 > 0
    if np.any(pre):
        _, inverse, la, le = _energy_table(n)
        with np.errstate(divide="ignore", over="ignore"):
            target = np.log(energy[pre] / k[pre]) - (n + 1) * np.log(delta0[pre])
        a = np.exp(inverse(np.clip(target, le[0], le[-1])))
        low = target < le[0]  # KdV limit: ε = (4n/(3√(n-1))) a^{3/2}
        a[low] = (np.exp(target[low]) * 3 * np.sqrt(n - 1) / (4 * n)) ** (2 / 3)
        high = target > le[-1]  # sonic vacuum: ε → ε0 a^{n+1}
        out_pre = np.where(high, out[pre], a * delta0[pre])
        out[pre] = out_pre
    return _ret(out)


# ------------------------------------------------------------------ depth laws
@dataclass(frozen=True)
class DepthExponents:
    """Power laws of a weak pulse along a vertical chain, quantity ∝ depth^exponent.

    Attributes
    ----------
    phase_speed : float
        (1 - 1/n)/2: the local sound speed (1/6 for Hertz).
    displacement : float
        -(1 - 1/n)/4: the grain-displacement signal (-1/12 for Hertz).
    velocity : float
        -(1/3 + 1/n)/4: the leading grain-velocity peak (-1/4 for Hertz).
    """

    phase_speed: float
    displacement: float
    velocity: float


def weak_wave_depth_exponents(exponent: float = 1.5) -> DepthExponents:
    """Depth exponents of a weak impulse in a vertical chain (Hong, Ji & Kim 1999).

    Hong, Ji & Kim, Phys. Rev. Lett. 82 (1999) 3058, abstract and their analysis of the
    linearised chain under gravity with F = k δ^p: phase velocity ∝ h^{(1-1/p)/2},
    displacement ∝ h^{-(1-1/p)/4}, grain velocity ∝ h^{-(1/3+1/p)/4} (measured on the
    leading peak, 0.250 for Hertz: arXiv:patt-sol/9808008).  The phase-speed
    law is that of :func:`theory.speeds.c0` with δ0 ∝ h^{1/n}.

    Parameters
    ----------
    exponent : float
        n = p of F = k δ^n, in (1, 10].
    """
    n = _exponent(exponent)
    return DepthExponents(phase_speed=0.5 * (1 - 1 / n), displacement=-0.25 * (1 - 1 / n),
                          velocity=-0.25 * (1 / 3 + 1 / n))


# ------------------------------------------------------------------ arrival times
@dataclass(frozen=True)
class VerticalWave:
    """A solitary wave descending a vertical chain (:func:`solitary_wave_descent`).

    Attributes
    ----------
    delta0 : ndarray, shape (N-1,)
        Static overlap of contacts 1 … N-1 (below grains 0 … N-2), m.
    amplitude : ndarray, shape (N-1,)
        Dynamic overlap A of the adiabatic wave at each contact, m.
    speed : ndarray, shape (N-1,)
        Its speed there, m/s.
    velocity_max : ndarray, shape (N-1,)
        Its peak grain velocity V A/d, m/s.
    arrival_time : ndarray, shape (N,)
        Time at which its peak passes grain i, s (grain 0, the struck top grain: 0).
    """

    delta0: np.ndarray
    amplitude: np.ndarray
    speed: np.ndarray
    velocity_max: np.ndarray
    arrival_time: np.ndarray


def _vertical(n_grains, mass, k, d, g, top_force, exponent):
    n = _exponent(exponent)
    if int(n_grains) != n_grains or n_grains < 2:
        raise ValueError(f"n_grains must be an integer >= 2 (got {n_grains!r})")
    mass, k, d = (float(check_positive(a, b)) for a, b in
                  (("mass", mass), ("k", k), ("d", d)))
    delta0 = static_overlaps_under_gravity(n_grains, mass, k, g, exponent=n,
                                           top_force=top_force)[1:-1]
    if not np.all(delta0 > 0):
        raise ValueError("g must be > 0 m/s² or top_force > 0 N (a loaded chain; got no load)")
    return n, mass, k, d, delta0


def solitary_wave_descent(n_grains: int, mass: float, k: float, d: float, g: float,
                          energy: float, *, exponent: float = 1.5,
                          top_force: float = 0.0) -> VerticalWave:
    r"""Adiabatic solitary wave descending a vertical chain of identical grains.

    At contact j the wave is the long-wave solitary wave of the local static overlap
    δ0_j (:func:`static_overlaps_under_gravity`) carrying the conserved energy E
    (module docstring): A_j = :func:`solitary_wave_amplitude` (E, k, δ0_j), speed
    V_j = :func:`theory.speeds.nesterenko_speed` (at ξ0 = δ0_j/d, ξ_max = A_j/d).  It
    passes grain i at

    .. math:: t_i = \sum_{j=1}^{i} d / V_j

    (midpoint rule: the peak crosses contact j between grains j-1 and j).  Valid while
    the wave is a solitary wave of the local load: an impact whose wave is strongly
    nonlinear near the top (A ≳ δ0 there).  Against the discrete chain of 300 steel
    grains the arrival times agree to ≤ 0.9 % for impacts of 0.01 … 1 m/s from grain 10
    on, ≤ 2.6 % from the struck grain (docs/physics.md §14).  Far down, where A ≪ δ0,
    V → c0 and the amplitude stops mattering; the simulated pulse there is no longer
    adiabatic (its amplitude falls more slowly than this one's, as Hong et al.'s weak
    pulse does), which changes the arrival times by < 0.1 %.

    Parameters
    ----------
    n_grains : int
        Number of grains N (>= 2).
    mass, k, d : float
        Grain mass (kg), contact constant (N/m^n), diameter (m).
    g : float
        Gravity, m/s² (>= 0; with top_force, not both 0).
    energy : float
        Wave energy E, J (> 0).  An impact of the top grain at v0 puts ½ m v0² into the
        chain, 99.4 % of it into the leading wave (Hertz, δ0 = 0).
    exponent : float
        n of F = k δ^n, in (1, 10].
    top_force : float
        Static force on the top grain, N (>= 0).
    """
    n, mass, k, d, delta0 = _vertical(n_grains, mass, k, d, g, top_force, exponent)
    energy = float(check_positive("energy", energy))
    amp = np.asarray(solitary_wave_amplitude(energy, k, delta0, exponent=n), dtype=float)
    speed = np.asarray(nesterenko_speed(c_mat(k, mass, d, n), delta0 / d, amp / d, n),
                       dtype=float)
    arrival = np.r_[0.0, np.cumsum(d / speed)]
    return VerticalWave(delta0=delta0, amplitude=amp, speed=speed,
                        velocity_max=speed * amp / d, arrival_time=arrival)


def weak_pulse_arrival_times(n_grains: int, mass: float, k: float, d: float, g: float, *,
                             exponent: float = 1.5, top_force: float = 0.0) -> np.ndarray:
    r"""Arrival time of a weak pulse's leading velocity peak at each grain, s.

    Linearised about the local load, the chain has ω = c0 q (1 - q²d²/24 + …) with c0
    from :func:`theory.speeds.c0`, i.e. q(ω) = ω/c0 + ω³d²/(24 c0³).  A short pulse
    launched at the top (an impact of grain 0: v_i = v0 J_{2i}(ω_max t) on a uniform
    chain, whose front is an Airy function) accumulates, in the WKB approximation for a
    slowly varying c0, the phase ω τ_i + ω³ Λ_i with

    .. math:: \tau_i = \sum_{j=1}^{i}\frac{d}{c_{0,j}}, \qquad
              \Lambda_i = \sum_{j=1}^{i}\frac{d^3}{24\,c_{0,j}^3},

    so v_i ∝ Ai(-(t - τ_i)/(3Λ_i)^{1/3}) and the leading peak passes at
    t_i = τ_i + s_1 (3Λ_i)^{1/3}, s_1 = 1.01879 (:data:`AIRY_PEAK`).  For Hertz without
    a top force τ ∝ depth^{5/6} and the delay ∝ depth^{1/6}.  Against the discrete
    chain (v0 = 1e-4 m/s, 300 grains): within 1.0 % from the struck grain,
    0.15 % from grain 10 (docs/physics.md §14).

    Parameters
    ----------
    n_grains : int
        Number of grains N (>= 2).
    mass, k, d : float
        Grain mass (kg), contact constant (N/m^n), diameter (m).
    g : float
        Gravity, m/s² (>= 0; with top_force, not both 0).
    exponent : float
        n of F = k δ^n, in (1, 10].
    top_force : float
        Static force on the top grain, N (>= 0).

    Returns
    -------
    ndarray, shape (N,)
        t_i, s (t_0 = 0).
    """
    n, mass, k, d, delta0 = _vertical(n_grains, mass, k, d, g, top_force, exponent)
    c = np.asarray(c0(k, mass, d, delta0, n), dtype=float)
    tau = np.r_[0.0, np.cumsum(d / c)]
    lam = np.r_[0.0, np.cumsum(d**3 / (24.0 * c**3))]
    return tau + AIRY_PEAK * np.cbrt(3.0 * lam)
