r"""Characteristic and solitary-wave speeds of a granular chain (Hertz, or F = k δ^n).

Notation: d grain diameter (m), m grain mass (kg), k_n contact constant (N/m^{3/2} for
Hertz, N/m^n for the power law F = k δ^n), δ0 static overlap (m), ξ = -u_x strain
(dimensionless; in the chain ξ ≈ overlap change / d), ξ0 = δ0/d the static strain.
The speeds and coefficients of the long-wave equations take the law's ``exponent`` n
(3/2, Hertz, by default; the KdV speeds are Hertz's): the formulas below are Hertz's,
the general ones are in the functions' docstrings (docs/physics.md, "Long waves for a
power-law contact").

* c0² = (3/2)(k_n/m) d² δ0^{1/2}  — sound speed of the precompressed chain (paper Eq. 4),
  i.e. c0 = d √(K/m) with the linearised stiffness K = dF/dδ = (3/2) k_n δ0^{1/2}.
* c_mat² = k_n d^{5/2}/m  — (paper Eq. 7), so c0² = (3/2) c_mat² ξ0^{1/2}.
* V_S = c0 (1 + d ξ_max/(12 δ0))  — KdV solitary wave (paper Eq. 5); only consistent
  with Eq. 4 when its nonlinear coefficient is b = d/(2δ0) (docs/physics.md §2).
* V_S0 = (2/√5) c_mat ξ_max^{1/4}  — Nesterenko's sonic-vacuum wave (paper Eq. 8).
* Nesterenko's general relation (Nesterenko, *Dynamics of Heterogeneous Materials*,
  Springer 2001, Eq. 1.4.28; Sen et al., Phys. Rep. 462 (2008) Eq. 14)

  .. math:: V_s = \frac{c_0}{f_r - 1}\sqrt{\tfrac{4}{15}\left(3 + 2 f_r^{5/2} - 5 f_r\right)},
            \qquad f_r = \frac{\xi_0 + \xi_{max}}{\xi_0},

  which tends to Eq. 5 as f_r → 1 and to Eq. 8 as f_r → ∞ (ξ_max is the dynamic
  strain on top of ξ0).
"""

from __future__ import annotations

import numpy as np

from ._numerics import power_remainder
from ._validate import check_exponent, check_nonnegative, check_positive

__all__ = [
    "linear_stiffness",
    "c0",
    "c_mat",
    "long_wave_dispersion",
    "kdv_speed",
    "kdv_speed_exact",
    "sonic_vacuum_speed",
    "nesterenko_speed",
    "lattice_dispersion",
]


def _ret(x):
    x = np.asarray(x)
    return x if x.ndim else float(x)


def linear_stiffness(k_n, delta0, exponent=1.5):
    """Linearised contact stiffness K = n k_n δ0^{n-1}, N/m (derivative of F = k δ^n).

    (3/2) k_n δ0^{1/2} for Hertz (derivative of paper Eq. 1).  ``exponent`` n in [1, 10].
    """
    k_n = check_positive("k_n", k_n)
    delta0 = check_positive("delta0", delta0)
    n = check_exponent(exponent)
    return _ret(n * k_n * delta0 ** (n - 1.0))


def c0(k_n, mass, d, delta0, exponent=1.5):
    r"""Sound speed of a precompressed chain, :math:`c_0 = d\sqrt{n k_n\delta_0^{n-1}/m}`, m/s.

    c0 = d √(K/m) with the linearised stiffness K = n k δ0^{n-1} (:func:`linear_stiffness`):
    the long-wave limit of the linearised lattice (Nesterenko 2001, §1.1).  For Hertz,
    c0² = (3/2)(k_n/m) d² δ0^{1/2} (paper Eq. 4).

    Parameters
    ----------
    k_n : float or array
        Contact constant, N/m^n (Hertz: N/m^{3/2}).
    mass : float or array
        Grain mass, kg.
    d : float or array
        Grain diameter (= lattice spacing), m.
    delta0 : float or array
        Static overlap, m (> 0; a chain without precompression has no sound speed).
    exponent : float
        n of the law F = k δ^n, in [1, 10].
    """
    k_n = check_positive("k_n", k_n)
    mass = check_positive("mass", mass)
    d = check_positive("d", d)
    delta0 = check_positive("delta0", delta0)
    n = check_exponent(exponent)
    return _ret(np.sqrt(n * k_n / mass * delta0 ** (n - 1.0)) * d)


