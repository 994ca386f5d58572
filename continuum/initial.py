r"""Initial conditions matching the discrete solver's: solitary waves and grain snapshots.

* :func:`solitary_wave` — the sech² solitary wave of the regularised Eq. 4
  (:class:`~continuum.boussinesq.BoussinesqPDE`), or the KdV soliton of Eq. 4 itself;
* :func:`compacton` — Nesterenko's cos⁴ compacton (docs/physics.md §3, paper Eq. 8) for
  :class:`~continuum.nesterenko.NesterenkoPDE`;
* :func:`from_grains` — any discrete snapshot ``(u_i, v_i)`` (e.g. the exact discrete
  solitary wave of ``theory.profiles`` sampled per grain, or a DEM state) interpolated
  onto the nodes.

All return the py-pde state :class:`~pde.FieldCollection` ``(u, v)``, u in m, v in m/s,
positions in grain diameters.  Waves travel towards +X.
"""

from __future__ import annotations

import numpy as np
from pde import FieldCollection
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

__all__ = ["solitary_wave", "solitary_wave_parameters", "compacton", "compacton_parameters",
           "from_grains"]

COMPACTON_WAVENUMBER = np.sqrt(10.0) / 5.0
"""κ = √10/5 of the compacton cos⁴(κ X) (docs/physics.md §3), per grain diameter."""


def _grain_index(pde, center: float) -> int:
    return int(np.clip(round(center), 0, pde.medium.n_grains - 1))


def solitary_wave_parameters(pde, center: float, *, amplitude: float | None = None,
                             velocity_max: float | None = None,
                             kind: str = "regularised") -> dict[str, float]:
    r"""Amplitude, speed and width of the sech² wave of the corrected Eq. 4.

    With the local section's K, m, δ0 (``c² = K/m``, grains²/s²) and overlap amplitude
    A (m), the travelling wave of both Eq. 4 and its Rosenau form has

    .. math:: V^2 = c^2\,\big(1 + A/(6\delta_0)\big)\quad\text{(Eq. 5 to first order)},\qquad
              s = A\,\mathrm{sech}^2\big((X - X_0 - Vt)/\Lambda\big)

    with :math:`\Lambda = \sqrt{2\delta_0/A}` (Eq. 4, ``kind="kdv"``) or
    :math:`\Lambda = (V/c)\sqrt{2\delta_0/A}` (Rosenau form, ``kind="regularised"``),
    in grain diameters.  The grain velocity is v = V s, so ``velocity_max`` = V A.

    Returns
    -------
    dict
        ``amplitude`` (m), ``speed`` (grains/s), ``speed_m_s``, ``width`` (grains),
        ``c0`` (grains/s), ``delta0`` (m), ``velocity_max`` (m/s).
    """
    if (amplitude is None) == (velocity_max is None):
        raise ValueError("give exactly one of amplitude (m) or velocity_max (m/s)")
    if kind not in ("regularised", "kdv"):
        raise ValueError(f"kind must be 'regularised' or 'kdv' (got {kind!r})")
    disc = pde.disc
    q = disc.contact_faces[min(_grain_index(pde, center), disc.contact_faces.size - 1)]
    p = disc.grain_nodes[_grain_index(pde, center)]
    k_lin, m, d0 = float(disc.stiffness[q]), float(disc.mass[p]), float(disc.delta0[q])
    c = np.sqrt(k_lin / m)

    def speed(a):
        return c * np.sqrt(1.0 + a / (6.0 * d0))

    if amplitude is None:
        vm = float(velocity_max)
        if vm <= 0:
            raise ValueError(f"velocity_max must be > 0 m/s (got {vm})")
        amplitude = brentq(lambda a: speed(a) * a - vm, 0.0, vm / c * 2 + 10 * d0)
    a = float(amplitude)
    if a <= 0:
        raise ValueError(f"amplitude must be > 0 m (got {a})")
    v = speed(a)
    width = np.sqrt(2.0 * d0 / a) * (v / c if kind == "regularised" else 1.0)
    return {"amplitude": a, "speed": v, "speed_m_s": v * pde.medium.diameter, "width": width,
            "c0": c, "delta0": d0, "velocity_max": v * a}


