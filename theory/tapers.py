r"""Tapered chains: binary-collision and adiabatic estimates of the transmitted pulse.

A tapered chain has grain masses changing by a factor q per grain (radii by q^{1/3} at a
fixed material): q < 1 forward (large to small grains), q > 1 backward.  Tapered chains
spread and absorb an impact (Sen, Manciu & Wright, Phys. Rev. E 57 (1998) 2386; Nakagawa,
Agui, Wu & Vivanco, Granular Matter 4 (2003) 167; Doney & Sen, Phys. Rev. Lett. 97 (2006)
155502).  Two estimates of the pulse, each exact in its own limit:

* **Binary-collision approximation** (BCA; Harbola, Rosas, Esposito & Lindenberg, Phys.
  Rev. E 80 (2009) 031303; the hard-sphere cascade of Nakagawa et al. 2003 for the
  velocities): the pulse passes from grain to grain in isolated elastic two-body
  collisions, grain k at rest when struck by grain k-1.  Momentum and energy give
  v_k = 2 m_{k-1} v_{k-1}/(m_{k-1} + m_k) (:func:`bca_velocities`), a growth of 2/(1+q)
  per grain; the contact force and duration of each collision follow from the two-body
  Hertz problem (:func:`binary_collision`).  Exact for hard grains (collision time ≪
  time between collisions); a strong taper makes the collisions overlap.
* **Adiabatic solitary wave** (a weak taper, 1 - q → 0): the exact lattice solitary wave
  (docs/physics.md §7) of the local grains carries the conserved energy E; its peak
  velocity goes as m^{-1/2} and its force as k^{1/(n+1)} (:func:`adiabatic_taper_wave`).
  To first order in 1 - q it has the BCA's velocity growth, q^{-1/2} = 2/(1+q) + O((1-q)²).

The published comparisons (Harbola et al. 2009: the BCA pulse velocity "quantitatively
accurate"; Machado, Rosas & Lindenberg, Eur. Phys. J. E (2013), arXiv:1307.1191: the BCA
captures the trends of the momentum and energy along tapered chains, not their values)
give no numerical tolerance; the agreement with the discrete chain is in
docs/physics.md §12.

The adiabatic wave scales the exact lattice wave at δ0 = 0 with its dimensionless
constants (energy, momentum, amplitude and speed per peak velocity:
:func:`theory.profiles.sonic_vacuum_wave_constants`, which :mod:`theory.striker` and
:mod:`theory.dissipation` use too).
"""

from __future__ import annotations

from dataclasses import dataclass
from math import gamma

import numpy as np

from ._validate import check_positive, check_range
from .profiles import sonic_vacuum_wave_constants

__all__ = [
    "bca_velocities",
    "BinaryCollision",
    "binary_collision",
    "bca_arrival_times",
    "wall_impact_force",
    "TaperRatios",
    "geometric_taper_ratios",
    "AdiabaticTaperWave",
    "adiabatic_taper_wave",
]


def _ret(x):
    x = np.asarray(x, dtype=float)
    return x if x.ndim else float(x)


def _exponent(exponent) -> float:
    return float(check_range("exponent", exponent, 1.0, 10.0, closed=(False, True)))


# ------------------------------------------------------------------ binary collisions
def bca_velocities(masses, v0: float) -> np.ndarray:
    """Velocity of each grain after it is struck, binary-collision approximation, m/s.

    v_0 = v0 and v_k = 2 m_{k-1} v_{k-1}/(m_{k-1} + m_k) (elastic collision of k-1 at
    v_{k-1} with k at rest; Harbola et al. 2009).  For a geometric taper m_k = q^k m_0,
    v_k = (2/(1+q))^k v0.

    Parameters
    ----------
    masses : array, shape (N,)
        Grain masses in the order the pulse meets them, kg (> 0).
    v0 : float
        Velocity given to grain 0, m/s (> 0).
    """
    m = check_positive("masses", np.atleast_1d(masses))
    v0 = float(check_positive("v0", v0))
    return v0 * np.cumprod(np.r_[1.0, 2.0 * m[:-1] / (m[:-1] + m[1:])])


