r"""Dissipative chains: shock structure, critical viscosity, damped solitary waves, restitution.

Contact forces F = k δ^n + c(δ) δ̇ (c ≥ 0, N·s/m): a linear dashpot has constant c = μ; the
viscoelastic Hertz law of Kuwabara & Kono (Jpn. J. Appl. Phys. 26 (1987) 1230; Brilliantov,
Spahn, Hertzsch & Pöschel, Phys. Rev. E 53 (1996) 5382) F = k(δ^{3/2} + A δ^{1/2} δ̇) has
c = k A δ^{1/2} (:func:`kuwabara_kono_damping`; A in s).  An on-site drag -m β v acts on
every grain (β in 1/s).

**Shocks.**  A piston pushing at velocity U into a chain at static overlap δ0 drives a
steady shock to the overlap δ_f with (mass and momentum balance, exact on the lattice:
the compressed region grows by one contact per 1/s seconds, each grain joining it takes
the momentum m U) U = s(δ_f - δ0) and m s² (δ_f - δ0) = k(δ_f^n - δ0^n), s the shock's
rate in grains per second (:func:`shock_from_piston`).  Behind the front the chain relaxes
to δ_f through the modes e^{λ z} (z = j - s t in grains, Re λ > 0) of the chain
linearised about δ_f, m s² λ² = (K - c s λ)(2 cosh λ - 2), K = n k δ_f^{n-1}
(:func:`shock_tail_modes`): an oscillatory profile if a complex pair decays slowest,
monotonic if the real root does.  Herbold & Nesterenko (Phys. Rev. E 75 (2007) 021304)
find the critical viscosity of the transition from the long-wave approximation
(2 cosh λ - 2 ≈ λ² + λ⁴/12), where the pair merges into two real roots at

.. math:: c_{cr} = \frac{2}{s}\sqrt{\frac{K}{12}\,(K - m s^2)}
          \;\xrightarrow{\delta_0 = 0}\; \sqrt{\frac{(n-1)\, m K}{3}}

(:func:`critical_viscosity`; "comparable to the value obtained in the numerical analysis
of a discrete system", their abstract).  On the lattice the pair never merges (the
real root always exists); the profile turns monotonic where the real root starts to
decay more slowly than the pair, at c s/K = 0.263 for Hertz (against the long-wave
1/3; :func:`critical_viscosity_lattice`).  Both against the discrete chain:
docs/physics.md §14.

**Damped solitary waves** (first order in the damping).  A weakly damped wave stays the
lossless exact wave (docs/physics.md §7) of slowly falling amplitude; its energy E = C m v²
falls at the power the damping dissipates in it (:mod:`discrete.waves` integrates that
numerically).  Closed forms, at δ0 = 0, with the constants of
:func:`theory.profiles.sonic_vacuum_wave_constants`:

* on-site drag: the power is 2β E_kin and E_kin = (n+1)/(n+3) E (virial), so
  v_max ∝ e^{-β(n+1)t/(n+3)}; with the speed ∝ v_max^{(n-1)/(n+1)} the wave stops after
  a finite distance, v_max(j) = v0 (1 - j/j_d)^{(n+1)/(n-1)} (:func:`drag_wave_decay`);
* Kuwabara–Kono: P = (k² A/m) λ³ ∫ρ^{1/2}ρ′² dz grows faster than E ∝ λ^{5/2}, and
  v_max(j) = v0 (1 + j/j_*)^{-5} (:func:`kuwabara_kono_wave_decay`).

Rosas, Romero, Nesterenko & Lindenberg (Phys. Rev. Lett. 98 (2007) 164301) observed, for a
dashpot proportional to the relative velocity, that an impact's pulse splits into such an
attenuating solitary wave and a slowly decaying shock-like structure behind it; no
closed-form decay law for the Kuwabara–Kono chain was found in the literature.

**Restitution** of two viscoelastic spheres (Schwager & Pöschel, Phys. Rev. E 57 (1998)
650): :func:`restitution_coefficient` (their dimensionless collision, integrated) and
:func:`restitution_series` (their expansion in β = A ρ^{2/5} v^{1/5}).
"""

