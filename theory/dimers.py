r"""Periodic chains (dimers, trimers): homogenised long-wave theory and anti-resonances.

**Homogenisation** (Porter, Daraio, Herbold, Szelengowicz & Kevrekidis, Phys. Rev. E 77
(2008) 015601 and Physica D 238 (2009) 666: the long-wave equation of a periodic granular
chain for a general interaction).  A cell of p grains (masses m_i, kg), p contacts
(F = k_j δ^n, k_j in N/m^n) and length L (m) carries, in a long wave, the same force F
through all its contacts; their overlaps add up to the cell's compression
Δ = Σ_j (F/k_j)^{1/n}, so F = k_eff Δ^n with

.. math:: k_{eff} = \Big(\sum_j k_j^{-1/n}\Big)^{-n}, \qquad M = \sum_i m_i ,

an effective monoatomic chain of grains M, spacing L, contact k_eff
(:func:`homogenise_cell`).  Its long-wave solitary wave has Nesterenko's speed
(:func:`theory.speeds.nesterenko_speed` with k_eff, M, L; :func:`cell_solitary_speed`),
which does not involve the dispersion.  The width does: the acoustic branch of the
linearised cell, ω² = c0² q² (1 - γ q² + O(q⁴)), gives the long-wave dispersion γ
(:attr:`HomogenisedCell.dispersion`; for a dimer with equal contacts
γ = (L²/4)(1/3 - m_1 m_2/(m_1 + m_2)²)), right for waves many cells wide (the KdV regime
of a precompressed chain).  A sonic-vacuum wave is about two cells wide, and there the
long-wave width fails: with γ in place of the monoatomic d²/12, Nesterenko's compacton
(:func:`theory.profiles.compacton_width`) is 27 % narrower than the discrete dimer's wave
at ε = 0.3428 (its FWHM 1.62 L against 1.19 L; docs/physics.md §14), so no
dimer width is offered.

**Anti-resonances** (Jayaprakash, Starosvetsky & Vakakis, Phys. Rev. Lett. 106 (2011)
034302 and Phys. Rev. E 83 (2011) 036606).  A dimer of heavy (m) and light (εm) grains
with equal contacts and no precompression carries a solitary wave without a radiated
tail only at a countable set of mass ratios ε_1 > ε_2 > … → 0; elsewhere the leading
wave leaves the light grains oscillating and decays.  Their first value for Hertz,
:data:`FIRST_ANTIRESONANCE_HERTZ` = 0.3428, is numerical.  :func:`antiresonance_mass_ratios`
computes the leading-order small-ε estimate derived here: the light grain, driven by the
heavy grains' motion in the ε → 0 limit (the heavy chain with k_eff = 2^{-n} k), is left
at rest after the wave's passage.  It is asymptotic: against the discrete chain's
ε_k it gives 0.81, 0.94, 1.01 × for k = 1, 2, 3 (docs/physics.md §14).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ._validate import check_nonnegative, check_positive, check_range
from .profiles import discrete_solitary_wave
from .speeds import c_mat, nesterenko_speed

__all__ = [
    "FIRST_ANTIRESONANCE_HERTZ",
    "HomogenisedCell",
    "homogenise_cell",
    "cell_sound_speed",
    "cell_solitary_speed",
    "antiresonance_mass_ratios",
]

FIRST_ANTIRESONANCE_HERTZ: float = 0.3428
"""First anti-resonance mass ratio ε_1 = m_light/m_heavy of a Hertzian dimer with equal
contacts and no precompression (Jayaprakash, Starosvetsky & Vakakis 2011, numerical)."""


ANTIRESONANCE_SEARCH_MAX = 0.6
"""Largest ε searched by :func:`antiresonance_mass_ratios`: the small-ε model also has a
zero near ε = 0.82 (Hertz), its image of the trivially tail-free monoatomic chain ε = 1,
which is not an anti-resonance."""


def _exponent(exponent) -> float:
    return float(check_range("exponent", exponent, 1.0, 10.0, closed=(False, True)))


@dataclass(frozen=True)
class HomogenisedCell:
    """A periodic cell as an effective monoatomic chain (:func:`homogenise_cell`).

    Attributes
    ----------
    mass : float
        Cell mass M = Σ m_i, kg.
    k_eff : float
        Effective contact constant (Σ k_j^{-1/n})^{-n}, N/m^n.
    length : float
        Cell length L, m.
    dispersion : float
        γ of the acoustic branch ω² = c0² q²(1 - γ q² + …), m².
    exponent : float
        n.
    k_contacts : tuple of float
        The cell's contact constants, N/m^n.
    """

    mass: float
    k_eff: float
    length: float
    dispersion: float
    exponent: float
    k_contacts: tuple[float, ...]

    def static_compression(self, force) -> float | np.ndarray:
        """Cell compression Δ = Σ_j (F/k_j)^{1/n} = (F/k_eff)^{1/n} at contact force F, m."""
        f = check_nonnegative("force", force)
        out = (f / self.k_eff) ** (1.0 / self.exponent)
        return out if np.ndim(out) else float(out)


def _acoustic_dispersion(masses: np.ndarray, springs: np.ndarray, length: float) -> float:
    """γ (m²) of the acoustic branch of a periodic mass-spring cell, from its Bloch matrix.

    Spring j joins grain j-1 and grain j (spring 0: the last grain of the previous cell
    and grain 0).  ω²(q) is the lowest eigenvalue of Φ(q) u = ω² M u; with θ = qL and
    c0² = K_eff L²/M (K_eff = 1/Σ 1/K_j), f(θ) = ω²/(c0² q²) = 1 - γ q² + b q⁴ - c q⁶ is
    fitted at θ = 0.1, 0.2, 0.3 (relative error of γ ~ 1e-10).
    """
    from scipy.linalg import eigh  # (lazy: scipy.* costs start-up where unused)
    p = masses.size
    c2 = length**2 / (masses.sum() * np.sum(1.0 / springs))
    fs = []
    thetas = np.array([0.1, 0.2, 0.3])
    for th in thetas:
        phi = np.zeros((p, p), dtype=complex)
        for j in range(p):
            i = (j - 1) % p
            ph = np.exp(-1j * th) if j == 0 else 1.0  # grain j-1 lies in the previous cell
            phi[j, j] += springs[j]
            phi[i, i] += springs[j]
            phi[j, i] -= springs[j] * ph
            phi[i, j] -= springs[j] * np.conj(ph)
        w2 = eigh(phi, np.diag(masses).astype(complex), eigvals_only=True)[0]
        fs.append(w2 / (c2 * (th / length) ** 2))
    x = (thetas / length) ** 2
    a = np.stack([-x, x**2, -(x**3)], axis=1)
    gamma = np.linalg.solve(a, np.array(fs) - 1.0)[0]
    return float(gamma)


def homogenise_cell(masses, k_contacts, length: float, *,
                    exponent: float = 1.5) -> HomogenisedCell:
    r"""Homogenise a periodic cell into an effective monoatomic chain (module docstring).

    Contact j joins grain j-1 and grain j of the periodic chain (contact 0: the last grain
    of the previous cell and grain 0).  γ is computed from the linearised cell with the
    spring constants K_j = n k_j^{1/n} F^{(n-1)/n} of a common force F (their ratios, all
    γ depends on, do not depend on F: the same γ for any precompression and in the
    δ0 → 0 limit).  For a dimer with one spring K, expanding the acoustic branch
    ω² = K μ [1 - √(1 - 4 sin²(qL/2)/(μ² m_1 m_2))], μ = 1/m_1 + 1/m_2, gives
    γ = (L²/4)(1/3 - m_1 m_2/(m_1 + m_2)²) (L²/12 per grain for m_1 = m_2: the monoatomic
    d²/12 of paper Eq. 4).

    Parameters
    ----------
    masses : array, shape (p,)
        Masses of the grains of one cell, kg (> 0).
    k_contacts : array, shape (p,)
        Contact constants, N/m^n (> 0).
    length : float
        Cell length (sum of the grain diameters), m (> 0).
    exponent : float
        n of F = k δ^n, in (1, 10].
    """
    n = _exponent(exponent)
    m = check_positive("masses", np.atleast_1d(masses)).astype(float)
    k = check_positive("k_contacts", np.atleast_1d(k_contacts)).astype(float)
    if k.shape != m.shape:
        raise ValueError(f"k_contacts must have the shape of masses {m.shape} (got {k.shape})")
    length = float(check_positive("length", length))
    k_eff = float(np.sum(k ** (-1.0 / n)) ** (-n))
    springs = k ** (1.0 / n) / np.max(k ** (1.0 / n))
    if m.size == 1:
        gamma = length**2 / 12.0
    else:
        gamma = _acoustic_dispersion(m, springs, length)
    return HomogenisedCell(mass=float(m.sum()), k_eff=k_eff, length=length, dispersion=gamma,
                           exponent=n, k_contacts=tuple(float(x) for x in k))


def cell_sound_speed(cell: HomogenisedCell, static_force: float) -> float:
    """Long-wave sound speed of a precompressed periodic chain, c0 = L √(K_eff/M), m/s.

    K_eff = 1/Σ_j 1/K_j with K_j = n k_j δ_j^{n-1}, δ_j = (F0/k_j)^{1/n}: springs in
    series; equal to :func:`theory.speeds.c0` of the effective chain at
    its compression (F0/k_eff)^{1/n}.

    Parameters
    ----------
    cell : HomogenisedCell
    static_force : float
        Static contact force F0, N (> 0).
    """
    f0 = float(check_positive("static_force", static_force))
    n = cell.exponent
    k = np.asarray(cell.k_contacts)
    stiff = n * k * (f0 / k) ** ((n - 1) / n)
    return float(cell.length * np.sqrt(1.0 / (np.sum(1.0 / stiff) * cell.mass)))


def cell_solitary_speed(cell: HomogenisedCell, force_max, static_force: float = 0.0):
    r"""Long-wave solitary-wave speed of a periodic chain at peak contact force F_m, m/s.

    The effective chain (M, L, k_eff) at static compression Δ0 = (F0/k_eff)^{1/n} carrying
    a wave of peak compression Δ_m = (F_m/k_eff)^{1/n}: Nesterenko's speed
    (:func:`theory.speeds.nesterenko_speed` at ξ0 = Δ0/L, ξ_max = (Δ_m - Δ0)/L).  At δ0 = 0,
    V = √(2/(n+1)) L √(k_eff/M) Δ_m^{(n-1)/2}; for a dimer with equal contacts this is
    the monoatomic speed of grains of the mean mass (m_1 + m_2)/2 and the mean spacing at
    the same force.  Compared with the discrete chain in docs/physics.md §14.

    Parameters
    ----------
    cell : HomogenisedCell
    force_max : float or array
        Peak contact force of the wave, N (> static_force).
    static_force : float
        Static contact force F0, N (>= 0).
    """
    f0 = float(check_nonnegative("static_force", static_force))
    fm = check_positive("force_max", force_max)
    if np.any(fm <= f0):
        raise ValueError(f"force_max must exceed static_force = {f0!r} N")
    d0 = cell.static_compression(f0)
    dm = np.asarray(cell.static_compression(fm))
    n, length = cell.exponent, cell.length
    return nesterenko_speed(c_mat(cell.k_eff, cell.mass, length, n), d0 / length,
                            (dm - d0) / length, n)


# ------------------------------------------------------------------ anti-resonances
@lru_cache(maxsize=8)
def _heavy_motion(n: float):
    """The heavy grains' motion as ε → 0: u(ζ), ζ = i - s t, its rate s and shift D.

    The exact wave of the heavy chain (k_eff = 2^{-n}, masses 1, contacts k = 1).
    """
    from scipy.interpolate import CubicSpline  # (lazy: scipy.* costs start-up where unused)
    w = discrete_solitary_wave(2.0**-n, 1.0, 1.0, velocity_max=1.0, exponent=n)
    ppg = w.points_per_grain
    r = w.overlap.reshape(-1, ppg)  # rows: grains, columns: sub-grid phase
    # u(z) = Σ_{g ≥ 1} r(z + g): per phase, reversed cumulative sums shifted by one grain
    u = np.vstack([np.cumsum(r[::-1], axis=0)[::-1][1:], np.zeros((1, ppg))]).ravel()
    spline = CubicSpline(w.z, u)
    lo, hi, shift = w.z[0], w.z[-1], float(w.net_shift)

    def motion(z):  # u → D behind the domain, 0 ahead (the δ0 = 0 tails are doubly exponential)
        return np.where(z < lo, shift, np.where(z > hi, 0.0, spline(np.clip(z, lo, hi))))

    return motion, w.grain_rate, shift, float(w.energy()), float(w.amplitude)


def _light_grain_residual(eps: np.ndarray, n: float) -> np.ndarray:
    r"""Energy left in a light grain after the ε → 0 wave has passed, over the wave's.

    ε m ẍ = k[U_0 - x]_+^n - k[x - U_1]_+^n with U_0(t) = u(-s t), U_1(t) = u(1 - s t) the
    heavy neighbours (k = m = 1), from rest 10 grains before the wave to 10 after it;
    classical RK4 with 60 steps per period of the light grain's fastest linear oscillation
    √(2n (A/2)^{n-1}/ε) at the wave's peak compression A.
    """
    spline, s, shift, energy, amp = _heavy_motion(n)
    t0, t1 = -10.0 / s, 10.0 / s
    omega = np.sqrt(2 * n * (amp / 2) ** (n - 1) / np.min(eps))
    steps = int(np.ceil((t1 - t0) * omega * 60 / (2 * np.pi)))
    dt = (t1 - t0) / steps
    tt = t0 + dt * np.arange(2 * steps + 1) / 2  # the RK4 stage times
    u0, u1 = spline(-s * tt), spline(1.0 - s * tt)
    x = 0.5 * (u0[0] + u1[0]) * np.ones_like(eps)
    v = np.zeros_like(eps)

    def acc(xx, a, b):
        return (np.maximum(a - xx, 0.0) ** n - np.maximum(xx - b, 0.0) ** n) / eps

    for i in range(steps):
        a0, b0 = u0[2 * i], u1[2 * i]
        am, bm = u0[2 * i + 1], u1[2 * i + 1]
        a1, b1 = u0[2 * i + 2], u1[2 * i + 2]
        k1x, k1v = v, acc(x, a0, b0)
        k2x, k2v = v + 0.5 * dt * k1v, acc(x + 0.5 * dt * k1x, am, bm)
        k3x, k3v = v + 0.5 * dt * k2v, acc(x + 0.5 * dt * k2x, am, bm)
        k4x, k4v = v + dt * k3v, acc(x + dt * k3x, a1, b1)
        x = x + dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v = v + dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
    pot = (np.maximum(u0[-1] - x, 0.0) ** (n + 1) + np.maximum(x - u1[-1], 0.0) ** (n + 1))
    return (0.5 * eps * v**2 + pot / (n + 1)) / energy


@lru_cache(maxsize=16)
def _antiresonances(count: int, n: float) -> tuple[float, ...]:
    """The ``count`` largest zeros of the light grain's residual energy.

    Scanned below the search maximum band by band downward (each band with its own RK4
    step); each local minimum of √(residual) is zoomed onto and kept if it is a zero
    (√residual < 1e-6).
    """
    found: list[float] = []
    edges = ANTIRESONANCE_SEARCH_MAX / 1.6 ** np.arange(0, 16)  # down to ~5e-4
    for hi, lo in zip(edges[:-1], edges[1:], strict=True):
        grid = np.geomspace(lo / 1.1, hi * 1.1, 30)  # overlapping bands
        res = np.sqrt(_light_grain_residual(grid, n))
        minima = np.flatnonzero((res[1:-1] < res[:-2]) & (res[1:-1] < res[2:])) + 1
        for j in minima[::-1]:
            a, b = grid[j - 1], grid[j + 1]
            for _ in range(7):  # zoom onto the minimum, 7.5× per level
                g = np.linspace(a, b, 16)
                r = np.sqrt(_light_grain_residual(g, n))
                c = int(np.argmin(r))
                a, b = g[max(c - 1, 0)], g[min(c + 1, 15)]
            # a zero of the residual (not a shallow minimum), counted in one band only
            if r[c] < 1e-6 and lo <= g[c] < hi:
                found.append(float(g[c]))
            if len(found) == count:
                return tuple(found)
    raise RuntimeError(f"found only {len(found)} anti-resonances above {edges[-1]:g}")


def antiresonance_mass_ratios(count: int = 3, *, exponent: float = 1.5) -> np.ndarray:
    r"""Small-ε estimate of a dimer's anti-resonance mass ratios ε_1 > ε_2 > ….

    Model (leading order in the light-to-heavy mass ratio ε; derived here after the
    asymptotic picture of Jayaprakash, Starosvetsky & Vakakis 2011).  As ε → 0 a light
    grain is a massless link: the heavy grains form a monoatomic chain with contact
    constant k 2^{-n} (two contacts in series) and carry its exact solitary wave
    (:func:`theory.discrete_solitary_wave`).  A light grain of mass εm between two heavy
    neighbours moving so, ε m ẍ = k[U_0 - x]_+^n - k[x - U_1]_+^n, is set oscillating by
    the passage; a tail-free wave needs it left at rest, i.e. the energy it keeps after
    the passage (relative to the wave's) to vanish.  Its zeros are the ε_k, independent of
    the wave's amplitude (the δ0 = 0 wave is self-similar).  For Hertz: 0.2777, 0.1463,
    0.0913; the discrete chain's are 0.343, 0.155, 0.090 (docs/physics.md §14): the estimate
    improves as ε_k → 0.

    Parameters
    ----------
    count : int
        How many, in [1, 8].
    exponent : float
        n of F = k δ^n, in (1, 10].

    Returns
    -------
    ndarray
        ε_1 > ε_2 > … (m_light/m_heavy).
    """
    if int(count) != count or not 1 <= count <= 8:
        raise ValueError(f"count must be an integer in [1, 8] (got {count!r})")
    return np.array(_antiresonances(int(count), _exponent(exponent)))