def c_mat(k_n, mass, d, exponent=1.5):
    r"""Nesterenko's material speed :math:`c = \sqrt{k_n d^{n+1}/m}`, m/s.

    The speed of the strongly nonlinear long-wave equation
    :math:`u_{tt} = -c^2\partial_x[\xi^n + \dots]` (Nesterenko 2001, §1.2); paper
    Eq. 7 for Hertz, c² = k_n d^{5/2}/m.  So c0² = n c² ξ0^{n-1}.
    """
    k_n = check_positive("k_n", k_n)
    mass = check_positive("mass", mass)
    d = check_positive("d", d)
    n = check_exponent(exponent)
    return _ret(np.sqrt(k_n * d ** (n + 1.0) / mass))


def long_wave_dispersion(d, exponent=1.5):
    r"""Dispersion coefficient a = n d²/(6(n+1)) of the strongly nonlinear long-wave equation, m².

    .. math:: u_{tt} = -c^2\,\partial_x\!\left[\xi^n + a\,\xi^{(n-1)/2}\,
              \partial_{xx}\xi^{(n+1)/2}\right]

    for F = k δ^n (Nesterenko 2001, §1.2, derived for any n in docs/physics.md, "Long
    waves for a power-law contact"); d²/10 for Hertz (the corrected paper Eq. 7).
    """
    d = check_positive("d", d)
    n = check_exponent(exponent)
    return _ret(n * d * d / (6.0 * (n + 1.0)))


def kdv_speed(c0_, d, delta0, xi_max):
    """KdV solitary-wave speed V_S = c0 (1 + d ξ_max/(12 δ0)), m/s (paper Eq. 5).

    ``xi_max`` is the dynamic strain amplitude (overlap increase / d).  Valid for
    d ξ_max/δ0 ≪ 1; see :func:`kdv_speed_exact` for the Boussinesq form and
    :func:`nesterenko_speed` for any amplitude.
    """
    c0_ = check_positive("c0", c0_)
    d = check_positive("d", d)
    delta0 = check_positive("delta0", delta0)
    xi_max = check_nonnegative("xi_max", xi_max)
    return _ret(c0_ * (1.0 + d * xi_max / (12.0 * delta0)))


def kdv_speed_exact(c0_, d, delta0, xi_max):
    """Solitary-wave speed of the corrected Eq. 4, V = c0 √(1 + d ξ_max/(6 δ0)), m/s.

    The sech² travelling wave of u_tt = c0²(u_xx + (d²/12) u_xxxx - (d/(2δ0)) u_x u_xx)
    has V²/c0² = 1 + b ξ_max/3 with b = d/(2δ0) (docs/physics.md §2); to first order this is
    Eq. 5.
    """
    c0_ = check_positive("c0", c0_)
    d = check_positive("d", d)
    delta0 = check_positive("delta0", delta0)
    xi_max = check_nonnegative("xi_max", xi_max)
    return _ret(c0_ * np.sqrt(1.0 + d * xi_max / (6.0 * delta0)))


def sonic_vacuum_speed(c_mat_, xi_max, exponent=1.5):
    r"""Compacton speed at δ0 = 0, :math:`V = c\sqrt{2/(n+1)}\,\xi_{max}^{(n-1)/2}`, m/s.

    The travelling wave of the strongly nonlinear long-wave equation for F = k δ^n
    (Nesterenko 2001, §1.2; :func:`theory.profiles.compacton_strain`); for Hertz
    Nesterenko's V_S0 = (2/√5) c_mat ξ_max^{1/4} (paper Eq. 8).  ``c_mat_`` from
    :func:`c_mat` with the same exponent; ``exponent`` n in [1, 10].
    """
    c_mat_ = check_positive("c_mat", c_mat_)
    xi_max = check_nonnegative("xi_max", xi_max)
    n = check_exponent(exponent)
    return _ret(np.sqrt(2.0 / (n + 1.0)) * c_mat_ * xi_max ** (0.5 * (n - 1.0)))