from __future__ import annotations

from dataclasses import dataclass
from math import gamma

import numpy as np

from ._validate import check_nonnegative, check_positive, check_range
from .profiles import sonic_vacuum_wave_constants

__all__ = [
    "kuwabara_kono_damping",
    "shock_from_piston",
    "critical_viscosity",
    "ShockTail",
    "shock_tail_modes",
    "critical_viscosity_lattice",
    "drag_wave_decay",
    "kuwabara_kono_wave_decay",
    "RESTITUTION_C1",
    "RESTITUTION_C2",
    "restitution_series",
    "restitution_coefficient",
]

RESTITUTION_C1: float = float(gamma(0.6) * np.sqrt(np.pi)
                              / (2**0.2 * 5**0.4 * gamma(2.1)))
"""C1 = Γ(3/5)√π/(2^{1/5} 5^{2/5} Γ(21/10)) = 1.15344 (Schwager & Pöschel 1998)."""

RESTITUTION_C2: float = 0.6 * RESTITUTION_C1**2
"""C2 = (3/5) C1² = 0.79826 (Schwager & Pöschel 1998; Ramírez et al., Phys. Rev. E 60
(1999) 4465)."""


def _ret(x):
    x = np.asarray(x, dtype=float)
    return x if x.ndim else float(x)


def _exponent(exponent) -> float:
    return float(check_range("exponent", exponent, 1.0, 10.0, closed=(False, True)))


def kuwabara_kono_damping(k, damping_time, overlap):
    """Damping coefficient c = k A δ^{1/2} of the Kuwabara–Kono law at overlap δ, N·s/m.

    F = k(δ^{3/2} + A δ^{1/2} δ̇) (Brilliantov et al. 1996, Eq. 18 with their (3/2)A as
    A; :class:`discrete.ViscoelasticHertz`).  Linearised about an overlap δ_f the law is a
    dashpot of this coefficient.

    Parameters
    ----------
    k : float or array
        Hertz constant, N/m^{3/2} (> 0).
    damping_time : float or array
        A, s (>= 0).
    overlap : float or array
        δ, m (>= 0).
    """
    k = check_positive("k", k)
    a = check_nonnegative("damping_time", damping_time)
    d = check_nonnegative("overlap", overlap)
    return _ret(k * a * np.sqrt(d))


# ------------------------------------------------------------------ shocks
def shock_from_piston(piston_velocity: float, k: float, mass: float, *, delta0: float = 0.0,
                      exponent: float = 1.5) -> tuple[float, float]:
    """Final overlap δ_f (m) and rate s (grains/s) of the steady shock of a piston.

    U = s (δ_f - δ0) and m s² (δ_f - δ0) = k(δ_f^n - δ0^n) (module docstring; the lattice's
    mass and momentum balance, the Rankine–Hugoniot conditions of the long-wave theory):
    δ_f solves m U² = k(δ_f^n - δ0^n)(δ_f - δ0), at δ0 = 0 δ_f = (m U²/k)^{1/(n+1)}.
    The shock speed is V = s d for grains of diameter d.

    Parameters
    ----------
    piston_velocity : float
        U, m/s (> 0).
    k : float
        Contact constant, N/m^n (> 0).
    mass : float
        Grain mass, kg (> 0).
    delta0 : float
        Static overlap ahead of the shock, m (>= 0).
    exponent : float
        n, in (1, 10].
    """
    n = _exponent(exponent)
    u = float(check_positive("piston_velocity", piston_velocity))
    k = float(check_positive("k", k))
    m = float(check_positive("mass", mass))
    d0 = float(check_nonnegative("delta0", delta0))
    target = m * u**2 / k
    if d0 == 0.0:
        df = target ** (1.0 / (n + 1))
    else:
        def f(x):
            return (np.expm1(n * np.log1p(x)) * x) * d0 ** (n + 1) - target

        hi = 1.0
        while f(hi) < 0:
            hi *= 2.0
        from scipy.optimize import brentq  # lazy: importing scipy costs start-up
        df = d0 * (1.0 + brentq(f, 0.0, hi, xtol=1e-15, rtol=1e-14))
    return float(df), float(u / (df - d0))


