r"""A striker of mass M hitting an uncompressed chain of grains of mass m: the solitary-wave train.

What is published.  A striker heavier than a grain launches a train of solitary waves of
decreasing amplitude (Nesterenko, *Dynamics of Heterogeneous Materials*, 2001, ch. 1;
Sen, Hong, Bang, Avalos & Doney, Phys. Rep. 462 (2008) 21: the number of waves grows
with M/m).  Job, Melo, Sokolow &
Sen (Granular Matter 10 (2007) 13) show that the force at the struck end unloads nearly
exponentially in time, with a time constant set by the striker and grain masses, so that
successive waves have geometrically decreasing amplitudes.  No closed form for the leading
amplitude or the number of waves as functions of M/m was found in these sources.

The model here (derived for this package; tested against the discrete chain).  Assume a
geometric train, peak velocities v_j = v_1 ρ^{j-1}, and that the striker ends at rest
(in the discrete chain it keeps ≤ 0.3 % of its velocity for M/m ≤ 32).  Each wave is the
exact lattice wave, with energy C_E m v_j² and momentum C_P m v_j
(:func:`theory.profiles.sonic_vacuum_wave_constants`: C_E = 1.0693, C_P = 1.6700 for
Hertz).  Energy and momentum conservation, Σ C_E m v_j² = ½ M v0² and
Σ C_P m v_j = M v0, fix both unknowns:

.. math:: \frac{1-\rho}{1+\rho} = \frac{C_P^2}{2 C_E\, r}, \qquad
          v_1 = \frac{C_P\, r}{C_E\, r + C_P^2/2}\, v_0, \qquad r = M/m .

For r < C_P²/(2C_E) (1.30 for Hertz) ρ < 0: one wave, and the same v_1 is then the wave of
the one-wave-plus-recoiling-striker balance.  As r → ∞, v_1 → (C_P/C_E) v0 = 1.56 v0 and
ρ → 1 - C_P²/(C_E r).  Against the discrete Hertz chain (docs/physics.md §14): v_1 within
0.6, 0.3, 2.9, 6.8, 11, 14 % (low) at r = 1, 2, 4, 8, 16, 32; the ratio of successive
amplitudes tends to ρ along the train (0.719 against 0.720 at r = 8), while the leading
waves are larger than geometric.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validate import check_positive, check_range
from .profiles import sonic_vacuum_wave_constants

__all__ = ["StrikerTrain", "striker_train"]


@dataclass(frozen=True)
class StrikerTrain:
    """The geometric-train model of a striker's solitary waves (:func:`striker_train`).

    Attributes
    ----------
    mass_ratio : float
        r = M/m.
    ratio : float
        ρ, the ratio of successive peak velocities (<= 0: a single wave).
    velocity_max : float
        Peak grain velocity of the leading wave v_1, m/s.
    energy_fraction : float
        Share of the striker's energy in the leading wave, 2 C_E v_1²/(r v0²).
    """

    mass_ratio: float
    ratio: float
    velocity_max: float
    energy_fraction: float

    def velocities(self, count: int) -> np.ndarray:
        """Peak velocities of the first ``count`` waves, v_1 ρ^{j-1}, m/s."""
        if int(count) != count or count < 1:
            raise ValueError(f"count must be an integer >= 1 (got {count!r})")
        if self.ratio <= 0:
            return np.r_[self.velocity_max, np.zeros(int(count) - 1)]
        return self.velocity_max * self.ratio ** np.arange(int(count))

    def count_above(self, fraction: float) -> int:
        """Number of waves whose peak velocity exceeds ``fraction`` of the leading one.

        1 + ⌊ln f / ln ρ⌋ for 0 < ρ < 1 (1 for a single wave).
        """
        f = float(check_range("fraction", fraction, 0.0, 1.0))
        if self.ratio <= 0:
            return 1
        return 1 + int(np.floor(np.log(f) / np.log(self.ratio)))


def striker_train(mass_ratio: float, v0: float = 1.0, *, exponent: float = 1.5) -> StrikerTrain:
    """Leading amplitude and decay ratio of a striker's solitary-wave train (module docstring).

    Parameters
    ----------
    mass_ratio : float
        r = M/m, striker over grain mass (>= 1; a lighter striker rebounds and its recoil
        is outside the model).
    v0 : float
        Striker velocity, m/s (> 0).
    exponent : float
        n of F = k δ^n, in (1, 10].
    """
    r = float(check_range("mass_ratio", mass_ratio, 1.0, np.inf, closed=(True, False)))
    v0 = float(check_positive("v0", v0))
    n = float(check_range("exponent", exponent, 1.0, 10.0, closed=(False, True)))
    c = sonic_vacuum_wave_constants(n)
    x = c.momentum**2 / (2.0 * c.energy * r)
    v1 = c.momentum * r / (c.energy * r + 0.5 * c.momentum**2) * v0
    return StrikerTrain(mass_ratio=r, ratio=(1.0 - x) / (1.0 + x), velocity_max=v1,
                        energy_fraction=2.0 * c.energy * v1**2 / (r * v0**2))