@dataclass(frozen=True)
class BinaryCollision:
    """One elastic two-body collision with F = k r^n (:func:`binary_collision`).

    Attributes
    ----------
    time_to_max : float or ndarray
        Time from first contact to the largest overlap, s (half the contact duration).
    max_overlap : float or ndarray
        Largest overlap, m.
    max_force : float or ndarray
        Peak contact force k r_max^n, N.
    velocity_striker, velocity_struck : float or ndarray
        Velocities after the collision, m/s.
    """

    time_to_max: float | np.ndarray
    max_overlap: float | np.ndarray
    max_force: float | np.ndarray
    velocity_striker: float | np.ndarray
    velocity_struck: float | np.ndarray


def _collision_integral(n: float) -> float:
    """∫_0^1 dx/√(1 - x^{n+1}) = √π Γ(1 + 1/(n+1))/Γ(1/2 + 1/(n+1))."""
    p = 1.0 / (n + 1.0)
    return float(np.sqrt(np.pi) * gamma(1.0 + p) / gamma(0.5 + p))


def binary_collision(m1, m2, k, v, *, exponent: float = 1.5) -> BinaryCollision:
    r"""Elastic collision of a grain (m1, at v) with a grain at rest (m2), F = k r^n.

    The overlap obeys μ r̈ = -k r^n, μ = m1 m2/(m1 + m2), r(0) = 0, ṙ(0) = v: energy
    ½ μ v² = k r_max^{n+1}/(n+1) gives r_max = ((n+1) μ v²/(2k))^{1/(n+1)}, and

    .. math:: t_{max} = \int_0^{r_{max}} \frac{dr}{\sqrt{v^2 - 2k r^{n+1}/((n+1)\mu)}}
              = \frac{r_{max}}{v}\,\frac{\sqrt\pi\,\Gamma(1 + \frac{1}{n+1})}
              {\Gamma(\frac12 + \frac{1}{n+1})}

    (Johnson, *Contact Mechanics*, 1985, §11.4 for n = 3/2: 1.4716 r_max/v).  The
    collision is symmetric in time and elastic: v1′ = (m1 - m2) v/(m1 + m2),
    v2′ = 2 m1 v/(m1 + m2).  In the BCA the pulse is handed from grain k-1 to grain k in
    t_max, when the two move together (Harbola et al. 2009).

    Parameters
    ----------
    m1, m2 : float or array
        Masses of the striking and the struck grain, kg (> 0; m2 = inf: a rigid wall).
    k : float or array
        Contact constant, N/m^n (> 0).
    v : float or array
        Approach velocity, m/s (> 0).
    exponent : float
        n, in (1, 10].
    """
    n = _exponent(exponent)
    m1, k, v = (check_positive(a, b) for a, b in (("m1", m1), ("k", k), ("v", v)))
    m2 = np.asarray(m2, dtype=float)
    if np.any(~(m2 > 0)):
        raise ValueError("m2 must be > 0 kg (inf: a rigid wall)")
    wall = np.isinf(m2)
    mu = np.where(wall, m1, m1 * m2 / (m1 + np.where(wall, 1.0, m2)))
    r_max = ((n + 1) * mu * v**2 / (2 * k)) ** (1 / (n + 1))
    ratio = np.where(wall, 1.0, m2 / np.where(wall, 1.0, m1))
    return BinaryCollision(
        time_to_max=_ret(r_max / v * _collision_integral(n)), max_overlap=_ret(r_max),
        max_force=_ret(k * r_max**n),
        velocity_striker=_ret(np.where(wall, -v, (1 - ratio) / (1 + ratio) * v)),
        velocity_struck=_ret(np.where(wall, 0.0, 2 / (1 + ratio) * v)))