def _linear(k, mass, delta_f, delta0, n):
    """K = n k δ_f^{n-1} (N/m), m s² (N/m) and s (grains/s) of the shock to δ_f."""
    d0 = float(check_nonnegative("delta0", delta0))
    df = float(check_positive("delta_f", delta_f))
    if df <= d0:
        raise ValueError(f"delta_f must exceed delta0 = {d0!r} m (got {df!r})")
    k_lin = n * k * df ** (n - 1)
    ms2 = k * (df**n - d0**n) / (df - d0)  # m s², from the momentum balance
    return k_lin, ms2, np.sqrt(ms2 / mass)


def critical_viscosity(k: float, mass: float, delta_f: float, *, delta0: float = 0.0,
                       exponent: float = 1.5) -> float:
    r"""Herbold & Nesterenko's critical viscosity of a shock to overlap δ_f, N·s/m.

    Long-wave form of the tail modes (module docstring): (K/12) λ² - c s λ + (K - m s²) = 0
    has a double root at c_cr = (2/s)√((K/12)(K - m s²)); below it the profile behind the
    front oscillates.  At δ0 = 0 (m s² = K/n): c_cr = √((n-1) m K/3).  For a weak shock
    (δ_f - δ0 ≪ δ0) K - m s² ≈ K (n-1)(δ_f - δ0)/(2δ0) and c_cr ∝ √(δ_f - δ0), the
    weakly nonlinear (KdV–Burgers) critical viscosity (Herbold & Nesterenko 2007).

    Parameters
    ----------
    k, mass : float
        Contact constant (N/m^n), grain mass (kg).
    delta_f : float
        Overlap behind the shock, m (> delta0).
    delta0 : float
        Overlap ahead of it, m (>= 0).
    exponent : float
        n, in (1, 10].
    """
    n = _exponent(exponent)
    k, mass = float(check_positive("k", k)), float(check_positive("mass", mass))
    k_lin, ms2, s = _linear(k, mass, delta_f, delta0, n)
    return float(2.0 / s * np.sqrt(k_lin / 12.0 * (k_lin - ms2)))


@dataclass(frozen=True)
class ShockTail:
    """Slowest modes of the relaxation behind a steady shock (:func:`shock_tail_modes`).

    Attributes
    ----------
    real : float
        The real root λ_r of the lattice's tail equation, 1/grain.
    complex : complex
        The complex root with the smallest real part (Im > 0), 1/grain.
    oscillatory : bool
        Re λ_c < λ_r: the profile far behind the front oscillates.
    """

    real: float
    complex: complex
    oscillatory: bool


def _shape(lam):
    """(2 cosh λ - 2)/λ² = (2 sinh(λ/2)/λ)², without cancellation at small λ."""
    return (2.0 * np.sinh(lam / 2.0) / lam) ** 2


