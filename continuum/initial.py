r"""Initial conditions matching the discrete solver's: solitary waves and grain snapshots.

* :func:`solitary_wave` — the sech² solitary wave of the regularised Eq. 4
  (:class:`~continuum.boussinesq.BoussinesqPDE`), or the KdV soliton of Eq. 4 itself;
* :func:`compacton` — Nesterenko's compacton (cos⁴ for Hertz, docs/physics.md §3,
  paper Eq. 8; cos^{2/(n-1)} for F = kδ^n) for :class:`~continuum.nesterenko.NesterenkoPDE`;
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

from theory import compacton_motion, compacton_width

from .boussinesq import law_curvature

__all__ = ["solitary_wave", "solitary_wave_parameters", "compacton", "compacton_parameters",
           "from_grains", "band_limited", "launch_interpolation", "INTERPOLATIONS"]

BAND_LIMITED_PAD = 10
"""Grains of the flat state on either side of a wave that :func:`band_limited` takes into
the interpolated segment."""
INTERPOLATIONS = ("smooth", "spline", "band_limited", "grains")
"""The ways :func:`from_grains` takes a grain state onto the nodes."""

COMPACTON_WAVENUMBER = np.sqrt(10.0) / 5.0
"""κ = √10/5 of the Hertz compacton cos⁴(κ X) (docs/physics.md §3), per grain."""


def _grain_index(pde, center: float) -> int:
    return int(np.clip(round(center), 0, pde.medium.n_grains - 1))


def solitary_wave_parameters(pde, center: float, *, amplitude: float | None = None,
                             velocity_max: float | None = None,
                             kind: str = "regularised") -> dict[str, float]:
    r"""Amplitude, speed and width of the sech² wave of the corrected Eq. 4.

    With the local section's K = F'(δ0), b = F''(δ0)/2, m and ℓ² (``c² = K/m``,
    grains²/s²; :class:`~continuum.boussinesq.BoussinesqPDE`) and overlap amplitude A (m),
    the travelling wave of both Eq. 4 and its Rosenau form has

    .. math:: V^2 = c^2\,\Big(1 + \frac{2bA}{3K}\Big),\qquad
              s = A\,\mathrm{sech}^2\big((X - X_0 - Vt)/\Lambda\big)

    with :math:`\Lambda = 2\ell c/\sqrt{V^2 - c^2}` (Eq. 4, ``kind="kdv"``) or
    :math:`\Lambda = 2\ell V/\sqrt{V^2 - c^2}` (Rosenau form, ``kind="regularised"``),
    in grains.  For Hertz b/K = 1/(4δ0): V² = c²(1 + A/(6δ0)) (Eq. 5 to first order)
    and Λ = √(2δ0/A) (× V/c).  The grain velocity is v = V s, so ``velocity_max`` = V A.

    Returns
    -------
    dict
        ``amplitude`` (m), ``speed`` (grains/s), ``speed_m_s`` (× the local diameter),
        ``width`` (grains), ``c0`` (grains/s), ``delta0`` (m), ``velocity_max`` (m/s).
    """
    if (amplitude is None) == (velocity_max is None):
        raise ValueError("give exactly one of amplitude (m) or velocity_max (m/s)")
    if kind not in ("regularised", "kdv"):
        raise ValueError(f"kind must be 'regularised' or 'kdv' (got {kind!r})")
    disc = pde.disc
    g = _grain_index(pde, center)
    q = disc.contact_faces[min(g, disc.contact_faces.size - 1)]
    p = disc.grain_nodes[g]
    k_lin, m, d0 = float(disc.stiffness[q]), float(disc.mass[p]), float(disc.delta0[q])
    if not d0 > 0:
        raise ValueError("the sech² solitary wave needs a precompressed chain (delta0 > 0)")
    b = 0.5 * float(np.asarray(law_curvature(pde.law, d0, disc.k[q])))
    ell = np.sqrt(float(disc.dispersion[q]) / 12.0)
    c = np.sqrt(k_lin / m)

    def speed(a):
        return c * np.sqrt(1.0 + 2.0 * b * a / (3.0 * k_lin))

    if amplitude is None:
        vm = float(velocity_max)
        if vm <= 0:
            raise ValueError(f"velocity_max must be > 0 m/s (got {vm})")
        amplitude = brentq(lambda a: speed(a) * a - vm, 0.0, vm / c * 2 + 10 * d0)
    a = float(amplitude)
    if a <= 0:
        raise ValueError(f"amplitude must be > 0 m (got {a})")
    v = speed(a)
    width = 2.0 * ell * (v if kind == "regularised" else c) / np.sqrt(v * v - c * c)
    return {"amplitude": a, "speed": v, "speed_m_s": v * float(pde.medium.diameter[g]),
            "width": width, "c0": c, "delta0": d0, "velocity_max": v * a}


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
    r"""Amplitude and speed of Nesterenko's compacton for the law F = k δ^n (paper Eq. 8).

    In grain units: peak overlap δ_max (m), :math:`V = \sqrt{2/(n+1)}\,c\,
    \delta_{max}^{(n-1)/2}` grains/s with :math:`c^2 = k/m` (the law's
    :meth:`~theory.laws.LongWave.compacton_speed`; Hertz: ξ_max = δ_max/d and
    :math:`V = (2/\sqrt5)\,c_{mat}\,\xi_{max}^{1/4}`, Eq. 7, 8); the grain velocity is
    v = V δ, so ``velocity_max`` = V δ_max.  Uses the contact constant and mass at
    ``grain`` (the homogenised cell's in a periodic section) and its diameter for m/s.

    Returns
    -------
    dict
        ``amplitude`` (overlap, m), ``strain_max`` (δ_max/d), ``speed_m_s``, ``speed``
        (grains/s), ``c_mat`` (m/s, √(k d^{n+1}/m)), ``velocity_max`` (m/s),
        ``half_width`` (grains: half the support, × √(12ℓ²) in a homogenised cell).
    """
    if (amplitude is None) == (velocity_max is None):
        raise ValueError("give exactly one of amplitude (m) or velocity_max (m/s)")
    med = pde.effective
    n = float(pde.law.exponent)
    if not n > 1:
        raise ValueError(f"the compacton needs a law exponent n > 1 (got {n:g})")
    d = float(med.diameter[grain])
    k, m = float(med.k[grain + 1]), float(med.mass[grain])
    lw = pde.law.long_wave(k, m, d)
    vac = np.sqrt(2.0 / (n + 1.0))
    if amplitude is None:
        # v = V δ = vac c (δ/d)^{(n-1)/2} δ/d (m/s): solve for δ
        xi = (float(velocity_max) / (vac * lw.c)) ** (2.0 / (n + 1.0))
    else:
        xi = float(amplitude) / d
    if not xi > 0:
        raise ValueError("amplitude / velocity_max must be > 0")
    vs = float(lw.compacton_speed(xi))
    r = float(pde.disc.dispersion[pde.disc.contact_faces[min(grain + 1, med.n_grains)]])
    return {"amplitude": xi * d, "strain_max": xi, "speed_m_s": vs, "speed": vs / d,
            "c_mat": lw.c, "velocity_max": vs * xi,
            "half_width": 0.5 * np.sqrt(r) * float(compacton_width(1.0, n))}


def compacton(pde, center: float, *, amplitude: float | None = None,
              velocity_max: float | None = None) -> FieldCollection:
    r"""State of a right-going compacton centred at grain ``center``.

    δ = δ_max cos^{2/(n-1)}(q (X - X0)) (:func:`theory.compacton_motion` in grain
    units, its width × √(12ℓ²) in a homogenised cell; Hertz: cos⁴(√10 (X - X0)/5),
    docs/physics.md §3), zero outside the support (≈ 2.48 grains either side for Hertz).
    The displacement is the exact integral of the overlap (zero ahead of the wave).
    """
    g = _grain_index(pde, center)
    par = compacton_parameters(pde, amplitude=amplitude, velocity_max=velocity_max, grain=g)
    n = float(pde.law.exponent)
    x = pde.disc.x_nodes
    scale = par["half_width"] / (0.5 * float(compacton_width(1.0, n)))
    c_grain = par["c_mat"] / float(pde.effective.diameter[g]) ** (0.5 * (n + 1.0))
    u, v = compacton_motion(x, par["amplitude"], scale, c_grain, center, exponent=n)
    u = np.asarray(u, float)
    v = np.asarray(v, float)
    # exactly zero outside the support (cos(±π/2)^p would leave ~1e-65)
    v = np.where(np.abs(x - center) < par["half_width"], v, 0.0)
    return pde.get_initial_condition(u, v)


def launch_interpolation(model, interpolation: str = "smooth") -> str:
    """The interpolation :func:`from_grains` uses for ``model`` (a PDE or its class).

    ``"smooth"`` is the model's own :attr:`~continuum.ChainPDEBase.smooth_interpolation`
    (``"spline"`` for a model without one, e.g. KdV or None); the others are returned as
    given.  Raises ValueError naming :data:`INTERPOLATIONS` for any other value.
    """
    if interpolation not in INTERPOLATIONS:
        raise ValueError(f"interpolation must be one of {', '.join(INTERPOLATIONS)} "
                         f"(got {interpolation!r})")
    if interpolation == "smooth":
        return getattr(model, "smooth_interpolation", "spline")
    return interpolation


def from_grains(pde, u_grains, v_grains, *, interpolation: str = "smooth"
                ) -> FieldCollection:
    """State interpolated from a discrete snapshot: u_i (m), v_i (m/s) of every grain.

    ``interpolation``:

    * ``"smooth"`` (a smooth wave): the model's own choice,
      :attr:`~continuum.ChainPDEBase.smooth_interpolation` (``"band_limited"`` for the
      quasi-continuum, ``"spline"`` for the others);
    * ``"spline"`` (a smooth wave): cubic splines through the grain centres X = i
      (not-a-knot ends) evaluated at the nodes; with n = 1 node per grain this is the
      identity.  The continuum strain at a contact face is then the spline's slope,
      which differs from the lattice overlap u_{j-1} - u_j by O(u_XXX/24), the same
      order as the long-wave equations' own error;
    * ``"band_limited"`` (a smooth wave, for :class:`~continuum.GrainAveragedPDE`): the
      Whittaker–Shannon (sinc) interpolant, the function with no wavenumber above π per
      grain through the grain values (:func:`band_limited`).  The chain's overlap
      u_{j-1} − u_j is then exactly the grain average S of the interpolant's strain
      −u_X at the contact (docs/physics.md §24), which is what the quasi-continuum's
      overlap δ = δ0 + S̃_M s approximates (with a spline, the overlap the model reads
      is that of a function with wavenumbers above π, and the sonic-vacuum wave starts
      with ~2 % less energy than the chain's);
    * ``"grains"`` (a state with a jump, an impact: one struck grain moving in a chain
      at rest): every node takes the u and v of the grain whose cell [i - 1/2, i + 1/2)
      holds it, so the momentum Σ m_i v_i and the kinetic energy Σ ½ m_i v_i² are
      exactly the grains'.  A spline through a velocity jump rings (Gibbs-like
      overshoot, extrapolated past the end grain) and hands the continuum up to ~1.8
      times the struck grain's kinetic energy.
    """
    interpolation = launch_interpolation(pde, interpolation)
    u_g = np.asarray(u_grains, dtype=float)
    v_g = np.asarray(v_grains, dtype=float)
    ng = pde.medium.n_grains
    if u_g.shape != (ng,) or v_g.shape != (ng,):
        raise ValueError(f"need u and v for all {ng} grains (got {u_g.shape}, {v_g.shape})")
    if pde.disc.n == 1:
        return pde.get_initial_condition(u_g.copy(), v_g.copy())
    xg = np.arange(ng, dtype=float)
    x = pde.disc.x_nodes
    if interpolation == "grains":
        cell = np.clip(np.floor(np.asarray(x) + 0.5).astype(int), 0, ng - 1)
        return pde.get_initial_condition(u_g[cell], v_g[cell])
    if interpolation == "band_limited":
        return pde.get_initial_condition(band_limited(u_g, pde.disc.n),
                                         band_limited(v_g, pde.disc.n))
    return pde.get_initial_condition(CubicSpline(xg, u_g)(x), CubicSpline(xg, v_g)(x))


def band_limited(values, nodes: int) -> np.ndarray:
    r"""Band-limited interpolant of per-grain values at ``nodes`` (odd) nodes per grain.

    The Whittaker–Shannon interpolant :math:`f(X) = \sum_j f_j\,\mathrm{sinc}(X - j)`
    has no wavenumber above π per grain; it is evaluated on the nodes
    X = −½ + (i + ½)/n, i = 0 … nN − 1, of :func:`continuum.medium.discretise` (the
    grain centres X = j among them for odd n) by trigonometric interpolation of the
    even (half-sample symmetric) extension f_0 … f_{N−1}, f_{N−1} … f_0 of period 2N:
    its discrete Fourier series, zero-padded, with the Nyquist term split evenly between
    ±π (Briggs & Henson, *The DFT*, SIAM 1995, §6.3).  The extension is smooth where the
    state is flat at both chain ends (a placed wave: u constant behind and ahead, v = 0),
    so the interpolant converges spectrally there; it reproduces the grain values exactly.

    Only the segment where f varies, padded by :data:`BAND_LIMITED_PAD` grains of the flat
    state on either side, is interpolated; the nodes outside take the flat grain values.
    A state that is not band-limited (the discrete wave) rings with a slowly decaying
    (~1/X) interpolant tail; kept to the segment, the state ahead of a wave stays exactly
    at rest, which the quasi-continuum's active window in the sonic vacuum relies on
    (:meth:`continuum.GrainAveragedPDE.make_chunk_stepper`).

    Parameters
    ----------
    values : array_like, shape (N,)
        f_j at the grain centres X = j (any unit; returned in the same).
    nodes : int
        n, odd nodes per grain.

    Returns
    -------
    numpy.ndarray, shape (n N,)
        The interpolant at the nodes.
    """
    f = np.asarray(values, dtype=float)
    n = int(nodes)
    if n != nodes or n < 1 or n % 2 == 0:
        raise ValueError(f"nodes must be an odd integer >= 1 (got {nodes!r})")
    if f.ndim != 1 or f.size < 2:
        raise ValueError(f"values must be a 1-D array of >= 2 grains (got shape {f.shape})")
    out = np.repeat(f, n)
    lead = np.flatnonzero(f != f[0])
    trail = np.flatnonzero(f != f[-1])
    if lead.size == 0:
        return out  # constant
    a = max(int(lead[0]) - 1 - BAND_LIMITED_PAD, 0)
    b = min(int(trail[-1]) + 1 + BAND_LIMITED_PAD, f.size - 1)
    seg = f[a:b + 1]
    ng = seg.size
    spec = np.fft.rfft(np.concatenate([seg, seg[::-1]]))
    spec[-1] *= 0.5  # the Nyquist term of period 2N: half at +π, half at −π
    fine = np.fft.irfft(spec, 2 * ng * n) * n  # at X = a + i/n, i = 0 … 2nN − 1
    idx = (np.arange(n * ng) - (n - 1) // 2) % fine.size
    out[a * n:(b + 1) * n] = fine[idx]
    return out