def bca_arrival_times(masses, k_contacts, v0: float, *, exponent: float = 1.5) -> np.ndarray:
    r"""Time at which the BCA pulse reaches each grain, s (grain 0 struck at t = 0).

    t_i = Σ_{j=1}^{i} t_max(m_{j-1}, m_j, k_j, v_{j-1}) with the velocities of
    :func:`bca_velocities` and the collision times of :func:`binary_collision`: the pulse
    reaches grain i when it moves together with grain i-1 (the largest overlap).  On a
    uniform Hertz chain the BCA speed is d/t_max = 0.8201 c^{4/5} v0^{1/5}
    (c² = k d^{5/2}/m), 2.4 % below the speed 0.8405 c^{4/5} v0^{1/5} of the solitary wave
    an impact at v0 forms (v_max = 0.6816 v0; docs/physics.md §12).

    Parameters
    ----------
    masses : array, shape (N,)
        Grain masses, kg.
    k_contacts : array, shape (N-1,)
        Constants of the grain–grain contacts (contact j between grains j-1 and j),
        N/m^n.
    v0 : float
        Velocity of grain 0, m/s.
    exponent : float
        n, in (1, 10].
    """
    m = check_positive("masses", np.atleast_1d(masses))
    k = check_positive("k_contacts", np.atleast_1d(k_contacts))
    if k.shape != (m.size - 1,):
        raise ValueError(f"k_contacts must have shape ({m.size - 1},) (got {k.shape})")
    v = bca_velocities(m, v0)
    c = binary_collision(m[:-1], m[1:], k, v[:-1], exponent=exponent)
    return np.r_[0.0, np.cumsum(c.time_to_max)]


def wall_impact_force(mass, k_wall, v, *, exponent: float = 1.5):
    """Peak force of a grain (mass m at v) hitting a rigid wall, N (binary collision).

    k_w ((n+1) m v²/(2 k_w))^{n/(n+1)}: :func:`binary_collision` with m2 = ∞ (for Hertz
    k_w (5 m v²/(4 k_w))^{3/5}, Johnson 1985 §11.4).  With the BCA velocity of the last
    grain it estimates the force a tapered chain transmits to a wall (Harbola et al. 2009).
    """
    return binary_collision(mass, np.inf, k_wall, v, exponent=exponent).max_force


@dataclass(frozen=True)
class TaperRatios:
    """Per-grain factors of a geometric taper (masses × q per grain), two estimates.

    Attributes
    ----------
    bca_velocity, bca_energy, bca_momentum : float
        Binary collisions: 2/(1+q), 4q/(1+q)² (kinetic energy of the leading grain),
        2q/(1+q).
    adiabatic_velocity, adiabatic_momentum, adiabatic_force, adiabatic_speed : float
        Adiabatic solitary wave (energy conserved): q^{-1/2}, q^{1/2},
        q^{1/(6(n+1))} and q^{1/3 + 1/(6(n+1)) - 1/2} for spheres of one material
        (d ∝ m^{1/3}, k ∝ √d ∝ m^{1/6}): m^{1/15} and m^{-1/10} for Hertz.
    """

    bca_velocity: float
    bca_energy: float
    bca_momentum: float
    adiabatic_velocity: float
    adiabatic_momentum: float
    adiabatic_force: float
    adiabatic_speed: float


def geometric_taper_ratios(q: float, *, exponent: float = 1.5) -> TaperRatios:
    """Per-grain growth factors of the pulse in a geometric taper (:class:`TaperRatios`).

    BCA from :func:`bca_velocities`; adiabatic from the exact wave at constant energy,
    E = C m v², P = C′ m v, peak force k A^n with A ∝ (v √(m/k))^{2/(n+1)}, i.e.
    F ∝ k^{1/(n+1)} E^{n/(n+1)}, and V = d s ∝ d k^{1/(n+1)} m^{-1/2} E^{(n-1)/(2(n+1))}
    (:class:`theory.profiles.SonicVacuumWave`).  Both velocity factors agree to first
    order in 1 - q.

    Parameters
    ----------
    q : float
        Mass ratio of consecutive grains, > 0 (< 1 forward, > 1 backward).
    exponent : float
        n, in (1, 10].
    """
    n = _exponent(exponent)
    q = float(check_positive("q", q))
    fk = 1.0 / (6 * (n + 1))
    return TaperRatios(bca_velocity=2 / (1 + q), bca_energy=4 * q / (1 + q) ** 2,
                       bca_momentum=2 * q / (1 + q), adiabatic_velocity=q**-0.5,
                       adiabatic_momentum=q**0.5, adiabatic_force=q**fk,
                       adiabatic_speed=q ** (1 / 3 + fk - 0.5))