def _tail_roots(nu: float, sigma: float) -> tuple[float, complex]:
    """Roots of σ = (1 - ν λ) S(λ), S = (2 cosh λ - 2)/λ², σ = m s²/K, ν = c s/K.

    The real root lies in (0, 1/ν]: σ - 1 < 0 at λ → 0 and σ > 0 at λ = 1/ν; it is
    1/ν - σ/(ν S) = 1/ν to double precision once 1/ν > 600 (S > e^{587}).
    """
    with np.errstate(over="ignore", invalid="ignore"):
        if nu * 600.0 < 1.0:
            real = 1.0 / nu
        else:
            from scipy.optimize import brentq  # lazy: importing scipy costs start-up
            real = brentq(lambda x: sigma - (1.0 - nu * x) * _shape(x), 1e-12, 1.0 / nu,
                          xtol=1e-14, rtol=1e-13)
        # complex roots: Newton from a grid of starts, 0 < Re λ < min(λ_r, 20), 0 < Im < 4π
        re, im = np.meshgrid(np.linspace(0.05, min(max(real, 0.1), 20.0), 24),
                             np.linspace(0.1, 12.5, 48))
        z = (re + 1j * im).ravel()
        for _ in range(60):
            sh, ch = np.sinh(z / 2.0), np.cosh(z / 2.0)
            g = sigma * z * z - (1.0 - nu * z) * 4.0 * sh * sh
            dg = 2.0 * sigma * z + nu * 4.0 * sh * sh - (1.0 - nu * z) * 4.0 * sh * ch
            z = z - g / np.where(dg == 0, 1.0, dg)
        ok = np.isfinite(z) & (z.imag > 1e-6) & (z.real > 1e-9) & (z.real < 40.0)
        sh = np.sinh(z[ok] / 2.0)
        res = np.abs(sigma * z[ok] ** 2 - (1.0 - nu * z[ok]) * 4.0 * sh * sh)
    good = z[ok][res < 1e-9 * (1.0 + np.abs(z[ok]) ** 2)]
    if good.size == 0:
        return float(real), complex(np.inf, 0.0)
    return float(real), complex(good[np.argmin(good.real)])


def shock_tail_modes(viscosity: float, k: float, mass: float, delta_f: float, *,
                     delta0: float = 0.0, exponent: float = 1.5) -> ShockTail:
    r"""Decay modes e^{λ z} behind a steady shock in a chain with dashpots c, per grain.

    Linearising m r̈_j = Δ₂[F(r_j) + c ṙ_j] about δ_f in the frame z = j - s t
    (r = δ_f + e^{λ z}): m s² λ² = (K - c s λ)(2 cosh λ - 2), K = n k δ_f^{n-1}, the
    trivial double root λ = 0 (a shift) removed.  With σ = m s²/K < 1 (the shock is
    subsonic behind) and ν = c s/K there is always one real root λ_r in (0, 1/ν] and
    complex pairs; the slowest-decaying mode sets the far profile.  Roots by Newton's
    method from a grid of starting points (residual < 1e-9).

    Parameters
    ----------
    viscosity : float
        Dashpot coefficient c at δ_f, N·s/m (> 0; :func:`kuwabara_kono_damping` for the
        viscoelastic law).
    k, mass, delta_f, delta0, exponent
        As in :func:`critical_viscosity`.
    """
    n = _exponent(exponent)
    c = float(check_positive("viscosity", viscosity))
    k, mass = float(check_positive("k", k)), float(check_positive("mass", mass))
    k_lin, ms2, s = _linear(k, mass, delta_f, delta0, n)
    real, cplx = _tail_roots(c * s / k_lin, ms2 / k_lin)
    return ShockTail(real=real, complex=cplx, oscillatory=cplx.real < real)


def critical_viscosity_lattice(k: float, mass: float, delta_f: float, *, delta0: float = 0.0,
                               exponent: float = 1.5) -> float:
    """Dashpot coefficient at which the lattice's shock profile turns monotonic, N·s/m.

    The c at which the real tail mode λ_r and the slowest complex one decay alike,
    Re λ_c = λ_r (:func:`shock_tail_modes`); below it the far profile oscillates.  In
    units of K/s: 0.2632 for Hertz at δ0 = 0 against Herbold & Nesterenko's long-wave 1/3
    (:func:`critical_viscosity`); 0.398 against 0.408 for n = 2.
    """
    n = _exponent(exponent)
    k, mass = float(check_positive("k", k)), float(check_positive("mass", mass))
    k_lin, ms2, s = _linear(k, mass, delta_f, delta0, n)
    sigma = ms2 / k_lin

    def gap(nu):
        real, cplx = _tail_roots(nu, sigma)
        return cplx.real - real

    nu_lw = 2.0 * np.sqrt((1.0 - sigma) / 12.0)
    lo, hi = 0.2 * nu_lw, 0.5 * nu_lw
    while gap(hi) < 0:
        lo, hi = hi, hi * 1.5
        if hi > 20 * nu_lw:
            raise RuntimeError("no crossover of the tail modes found")
    from scipy.optimize import brentq  # lazy: importing scipy costs start-up
    return float(brentq(gap, lo, hi, xtol=1e-10) * k_lin / s)


