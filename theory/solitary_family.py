r"""The exact discrete solitary waves of one uniform section as a one-parameter family.

A solitary wave of a section (grain mass m, Hertz constant k, static overlap δ0) is fixed
by its amplitude A = r_max − δ0, the peak dynamic overlap.  Its conserved quantities are
(docs/physics.md §16.1; :class:`theory.DiscreteSolitaryWave`):

* energy E = Σ ½ m v_i² + Σ [U(r_j) − U(δ0)], U(r) = k r^{n+1}/(n+1) (J; the wave energy
  of docs/physics.md §6, linear term kept),
* momentum P = Σ m v_i = m s D (kg m/s), s = V/d the wave's speed in grains per second,
* net shift D = Σ_j (r_j − δ0) (m): the displacement of the grains behind the wave, which
  is also the total compression the wave carries (Σ_j r_j is conserved by paper Eq. 2).

**Scaling.**  Without precompression (δ0 = 0) the travelling-wave equation
s² R'' = (k/m) Δ₂ F(R) with F = k R^n is invariant under R → λR, s → λ^{(n−1)/2} s
(:func:`theory.discrete_solitary_wave`), so with the unit wave (k = m = d = A = 1) of
energy ê, momentum p̂, net shift D̂ and grain rate ŝ::

    E = ê k A^{n+1},   P = p̂ (m k)^{1/2} A^{(n+1)/2},   D = D̂ A,   s = ŝ (k/m)^{1/2} A^{(n−1)/2}

(Hertz: E ∝ k A^{5/2}, P ∝ (mk)^{1/2} A^{5/4}, V ∝ (k/m)^{1/2} A^{1/4}).  Eliminating A,
**P² = (p̂²/ê) m E**: the wave is a quasi-particle of effective mass M = (p̂²/2ê) m
(1.304 m for Hertz), proportional to the grain mass and independent of k (Sen, Hong,
Bang, Avalos & Doney, Phys. Rep. 462, 21 (2008), §5; Tichler et al., PRL 111, 048001
(2013)).

Under precompression (Hertz only) the same rescaling with λ = δ0 leaves one parameter,
ε = A/δ0::

    E = k δ0^{5/2} ê(ε),   P = (m k)^{1/2} δ0^{5/4} p̂(ε),
    D = δ0 D̂(ε),           s = (k/m)^{1/2} δ0^{1/4} ŝ(ε)

ê, p̂, D̂, ŝ are tabulated from :func:`theory.discrete_solitary_wave` on
:data:`TABLE_RANGE` (:data:`TABLE_POINTS_PER_DECADE` points a decade, interpolated by
cubic splines in log–log) the first time they are needed.  Below the table the KdV limit
continues them (docs/physics.md §2: strain ε sech²(κz), κ² = ε/2 per grain²,
ŝ² = (3/2)(1 + ε/6)): D̂ = 2√(2ε), ê = 2√2 (ε^{1/2} + ε^{3/2}), p̂ = ŝ D̂, each times
(1 + c ε) with c matched at the table's lower end; above it each of ê/ε^{5/2},
p̂/ε^{5/4}, D̂/ε, ŝ/ε^{1/4} goes linearly in 1/ε to its sonic-vacuum value (the
precompression's correction is O(δ0/A): the table's last decade shows it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ._validate import check_nonnegative, check_positive, check_range

__all__ = ["TABLE_RANGE", "TABLE_POINTS_PER_DECADE", "WaveInvariants", "SolitaryWaveFamily",
           "sonic_vacuum_invariants", "precompressed_invariants"]

TABLE_RANGE = (1e-2, 1e4)
"""ε = A/δ0 range of the precompressed table (KdV limit below, sonic vacuum above)."""
TABLE_POINTS_PER_DECADE = 6
"""Table points per decade of ε: the splines interpolate ê, p̂, D̂, ŝ to better than
1e-4 relative between the points (tests/theory/test_strong_interface.py)."""
_PPG = 16
"""Grid points per grain of the tabulated waves (the invariants agree with 32 to 1e-13)."""


@dataclass(frozen=True)
class WaveInvariants:
    """Conserved quantities and speed of one solitary wave (units of the caller's inputs).

    Attributes
    ----------
    energy, momentum, net_shift, grain_rate : float
        E (J), P = m s D (kg m/s), D (m) and s = V/d (grains per second).
    """

    energy: float
    momentum: float
    net_shift: float
    grain_rate: float


@lru_cache(maxsize=8)
def sonic_vacuum_invariants(exponent: float = 1.5) -> WaveInvariants:
    """ê, p̂, D̂, ŝ of the unit sonic-vacuum wave (k = m = d = A = 1, δ0 = 0, F = k r^n).

    From :func:`theory.discrete_solitary_wave` (module docstring, scaling).
    """
    from .profiles import discrete_solitary_wave

    n = float(check_range("exponent", exponent, 1.0, 10.0, closed=(False, True)))
    w = discrete_solitary_wave(1.0, 1.0, 1.0, 0.0, amplitude=1.0, exponent=n,
                               points_per_grain=_PPG)
    return WaveInvariants(w.energy(), w.momentum(), w.net_shift, w.grain_rate)


@lru_cache(maxsize=1)
def _table():
    """(log ε, splines of log ê, log p̂, log D̂, log ŝ) of the precompressed Hertz waves."""
    from scipy.interpolate import CubicSpline

    from .profiles import discrete_solitary_wave

    lo, hi = (math.log10(x) for x in TABLE_RANGE)
    eps = np.logspace(lo, hi, round((hi - lo) * TABLE_POINTS_PER_DECADE) + 1)
    rows = []
    for e in eps:
        w = discrete_solitary_wave(1.0, 1.0, 1.0, 1.0, amplitude=float(e), points_per_grain=_PPG)
        rows.append((w.energy(), w.momentum(), w.net_shift, w.grain_rate))
    x, y = np.log(eps), np.log(np.array(rows))
    return x, tuple(CubicSpline(x, y[:, j]) for j in range(4))


_POWERS = (2.5, 1.25, 1.0, 0.25)
"""Sonic-vacuum powers of ε of ê, p̂, D̂, ŝ (Hertz; module docstring)."""


def _kdv(eps: float) -> tuple[float, float, float, float]:
    """Leading KdV forms of ê, p̂, D̂, ŝ (module docstring)."""
    s = math.sqrt(1.5 * (1.0 + eps / 6.0))
    shift = 2.0 * math.sqrt(2.0 * eps)
    return 2.0 * math.sqrt(2.0) * (math.sqrt(eps) + eps**1.5), s * shift, shift, s


def precompressed_invariants(strain_over_delta0: float) -> WaveInvariants:
    """ê(ε), p̂(ε), D̂(ε), ŝ(ε) of the Hertz wave of amplitude A = ε δ0 (k = m = d = δ0 = 1).

    Parameters
    ----------
    strain_over_delta0 : float
        ε = A/δ0 (> 0, finite): the peak dynamic overlap over the static one (equal to the
        incident strain / δ0 of the validity map, hertzchain.reproduce.validity).
    """
    eps = float(check_positive("strain_over_delta0", strain_over_delta0))
    x, splines = _table()
    lx = math.log(eps)
    if x[0] <= lx <= x[-1]:
        return WaveInvariants(*(math.exp(float(s(lx))) for s in splines))
    if lx < x[0]:
        e0 = math.exp(x[0])
        at_edge = [math.exp(float(s(x[0]))) for s in splines]
        out = [a * (1.0 + (t / a0 - 1.0) / e0 * eps)
               for a, a0, t in zip(_kdv(eps), _kdv(e0), at_edge, strict=True)]
        return WaveInvariants(*out)
    sv = sonic_vacuum_invariants(1.5)
    e1 = math.exp(x[-1])
    frac = e1 / eps  # the O(δ0/A) correction falls as 1/ε
    out = []
    for s, p, limit in zip(splines, _POWERS, (sv.energy, sv.momentum, sv.net_shift,
                                               sv.grain_rate), strict=True):
        g1 = math.exp(float(s(x[-1]))) / e1**p
        out.append((limit + (g1 - limit) * frac) * eps**p)
    return WaveInvariants(*out)


@dataclass(frozen=True)
class SolitaryWaveFamily:
    """The solitary waves of one uniform section: invariants as functions of amplitude.

    Parameters
    ----------
    mass : float
        Grain mass m (> 0), kg (or any unit, consistently).
    k_n : float
        Contact constant k (> 0) of F = k r^n, N/m^n.
    delta0 : float
        Static overlap δ0 (>= 0), m; δ0 > 0 needs ``exponent`` = 3/2 (Hertz).
    exponent : float
        n of the contact law, in (1, 10].
    """

    mass: float
    k_n: float
    delta0: float = 0.0
    exponent: float = 1.5

    def __post_init__(self):
        check_positive("mass", self.mass)
        check_positive("k_n", self.k_n)
        check_nonnegative("delta0", self.delta0)
        n = float(check_range("exponent", self.exponent, 1.0, 10.0, closed=(False, True)))
        if n != 1.5 and self.delta0 > 0:
            raise ValueError(f"exponent = {n:g} needs delta0 = 0 (precompressed waves are "
                             "tabulated for Hertz, exponent 1.5, only)")

    @property
    def force(self) -> float:
        """Static contact force F0 = k δ0^n, N (the same in every section: equilibrium)."""
        return self.k_n * self.delta0**self.exponent

    @property
    def sound_grain_rate(self) -> float:
        """Long-wave sound speed over d, c0/d = (n k δ0^{n−1}/m)^{1/2}, 1/s (0 at δ0 = 0)."""
        if self.delta0 == 0:
            return 0.0
        return math.sqrt(self.exponent * self.k_n * self.delta0 ** (self.exponent - 1)
                         / self.mass)

    def invariants(self, amplitude: float) -> WaveInvariants:
        """E, P, D, s of the wave of amplitude A = r_max − δ0 (module docstring's scaling).

        A = 0 gives zeros (and the sound grain rate): no wave.
        """
        a = float(check_nonnegative("amplitude", amplitude))
        m, k, n = self.mass, self.k_n, self.exponent
        if a == 0:
            return WaveInvariants(0.0, 0.0, 0.0, self.sound_grain_rate)
        if self.delta0 == 0:
            u = sonic_vacuum_invariants(n)
            return WaveInvariants(u.energy * k * a ** (n + 1),
                                  u.momentum * math.sqrt(m * k) * a ** ((n + 1) / 2),
                                  u.net_shift * a,
                                  u.grain_rate * math.sqrt(k / m) * a ** ((n - 1) / 2))
        d0 = self.delta0
        u = precompressed_invariants(a / d0)
        return WaveInvariants(u.energy * k * d0**2.5, u.momentum * math.sqrt(m * k) * d0**1.25,
                              u.net_shift * d0, u.grain_rate * math.sqrt(k / m) * d0**0.25)

    def amplitude_of(self, quantity: str, value: float) -> float:
        """Amplitude A of the wave whose ``quantity`` has ``value`` (0 for value 0).

        ``quantity`` is ``"momentum"``, ``"energy"`` or ``"excess_energy"`` (E − F0 D, the
        energy beyond the linear part F0 D; docs/physics.md §16.3); each grows
        monotonically with A.
        """
        from scipy.optimize import brentq

        if quantity not in ("momentum", "energy", "excess_energy"):
            raise ValueError(f"quantity must be 'momentum', 'energy' or 'excess_energy' "
                             f"(got {quantity!r})")
        v = float(check_nonnegative(quantity, value))
        if v == 0:
            return 0.0

        def of(log_a: float) -> float:
            w = self.invariants(math.exp(log_a))
            q = {"momentum": w.momentum, "energy": w.energy,
                 "excess_energy": w.energy - self.force * w.net_shift}[quantity]
            return math.log(q / v) if q > 0 else -math.inf

        # a bracket in log A: the quantities grow at least as A^{1/2} (KdV) and at most as
        # A^{n+1}; start at the scale of δ0 (or 1 in the sonic vacuum) and widen
        lo = hi = math.log(self.delta0) if self.delta0 > 0 else 0.0
        while of(lo) > 0:
            lo -= 8.0
        while of(hi) < 0:
            hi += 8.0
        return math.exp(brentq(of, lo, hi, xtol=1e-14, rtol=1e-15))