# ------------------------------------------------------------------ adiabatic wave
@dataclass(frozen=True)
class AdiabaticTaperWave:
    """The exact lattice wave of the local grains carrying a fixed energy, grain by grain.

    Attributes
    ----------
    velocity_max : ndarray, shape (N,)
        Peak grain velocity √(E/(C m_i)), m/s.
    force_max : ndarray, shape (N,)
        Peak contact force k_i A_i^n, N (contact i: between grains i-1 and i).
    speed : ndarray, shape (N,)
        Wave speed, m/s.
    arrival_time : ndarray, shape (N,)
        Σ spacing/speed from grain ``start`` (0 there), s.
    """

    velocity_max: np.ndarray
    force_max: np.ndarray
    speed: np.ndarray
    arrival_time: np.ndarray


def adiabatic_taper_wave(masses, k_contacts, diameters, energy: float, *,
                         exponent: float = 1.5, start: int = 0) -> AdiabaticTaperWave:
    r"""The adiabatic solitary wave along a slowly varying chain (a weak taper).

    At grain i the wave is the exact lattice wave (δ0 = 0) of a uniform chain of grains
    m_i, contacts k_i (the contact before grain i; k_1 for grain 0) and spacing d_i,
    carrying the energy E (:class:`theory.profiles.SonicVacuumWave`): v_i = √(E/(C m_i)),
    A_i = a (v_i √(m_i/k_i))^{2/(n+1)}, F_i = k_i A_i^n, V_i = s d_i √(k_i/m_i)
    (v_i √(m_i/k_i))^{(n-1)/(n+1)}, and the wave passes grain i at
    t_i = Σ_{j=start+1}^{i} ½(d_{j-1} + d_j)/(½(V_{j-1} + V_j)).  Energy conservation
    holds to leading order in the slow variation; the wave also sheds a tail (a
    first-order loss, quantified in docs/physics.md §12).

    Parameters
    ----------
    masses : array, shape (N,)
        Grain masses, kg.
    k_contacts : array, shape (N-1,)
        Grain–grain contact constants (contact j between grains j-1 and j), N/m^n.
    diameters : array, shape (N,)
        Grain diameters, m.
    energy : float
        Wave energy, J (> 0).
    exponent : float
        n, in (1, 10].
    start : int
        Grain from which the arrival times are counted.
    """
    n = _exponent(exponent)
    m = check_positive("masses", np.atleast_1d(masses))
    k = check_positive("k_contacts", np.atleast_1d(k_contacts))
    d = check_positive("diameters", np.atleast_1d(diameters))
    if k.shape != (m.size - 1,) or d.shape != m.shape:
        raise ValueError(f"k_contacts must have shape ({m.size - 1},) and diameters "
                         f"({m.size},) (got {k.shape}, {d.shape})")
    if int(start) != start or not 0 <= start < m.size:
        raise ValueError(f"start must be an integer in [0, {m.size}) (got {start!r})")
    e = float(check_positive("energy", energy))
    c = sonic_vacuum_wave_constants(n)
    kg = np.r_[k[0], k]
    v = np.sqrt(e / (c.energy * m))
    u = v * np.sqrt(m / kg)
    amp = c.amplitude * u ** (2 / (n + 1))
    speed = c.rate * d * np.sqrt(kg / m) * u ** ((n - 1) / (n + 1))
    dt = 0.5 * (d[:-1] + d[1:]) / (0.5 * (speed[:-1] + speed[1:]))
    t = np.r_[0.0, np.cumsum(dt)]
    return AdiabaticTaperWave(velocity_max=v, force_max=kg * amp**n, speed=speed,
                              arrival_time=t - t[int(start)])