# ------------------------------------------------------------------ damped solitary waves
def _rate(k, mass, velocity_max, n):
    c = sonic_vacuum_wave_constants(n)
    u = velocity_max * np.sqrt(mass / k)
    return c, c.rate * np.sqrt(k / mass) * u ** ((n - 1) / (n + 1))  # grains/s


def drag_wave_decay(grains, velocity_max: float, k: float, mass: float, drag: float, *,
                    exponent: float = 1.5):
    r"""Peak velocity of a solitary wave after ``grains`` in a chain with on-site drag, m/s.

    First order in β (module docstring): dE/dt = -2β E_kin = -2β (n+1)/(n+3) E, so
    v_max = v0 e^{-a t}, a = β(n+1)/(n+3), and with the grain rate s = s0 (v/v0)^p,
    p = (n-1)/(n+1) (:class:`theory.profiles.SonicVacuumWave`), j = s0 (1 - e^{-a p t})/(a p):

    .. math:: v_{max}(j) = v_0\,(1 - j/j_d)^{1/p}, \qquad j_d = \frac{s_0 (n+3)}{β (n-1)}

    (9 s0/β for Hertz); 0 beyond j_d.

    Parameters
    ----------
    grains : float or array
        Distance travelled j, grains (>= 0).
    velocity_max : float
        Peak grain velocity at j = 0, m/s (> 0).
    k, mass : float
        Contact constant (N/m^n) and grain mass (kg) of a sonic-vacuum chain.
    drag : float
        β, 1/s (>= 0).
    exponent : float
        n, in (1, 10].
    """
    n = _exponent(exponent)
    j = check_nonnegative("grains", grains)
    v0 = float(check_positive("velocity_max", velocity_max))
    k, mass = float(check_positive("k", k)), float(check_positive("mass", mass))
    beta = float(check_nonnegative("drag", drag))
    if beta == 0.0:
        return _ret(np.full(np.shape(j), v0))
    _, s0 = _rate(k, mass, v0, n)
    p = (n - 1) / (n + 1)
    jd = s0 * (n + 3) / (beta * (n - 1))
    return _ret(v0 * np.maximum(1.0 - j / jd, 0.0) ** (1.0 / p))


def kuwabara_kono_wave_decay(grains, velocity_max: float, k: float, mass: float,
                             damping_time: float):
    r"""Peak velocity of a Hertz solitary wave after ``grains`` with Kuwabara–Kono damping, m/s.

    First order in A, δ0 = 0, the clip of the law at F = 0 neglected.  With r = λρ the
    exact wave (unit wave: k = m = 1, v_max = 1, profile R₁, rate s₁, energy C; r = λR₁,
    s = s₁ √(k/m) λ^{1/4}): P = Σ k A r^{1/2} ṙ² = (k²A/m) s₁² λ³ J with
    J = ∫ R₁^{1/2} R₁′² dz (the phase average of the lattice sum), E = C k λ^{5/2}; per
    grain travelled (dj = s dt) dλ/dj = -(2AJ s₁ √(k/m)/(5C)) λ^{5/4}, so λ^{-1/4} grows
    linearly and

    .. math:: v_{max}(j) = v_0 (1 + j/j_*)^{-5}, \qquad
              j_* = \frac{10\,C}{A J s_1 \sqrt{k/m}\;λ_0^{1/4}},

    λ0 = (v0 √(m/k))^{4/5} (the unit wave's scale is its v_max; docs/physics.md §14).

    Parameters
    ----------
    grains : float or array
        Distance travelled j, grains (>= 0).
    velocity_max : float
        Peak grain velocity at j = 0, m/s (> 0).
    k, mass : float
        Hertz constant (N/m^{3/2}) and grain mass (kg).
    damping_time : float
        A of :class:`discrete.ViscoelasticHertz`, s (>= 0).
    """
    j = check_nonnegative("grains", grains)
    v0 = float(check_positive("velocity_max", velocity_max))
    k, mass = float(check_positive("k", k)), float(check_positive("mass", mass))
    a = float(check_nonnegative("damping_time", damping_time))
    if a == 0.0:
        return _ret(np.full(np.shape(j), v0))
    c = sonic_vacuum_wave_constants(1.5)
    lam0 = (v0 * np.sqrt(mass / k)) ** 0.8
    j_star = 10.0 * c.energy / (a * c.rate * c.kk_integral * np.sqrt(k / mass) * lam0**0.25)
    return _ret(v0 * (1.0 + j / j_star) ** -5)


