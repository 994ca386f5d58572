r"""The dissipative Hertz law of Kuwabara & Kono (1987) / Brilliantov et al. (1996).

.. math::
    F = \begin{cases} \max\!\big(0,\ k\,[\delta^{3/2} + A\,\delta^{1/2}\dot\delta]
    \big) & \delta > 0 \\ 0 & \delta \le 0 \end{cases}

Kuwabara & Kono, Jpn. J. Appl. Phys. 26 (1987) 1230; derived for viscoelastic spheres
by Brilliantov, Spahn, Hertzsch & Pöschel, Phys. Rev. E 53 (1996) 5382, Eq. (18).  The
clip at 0 (no attraction while the contact unloads fast) follows Schwager & Pöschel,
Phys. Rev. E 57 (1998) 650 and Ramírez, Pöschel, Brilliantov & Schwager, Phys. Rev. E
60 (1999) 4465.  Experiments report the coefficient of restitution e of an impact
rather than A: :meth:`ViscoelasticHertz.from_restitution` solves the two-body problem
for the A that gives a measured e.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .base import ContactLaw, LawParameter, compile_piece

__all__ = ["ViscoelasticHertz"]


def _restitution(beta: float) -> float:
    r"""Coefficient of restitution e(β) of the reduced two-body impact (dimensionless).

    The relative overlap ξ (m) of two bodies of reduced mass μ meeting at speed g obeys
    :math:`\mu\ddot\xi = -\max(0, k[\xi^{3/2} + A\xi^{1/2}\dot\xi])` while ξ > 0.  In
    units of length :math:`g\tau` and time :math:`\tau = (k/\mu)^{-2/5} g^{-1/5}` this is

    .. math:: X'' = -\max\big(0,\ X^{3/2} + \beta X^{1/2} X'\big),\quad X(0) = 0,\
              X'(0) = 1,\qquad \beta = A\,(k/\mu)^{2/5} g^{1/5}

    (Schwager & Pöschel 1998, Eqs. 4-6), so e = -X'(t_end) depends on β alone.  The
    force vanishes for good once :math:`X + \beta X' = 0` (X' < 0 then stays constant
    and X + βX' keeps falling): the integration stops there (or at X = 0 for β = 0)
    and e = -X'.  scipy's DOP853 at rtol 1e-12: e to ~1e-11.
    """
    from scipy.integrate import solve_ivp

    def rhs(_t, y):
        x = max(y[0], 0.0)
        return [y[1], -max(x * math.sqrt(x) + beta * math.sqrt(x) * y[1], 0.0)]

    def released(_t, y):  # the force's bracket X + βX' (its sign), or X for β = 0
        return y[0] + beta * y[1]

    def apart(_t, y):
        return y[0]

    released.terminal = apart.terminal = True
    released.direction = apart.direction = -1
    t_end = 50.0 * (1.0 + beta)  # elastic contact time 3.22; overdamped release ~ β
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, 1.0], method="DOP853", rtol=1e-12,
                    atol=1e-14, events=(released, apart))
    hits = [ev for ev in sol.y_events if ev.size]
    if not hits:
        raise RuntimeError(f"the two-body impact with beta = {beta:g} did not end by "
                           f"t = {t_end:g} collision time units")
    return float(-hits[0][0][1])


class ViscoelasticHertz(ContactLaw):
    r"""Dissipative Hertz law of Kuwabara & Kono (1987) / Brilliantov et al. (1996).

    .. math::
        F = \begin{cases} \max\!\big(0,\ k\,[\delta^{3/2} + A\,\delta^{1/2}\dot\delta]
        \big) & \delta > 0 \\ 0 & \delta \le 0 \end{cases}

    (N; δ the overlap, m; :math:`\dot\delta` its rate, m/s; k in N/m^{3/2} as for
    :data:`theory.laws.HERTZ`; A in s).  Brilliantov, Spahn, Hertzsch & Pöschel, Phys.
    Rev. E 53 (1996) 5382, Eq. (18), with :math:`A = \tfrac13 (3\eta_2-\eta_1)^2/
    (3\eta_2+2\eta_1) \cdot (1-\nu^2)(1-2\nu)/(Y\nu^2)` for a material of Young's
    modulus Y, Poisson ratio ν and viscous constants η1, η2; γ = kA in the notation
    :math:`F = k\delta^{3/2} + \gamma\delta^{1/2}\dot\delta`.  The force is clipped at
    0 so that it never pulls (Schwager & Pöschel, Phys. Rev. E 57 (1998) 650).
    Elastic part, energies, static overlap and long-wave coefficients are Hertz's; the
    power it dissipates is :math:`(F - k\delta^{3/2})\,\dot\delta \ge 0`; its long-wave
    damping term is :math:`A\xi^{1/2}\xi_t` (:meth:`long_wave_damping_time`).

    Parameters
    ----------
    damping_time : float
        A, s (>= 0; 0 is the lossless Hertz law, computed through the dissipative path).
    """

    name = "viscoelastic_hertz"
    dissipative = True
    exponent = 1.5
    summary = "F = max(0, k (δ^{3/2} + A δ^{1/2} dδ/dt)) (Kuwabara & Kono 1987)"
    parameters = (LawParameter(
        "damping_time", 0.0, "the dissipative constant A of Brilliantov et al. (1996) "
        "Eq. 18", "s", low=0, low_open=False),)

    def __init__(self, damping_time: float) -> None:
        try:
            a = float(damping_time)
        except (TypeError, ValueError):
            raise ValueError(f"damping_time must be a real number >= 0 s "
                             f"(got {damping_time!r})") from None
        if not (math.isfinite(a) and a >= 0):
            raise ValueError(f"damping_time must be finite and >= 0 s (got {damping_time!r})")
        self.damping_time = a

    # ------------------------------------------------ from what experiments report
    @staticmethod
    def _scale(impact_speed, reduced_mass, k) -> float:
        """(k/μ)^{2/5} g^{1/5}, 1/s: β = A times this (:func:`_restitution`)."""
        for name, val in (("impact_speed", impact_speed), ("reduced_mass", reduced_mass),
                          ("k", k)):
            try:
                ok = math.isfinite(float(val)) and float(val) > 0
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise ValueError(f"{name} must be a finite number > 0 (got {val!r})")
        return (float(k) / float(reduced_mass)) ** 0.4 * float(impact_speed) ** 0.2

    @classmethod
    def from_restitution(cls, restitution: float, impact_speed: float,
                         reduced_mass: float, k: float) -> ViscoelasticHertz:
        r"""The law whose two-body impact at ``impact_speed`` has restitution coefficient e.

        Solves e(β) = ``restitution`` for β = A (k/μ)^{2/5} g^{1/5} by Brent's method
        on the reduced two-body equation (Schwager & Pöschel, Phys. Rev. E 57 (1998)
        650; Ramírez et al., Phys. Rev. E 60 (1999) 4465: e = 1 − C1 β + C2 β² ∓ … for
        small β, C1 = 1.15344, C2 = 0.79826), integrated with scipy (the clip included;
        e to ~1e-11, A to ~1e-10 relative).  e depends on the impact speed (as g^{1/5}
        through β): the law reproduces e at this speed only.

        Parameters
        ----------
        restitution : float
            e, in (0, 1]; 1 gives A = 0.  e below e(β = 1e4) ≈ 3e-7 (an overdamped
            contact, A beyond 1e4 collision times) is refused.
        impact_speed : float
            Relative normal speed g of the two bodies before the impact, m/s (> 0).
        reduced_mass : float
            μ = m1 m2/(m1 + m2), kg (> 0): m/2 for two equal grains of mass m, m for a
            grain on a rigid wall.
        k : float
            Hertz constant of the contact, N/m^{3/2} (> 0).

        Returns
        -------
        ViscoelasticHertz
        """
        from scipy.optimize import brentq

        try:
            e = float(restitution)
        except (TypeError, ValueError):
            e = float("nan")
        if not 0.0 < e <= 1.0:
            raise ValueError(f"restitution must lie in (0, 1] (got {restitution!r})")
        scale = cls._scale(impact_speed, reduced_mass, k)
        if e == 1.0:
            return cls(0.0)
        hi = 1.0
        while _restitution(hi) > e:
            hi *= 4.0
            if hi > 1e4:
                raise ValueError(f"restitution {e:g} is below that of the most damped "
                                 f"contact accepted (beta = 1e4, e = {_restitution(1e4):.3g})")
        beta = brentq(lambda b: _restitution(b) - e, 0.0 if hi == 1.0 else hi / 4.0, hi,
                      xtol=1e-14, rtol=1e-13)
        return cls(beta / scale)

    def restitution(self, impact_speed: float, reduced_mass: float, k: float) -> float:
        """Coefficient of restitution of a two-body impact with this law (dimensionless).

        The reduced two-body equation of :meth:`from_restitution`, at relative speed
        ``impact_speed`` (m/s), reduced mass ``reduced_mass`` (kg) and Hertz constant
        ``k`` (N/m^{3/2}); 1 for A = 0.
        """
        beta = self.damping_time * self._scale(impact_speed, reduced_mass, k)
        return 1.0 if beta == 0.0 else _restitution(beta)

    # ------------------------------------------------------------------- law
    def key(self) -> tuple:
        """See :meth:`ContactLaw.key`."""
        return ("viscoelastic_hertz",)

    def params(self) -> np.ndarray:
        """See :meth:`ContactLaw.params`: (A, 0)."""
        return np.array([self.damping_time, 0.0])

    def to_dict(self) -> dict[str, Any]:
        """See :meth:`ContactLaw.to_dict`."""
        return {"law": self.name, "damping_time": self.damping_time}

    def describe(self) -> str:
        """See :meth:`ContactLaw.describe`."""
        return (f"viscoelastic Hertz F = max(0, k (delta^(3/2) + A delta^(1/2) "
                f"d(delta)/dt)), A = {self.damping_time:g} s")

    def make_damping(self):
        """See :meth:`ContactLaw.make_damping`: c = k A √δ (N·s/m) for δ > 0."""
        def damping(r, k, p):
            if r <= 0.0:
                return 0.0
            return k * p[0] * np.sqrt(r)

        return compile_piece(damping)

    def damping(self, r, k):
        """See :meth:`ContactLaw.damping`: k A √[δ]_+, N·s/m."""
        return np.asarray(k, float) * self.damping_time * np.sqrt(np.maximum(r, 0.0))

    def long_wave_damping_time(self) -> float:
        r"""A, s: c(δ) = kAδ^{1/2} = kAδ^{n-1} gives the long-wave term Aξ^{1/2}ξ_t.

        With δ = dξ and :math:`\dot\delta = d\xi_t` the damping force is
        :math:`k d^{3/2} A\xi^{1/2}\xi_t`, beside the elastic :math:`k d^{3/2}\xi^{3/2}`
        (:class:`theory.laws.LongWave`; the clip at F = 0 is not part of it).
        """
        return self.damping_time
