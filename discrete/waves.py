r"""Solitary waves and dissipation: what a contact law does to the exact discrete wave.

Damped solitary wave (first-order estimate)
-------------------------------------------
A weakly dissipative law (:class:`~discrete.laws.ViscoelasticHertz` with a small A)
changes the shape of a solitary wave only at O(A); to first order the wave stays the
*lossless* exact wave (:func:`theory.discrete_solitary_wave`) with a slowly decreasing
amplitude, and its energy falls at the rate the law dissipates in that wave:

.. math::
    \frac{dE}{dt} = -P, \qquad
    P = \Big\langle \sum_j \big(F(r_j, \dot r_j) - F_{el}(r_j)\big)\,\dot r_j \Big\rangle

(W; the average is over the wave's position relative to the lattice, r_j and
:math:`\dot r_j = v_{j-1} - v_j` taken from the exact wave).  In a sonic vacuum (δ0 = 0)
with F = k r^n the exact wave is self-similar: r = λρ, v ∝ λ^{(n+1)/2}, so
:math:`E = c\,v_{\max}^2` with c from the wave itself (:meth:`DiscreteSolitaryWave.energy
<theory.DiscreteSolitaryWave.energy>`).  Measuring the distance in grains j travelled,
dt = dj/s with s the grain rate of the wave, gives the amplitude equation

.. math::
    \frac{dv_{\max}}{dj} = -\frac{P(v_{\max})}{2 c\, s(v_{\max})\, v_{\max}}

which :func:`damped_wave_decay` integrates (P evaluated on the exact wave at every
amplitude, so the clip of the law at F = 0 is included).  For the viscoelastic Hertz law
without the clip, :math:`\dot r = -s\lambda\rho'` and :math:`s^2 = (k/m)\lambda^{1/2}`
give :math:`P = (k^2 A/m)\,\lambda^3 \int \rho^{1/2}\rho'^2\,dz`, hence
:math:`\lambda^{-1/4}` grows linearly with j and :math:`v_{\max}(j) = v_0 (1 +
j/j_*)^{-5}`; the numerical integration needs no such assumption.  Checked against the
chain in ``tests/discrete/test_physics_laws.py``.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from theory import DiscreteSolitaryWave, discrete_solitary_wave

from .laws import ContactLaw, as_law
from .reference import overlap_rates

__all__ = ["wave_dissipation", "damped_wave_decay"]


def wave_dissipation(wave: DiscreteSolitaryWave, law: ContactLaw, *, phases: int = 16
                     ) -> float:
    """Power P (W) that ``law`` dissipates in the exact lossless ``wave`` (module docstring).

    Averaged over ``phases`` positions of the peak between two contacts.
    """
    law = as_law(law)
    n_dom = wave.z.size // wave.points_per_grain
    total = 0.0
    for ph in np.arange(int(phases)) / int(phases):
        st = wave.sample(n_dom, n_dom // 2 + ph)
        r = st.overlap
        rd = overlap_rates(st.velocity)
        f = law.force(r, rd, wave.k_n)
        total += float(np.sum((f - law.elastic(r, wave.k_n)) * rd))
    return total / int(phases)


def damped_wave_decay(k: float, mass: float, d: float, law: ContactLaw, velocity_max: float,
                      grains, *, phases: int = 8) -> np.ndarray:
    """First-order estimate of a damped solitary wave's peak velocity after ``grains``, m/s.

    The exact lossless wave of peak grain velocity ``velocity_max`` (m/s) in a sonic
    vacuum (δ0 = 0) of grains of ``mass`` (kg) and diameter ``d`` (m) with contacts of
    constant ``k``, travelling through ``law`` (module docstring).

    Parameters
    ----------
    k, mass, d : float
        Contact constant (N/m^n), grain mass (kg), diameter (m).
    law : ContactLaw
        The (weakly) dissipative law; its elastic part sets the exact wave.
    velocity_max : float
        Peak grain velocity at grain 0, m/s.
    grains : array
        Distances travelled, grains (>= 0).

    Returns
    -------
    ndarray
        Peak grain velocities at ``grains``, m/s.
    """
    law = as_law(law)
    n = law.exponent

    def wave(v):
        return discrete_solitary_wave(k, mass, d, velocity_max=float(v), exponent=n)

    w0 = wave(velocity_max)
    c = w0.energy() / velocity_max**2  # E = c v_max², exactly (self-similar wave)

    def rhs(_j, y):
        w = wave(y[0])
        return [-wave_dissipation(w, law, phases=phases) / (2.0 * c * w.grain_rate * y[0])]

    grains = np.asarray(grains, dtype=float)
    if np.any(grains < 0):
        raise ValueError("grains must be >= 0")
    sol = solve_ivp(rhs, (0.0, float(np.max(grains, initial=0.0))), [float(velocity_max)],
                    dense_output=True, rtol=1e-9, atol=1e-14 * velocity_max)
    return sol.sol(grains)[0]