# ------------------------------------------------------------------ restitution
def _beta(v, k, reduced_mass, damping_time):
    return damping_time * (k / reduced_mass) ** 0.4 * v**0.2


def restitution_series(v, k: float, reduced_mass: float, damping_time: float):
    r"""Schwager & Pöschel's coefficient of restitution, 1 - C1 β + C2 β², β = A ρ^{2/5} v^{1/5}.

    Two viscoelastic spheres (reduced mass μ, kg; Hertz constant k, N/m^{3/2}; damping
    time A, s, as in :class:`discrete.ViscoelasticHertz`) meeting at relative speed v (m/s):
    ρ = k/μ (Schwager & Pöschel, Phys. Rev. E 57 (1998) 650, whose A is 2/3 of this one).
    Error O(β^{5/2}) (the clip of the force at 0); :func:`restitution_coefficient`
    integrates the collision instead.
    """
    v = check_positive("v", v)
    b = _beta(v, float(check_positive("k", k)), float(check_positive("reduced_mass",
                                                                      reduced_mass)),
              float(check_nonnegative("damping_time", damping_time)))
    return _ret(1.0 - RESTITUTION_C1 * b + RESTITUTION_C2 * b**2)


def restitution_coefficient(v, k: float, reduced_mass: float, damping_time: float):
    r"""Coefficient of restitution of two viscoelastic spheres, by integrating the collision.

    With ξ = ξ_m x, t = (ξ_m/v) τ, ξ_m = (5μv²/(4k))^{2/5}, the law
    μ ξ̈ = -max(0, k ξ^{3/2} + k A ξ^{1/2} ξ̇) becomes
    x″ = -max(0, (5/4) x^{3/2} + γ x^{1/2} x′), x(0) = 0, x′(0) = 1, with the single
    parameter γ = (5/4)^{3/5} A ρ^{2/5} v^{1/5} (ρ = k/μ); ε = -x′ when x returns to 0
    (DOP853, rtol 1e-12).  The force never pulls (the clip), as in the discrete law.
    Agrees with :func:`restitution_series` to O(β^{5/2}).

    Parameters
    ----------
    v : float or array
        Relative approach speed, m/s (> 0).
    k : float
        Hertz constant, N/m^{3/2} (> 0).
    reduced_mass : float
        μ = m1 m2/(m1 + m2), kg (> 0).
    damping_time : float
        A, s (>= 0).
    """
    from scipy.integrate import solve_ivp  # (lazy: scipy.* costs start-up where unused)
    v = check_positive("v", v)
    b = _beta(v, float(check_positive("k", k)), float(check_positive("reduced_mass",
                                                                      reduced_mass)),
              float(check_nonnegative("damping_time", damping_time)))
    out = []
    for g in np.atleast_1d(b * 1.25**0.6):
        def rhs(_t, y, g=g):
            x = max(y[0], 0.0)
            return [y[1], -max(0.0, 1.25 * x**1.5 + g * np.sqrt(x) * y[1])]

        def back(_t, y):
            return y[0]

        back.terminal, back.direction = True, -1
        sol = solve_ivp(rhs, (0.0, 100.0), [0.0, 1.0], events=back, rtol=1e-12,
                        atol=1e-14, method="DOP853", first_step=1e-6)
        out.append(-sol.y_events[0][0][1] if sol.t_events[0].size else 0.0)
    return _ret(np.reshape(out, np.shape(b)))
