r"""Characteristic and solitary-wave speeds of a Hertz chain.

Notation: d grain diameter (m), m grain mass (kg), k_n Hertz constant (N/m^{3/2}),
δ0 static overlap (m), ξ = -u_x strain (dimensionless; in the chain ξ ≈ overlap
change / d), ξ0 = δ0/d the static strain.

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

from ._validate import check_nonnegative, check_positive

__all__ = [
    "linear_stiffness",
    "c0",
    "c_mat",
    "kdv_speed",
    "kdv_speed_exact",
    "sonic_vacuum_speed",
    "nesterenko_speed",
    "lattice_dispersion",
]


def _ret(x):
    x = np.asarray(x)
    return x if x.ndim else float(x)


def linear_stiffness(k_n, delta0):
    """Linearised contact stiffness K = (3/2) k_n δ0^{1/2}, N/m (derivative of Eq. 1)."""
    k_n = check_positive("k_n", k_n)
    delta0 = check_positive("delta0", delta0)
    return _ret(1.5 * k_n * np.sqrt(delta0))


def c0(k_n, mass, d, delta0):
    """Sound speed of a precompressed chain, c0 = √((3/2)(k_n/m) d² δ0^{1/2}), m/s (Eq. 4).

    Parameters
    ----------
    k_n : float or array
        Hertz constant, N/m^{3/2}.
    mass : float or array
        Grain mass, kg.
    d : float or array
        Grain diameter (= lattice spacing), m.
    delta0 : float or array
        Static overlap, m (> 0; a chain without precompression has no sound speed).
    """
    k_n = check_positive("k_n", k_n)
    mass = check_positive("mass", mass)
    d = check_positive("d", d)
    delta0 = check_positive("delta0", delta0)
    return _ret(np.sqrt(1.5 * k_n / mass * np.sqrt(delta0)) * d)


def c_mat(k_n, mass, d):
    """Nesterenko's material speed c_mat = √(k_n d^{5/2}/m), m/s (paper Eq. 7)."""
    k_n = check_positive("k_n", k_n)
    mass = check_positive("mass", mass)
    d = check_positive("d", d)
    return _ret(np.sqrt(k_n * d**2.5 / mass))


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


def sonic_vacuum_speed(c_mat_, xi_max):
    """Nesterenko's solitary-wave speed V_S0 = (2/√5) c_mat ξ_max^{1/4}, m/s (paper Eq. 8)."""
    c_mat_ = check_positive("c_mat", c_mat_)
    xi_max = check_nonnegative("xi_max", xi_max)
    return _ret(2.0 / np.sqrt(5.0) * c_mat_ * xi_max**0.25)


def nesterenko_speed(c_mat_, xi0, xi_max):
    r"""Nesterenko's solitary-wave speed for any precompression, m/s.

    .. math:: V_s = \frac{c_0}{f_r - 1}\sqrt{\tfrac{4}{15}(3 + 2 f_r^{5/2} - 5 f_r)},
              \quad c_0 = \sqrt{3/2}\, c_{mat}\, \xi_0^{1/4},
              \quad f_r = 1 + \xi_{max}/\xi_0

    (Nesterenko 2001, Eq. 1.4.28).  ``xi0 = 0`` returns Eq. 8; ``xi_max → 0`` gives c0
    and to first order Eq. 5.

    Parameters
    ----------
    c_mat_ : float or array
        Material speed, m/s.
    xi0 : float or array
        Static strain δ0/d (>= 0).
    xi_max : float or array
        Dynamic strain amplitude (>= 0).
    """
    c_mat_ = check_positive("c_mat", c_mat_)
    xi0 = check_nonnegative("xi0", xi0)
    xi_max = check_nonnegative("xi_max", xi_max)
    c_mat_, xi0, xi_max = np.broadcast_arrays(c_mat_, xi0, xi_max)
    out = np.empty(c_mat_.shape)
    vac = xi0 == 0
    out[vac] = 2.0 / np.sqrt(5.0) * c_mat_[vac] * xi_max[vac] ** 0.25
    pre = ~vac
    cc0 = np.sqrt(1.5) * c_mat_[pre] * xi0[pre] ** 0.25
    eps = xi_max[pre] / xi0[pre]
    fr = 1.0 + eps
    # For small eps the closed form cancels catastrophically; use its series there:
    # (4/15)(3 + 2 fr^{5/2} - 5 fr) = eps² (1 + eps/6 - eps²/48 + eps³/160 + ...).
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        big = np.sqrt(4.0 / 15.0 * (3.0 + 2.0 * fr**2.5 - 5.0 * fr)) / eps
        # fr^{5/2} overflows for eps ≳ 1e123 (δ0/d ≲ 1e-120): the ratio is inf or NaN
        # there and V_s its δ0 → 0 limit, Eq. 8 (c0 √(8/15) eps^{1/4} = (2/√5) c_mat ξ^{1/4})
        series = np.where(eps < 1e-3, np.sqrt(1.0 + eps / 6.0 - eps**2 / 48.0
                                               + eps**3 / 160.0), 0.0)
    ratio = np.where(eps < 1e-3, series, big)
    out[pre] = np.where(np.isfinite(ratio), cc0 * ratio,
                        2.0 / np.sqrt(5.0) * c_mat_[pre] * xi_max[pre] ** 0.25)
    return _ret(out)


def lattice_dispersion(k, c0_, d):
    """Linear dispersion of the precompressed chain, ω = (2 c0/d) |sin(k d/2)|, rad/s.

    Linearising Eq. 2 about δ0 gives a mass-spring lattice (docs/physics.md §4).
    """
    k = np.asarray(k, dtype=float)
    c0_ = check_positive("c0", c0_)
    d = check_positive("d", d)
    return _ret(2.0 * c0_ / d * np.abs(np.sin(k * d / 2.0)))