def nesterenko_speed(c_mat_, xi0, xi_max, exponent=1.5):
    r"""Solitary-wave speed of the long-wave equation for any precompression, m/s.

    .. math:: V^2 = c_0^2\,\frac{2}{n(n+1)}\,\frac{\xi_r^{n+1} - 1 - (n+1)(\xi_r - 1)}
              {(\xi_r - 1)^2},\quad c_0^2 = n c^2 \xi_0^{n-1},
              \quad \xi_r = 1 + \xi_{max}/\xi_0

    for F = k δ^n: the first integral of the travelling wave of
    :math:`u_{tt} = -c^2\partial_x[\xi^n + a\xi^{(n-1)/2}(\xi^{(n+1)/2})_{xx}]`
    at its peak (docs/physics.md, "Long waves for a power-law contact").  For Hertz
    (n = 3/2) it is Nesterenko's (2001, Eq. 1.4.28; Sen et al., Phys. Rep. 462 (2008)
    Eq. 14) :math:`V_s = \frac{c_0}{\xi_r - 1}\sqrt{\tfrac{4}{15}(3 + 2\xi_r^{5/2} -
    5\xi_r)}`, evaluated in that printed form (and its series for ξr - 1 < 1e-3);
    other n without cancellation (:func:`theory._numerics.power_remainder`).
    ``xi0 = 0`` returns the compacton's :func:`sonic_vacuum_speed` (Eq. 8), and so does
    ξ_max/ξ0 > 1e18: there V_s/V_vac = 1 + (n+1)ξ0/(2ξ_max) + … equals 1 to rounding,
    and the formula would overflow ((1 + ξ_max/ξ0)^{n+1}) as ξ0 → 0;
    ``xi_max → 0`` gives c0, to first order :math:`c_0(1 + (n-1)\xi_{max}/(6\xi_0))`
    (paper Eq. 5 for Hertz).

    Parameters
    ----------
    c_mat_ : float or array
        Material speed c = √(k d^{n+1}/m), m/s (:func:`c_mat`).
    xi0 : float or array
        Static strain δ0/d (>= 0).
    xi_max : float or array
        Dynamic strain amplitude (>= 0), on top of ξ0.
    exponent : float
        n, in [1, 10].
    """
    c_mat_ = check_positive("c_mat", c_mat_)
    xi0 = check_nonnegative("xi0", xi0)
    xi_max = check_nonnegative("xi_max", xi_max)
    n = check_exponent(exponent)
    c_mat_, xi0, xi_max = np.broadcast_arrays(c_mat_, xi0, xi_max)
    vac_coef = np.sqrt(2.0 / (n + 1.0))  # the compacton's V/(c ξ^{(n-1)/2})
    half = 0.5 * (n - 1.0)
    out = np.empty(c_mat_.shape)
    vac = xi0 == 0
    out[vac] = vac_coef * c_mat_[vac] * xi_max[vac] ** half
    pre = ~vac
    with np.errstate(divide="ignore", over="ignore"):
        eps = xi_max[pre] / xi0[pre]  # inf for a subnormal ξ0
    # the δ0 → 0 limit: beyond ε = 1e18 the compacton's speed to rounding (docstring)
    far = eps > 1e18
    eps = np.where(far, 1.0, eps)
    cc0 = np.sqrt(n) * c_mat_[pre] * xi0[pre] ** half
    with np.errstate(divide="ignore", invalid="ignore"):
        if n == 1.5:
            # Nesterenko's printed form and its series below eps = 1e-3 (the closed form
            # cancels there: ≲ 5e-11 relative at eps = 1e-3), kept bit for bit: the
            # paper scenarios' speeds and exact-wave guesses are made of it
            fr = 1.0 + eps
            big = np.sqrt(4.0 / 15.0 * (3.0 + 2.0 * fr**2.5 - 5.0 * fr)) / eps
            series = np.where(eps < 1e-3, np.sqrt(1.0 + eps / 6.0 - eps**2 / 48.0
                                                   + eps**3 / 160.0), 0.0)
            ratio = np.where(eps < 1e-3, series, big)
        else:
            # (2/(n(n+1))) [(1+eps)^{n+1} - 1 - (n+1) eps]/eps², free of cancellation
            ratio = np.where(eps > 0, np.sqrt(2.0 / (n * (n + 1.0))
                                              * power_remainder(eps, n + 1.0)) / eps, 1.0)
    out[pre] = np.where(far, vac_coef * c_mat_[pre] * xi_max[pre] ** half, cc0 * ratio)
    return _ret(out)


def lattice_dispersion(k, c0_, d):
    """Linear dispersion of the precompressed chain, ω = (2 c0/d) |sin(k d/2)|, rad/s.

    Linearising Eq. 2 about δ0 gives a mass-spring lattice (docs/physics.md §4).
    """
    k = np.asarray(k, dtype=float)
    c0_ = check_positive("c0", c0_)
    d = check_positive("d", d)
    return _ret(2.0 * c0_ / d * np.abs(np.sin(k * d / 2.0)))