def solitary_wave(pde, center: float, *, amplitude: float | None = None,
                  velocity_max: float | None = None, kind: str = "regularised"
                  ) -> FieldCollection:
    """State of a right-going sech² solitary wave centred at grain ``center``.

    See :func:`solitary_wave_parameters`.  The displacement is
    u = A Λ (1 - tanh((X - X0)/Λ)): zero ahead of the wave, 2AΛ behind it (the grains
    the wave has passed are shifted, as in the paper's set-up, Section 2).
    """
    par = solitary_wave_parameters(pde, center, amplitude=amplitude,
                                   velocity_max=velocity_max, kind=kind)
    x = pde.disc.x_nodes
    a, lam, vs = par["amplitude"], par["width"], par["speed"]
    y = (x - center) / lam
    u = a * lam * (1.0 - np.tanh(y))
    v = vs * a / np.cosh(np.clip(y, -300, 300)) ** 2
    return pde.get_initial_condition(u, v)


def compacton_parameters(pde, *, amplitude: float | None = None,
                         velocity_max: float | None = None, grain: int = 0) -> dict[str, float]:
    r"""Amplitude and speed of Nesterenko's compacton (paper Eq. 8).

    ξ_max = δ_max/d, :math:`V = (2/\sqrt5)\,c\,\xi_{max}^{1/4}` with
    :math:`c^2 = k_n d^{5/2}/m` (Eq. 7, 8); the grain velocity is v = V ξ, so
    ``velocity_max`` = V ξ_max.  Uses the contact stiffness and mass at ``grain``.

    Returns
    -------
    dict
        ``amplitude`` (overlap, m), ``strain_max``, ``speed_m_s``, ``speed`` (grains/s),
        ``c_mat`` (m/s), ``velocity_max`` (m/s), ``half_width`` (grains).
    """
    if (amplitude is None) == (velocity_max is None):
        raise ValueError("give exactly one of amplitude (m) or velocity_max (m/s)")
    med = pde.medium
    d = med.diameter
    c = np.sqrt(med.k[grain + 1] * d**2.5 / med.mass[grain])
    if amplitude is None:
        # v = (2/√5) c ξ^{5/4}
        xi = (float(velocity_max) * np.sqrt(5.0) / (2.0 * c)) ** 0.8
    else:
        xi = float(amplitude) / d
    if not xi > 0:
        raise ValueError("amplitude / velocity_max must be > 0")
    vs = 2.0 / np.sqrt(5.0) * c * xi**0.25
    return {"amplitude": xi * d, "strain_max": xi, "speed_m_s": vs, "speed": vs / d,
            "c_mat": c, "velocity_max": vs * xi,
            "half_width": np.pi / (2.0 * COMPACTON_WAVENUMBER)}


def compacton(pde, center: float, *, amplitude: float | None = None,
              velocity_max: float | None = None) -> FieldCollection:
    r"""State of a right-going compacton ξ = ξ_max cos⁴(√10 (X - X0)/5) (docs/physics.md §3).

    Zero outside :math:`|X - X_0| \le 5\pi/(2\sqrt{10})` ≈ 2.48 grains.  The
    displacement is the exact integral of the overlap (zero ahead of the wave).
    """
    par = compacton_parameters(pde, amplitude=amplitude, velocity_max=velocity_max,
                               grain=_grain_index(pde, center))
    x = pde.disc.x_nodes
    kappa = COMPACTON_WAVENUMBER
    th = np.clip((x - center) * kappa, -np.pi / 2, np.pi / 2)

    def prim(t):
        return 3 * t / 8 + np.sin(2 * t) / 4 + np.sin(4 * t) / 32

    u = par["amplitude"] / kappa * (prim(np.pi / 2) - prim(th))
    # exactly zero outside the support (cos(±π/2)⁴ would leave 1e-65)
    v = np.where(np.abs(th) < np.pi / 2, par["speed"] * par["amplitude"] * np.cos(th) ** 4, 0.0)
    return pde.get_initial_condition(u, v)


def from_grains(pde, u_grains, v_grains) -> FieldCollection:
    """State interpolated from a discrete snapshot: u_i (m), v_i (m/s) of every grain.

    Cubic splines through the grain centres X = i (not-a-knot ends) evaluated at the
    nodes; with n = 1 node per grain this is the identity.  The continuum strain at a
    contact face is then the spline's slope, which differs from the lattice overlap
    u_{j-1} - u_j by O(u_XXX/24), the same order as the long-wave equations' own error.
    """
    u_g = np.asarray(u_grains, dtype=float)
    v_g = np.asarray(v_grains, dtype=float)
    ng = pde.medium.n_grains
    if u_g.shape != (ng,) or v_g.shape != (ng,):
        raise ValueError(f"need u and v for all {ng} grains (got {u_g.shape}, {v_g.shape})")
    if pde.disc.n == 1:
        return pde.get_initial_condition(u_g.copy(), v_g.copy())
    xg = np.arange(ng, dtype=float)
    x = pde.disc.x_nodes
    return pde.get_initial_condition(CubicSpline(xg, u_g)(x), CubicSpline(xg, v_g)(x))
