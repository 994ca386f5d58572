r"""Symplectic splitting methods for the chain, one table (Dedalus style), and their NumPy step.

Every method is a symmetric composition of kicks (:math:`v \mathrel{+}= b_s h\,a(u)`)
and drifts (:math:`u \mathrel{+}= a_s h\,v`) of "BAB" form,

.. math::
    v \mathrel{+}= b_1 h\,a,\ u \mathrel{+}= a_1 h\,v,\ v \mathrel{+}= b_2 h\,a,\ \dots,\
    u \mathrel{+}= a_S h\,v,\ v \mathrel{+}= b_{S+1} h\,a ,

with S force evaluations per step (the last kick of a step and the first of the next
share one, "first same as last").  All are symplectic and time-reversible.

=================  =====  ==  ========================================================
name               order  S   reference
=================  =====  ==  ========================================================
``verlet``         2      1   velocity Verlet / Störmer; Swope et al., J. Chem. Phys.
                              76 (1982) 637, Eq. 7 (the paper's Section 2)
``yoshida4``       4      3   triple jump, H. Yoshida, Phys. Lett. A 150 (1990) 262,
                              Eq. 5.19 (w1 = 1/(2 - 2^{1/3}), w0 = 1 - 2 w1)
``blanes_moan4``   4      6   SRKN_6^b, S. Blanes & P. C. Moan, J. Comput. Appl.
                              Math. 142 (2002) 313, Table 3
=================  =====  ==  ========================================================

Which one pays is an accuracy-per-cost question (``benchmarks/fig5_full.py`` measures
it on the paper's runs); with a stated accuracy (``rtol``, ``integrator="auto"``)
:mod:`discrete.timestep` measures it for the run at hand and takes the method with the
fewest force evaluations per unit time.  The Hertz force :math:`k[r]_+^{3/2}` is only C¹ at r = 0
(a gap opening or closing), where the 4th-order methods lose their order; with
precompression and no gaps the force is smooth and they keep it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .reference import accelerations

__all__ = ["Integrator", "INTEGRATORS", "get_integrator", "step", "run"]


@dataclass(frozen=True)
class Integrator:
    """A BAB splitting method: drift coefficients a (S,) and kick coefficients b (S+1,)."""

    name: str
    order: int
    drift: tuple[float, ...]
    kick: tuple[float, ...]
    reference: str

    @property
    def stages(self) -> int:
        """Force evaluations per step S."""
        return len(self.drift)

    def coefficients(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """(a_s·dt, b_s·dt) for the kernels, s."""
        return (np.array(self.drift, dtype=float) * dt, np.array(self.kick, dtype=float) * dt)


def _yoshida4() -> Integrator:
    w1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
    w0 = 1.0 - 2.0 * w1
    return Integrator("yoshida4", 4, (w1, w0, w1),
                      (0.5 * w1, 0.5 * (w0 + w1), 0.5 * (w0 + w1), 0.5 * w1),
                      "H. Yoshida, Phys. Lett. A 150 (1990) 262, Eq. 5.19")


def _blanes_moan4() -> Integrator:
    b1, b2, b3 = 0.0829844064174052, 0.396309801498368, -0.0390563049223486
    a1, a2 = 0.245298957184271, 0.604872665711080
    a3 = 0.5 - (a1 + a2)
    b4 = 1.0 - 2.0 * (b1 + b2 + b3)
    return Integrator("blanes_moan4", 4, (a1, a2, a3, a3, a2, a1),
                      (b1, b2, b3, b4, b3, b2, b1),
                      "S. Blanes & P. C. Moan, J. Comput. Appl. Math. 142 (2002) 313, "
                      "Table 3 (SRKN_6^b)")


INTEGRATORS: dict[str, Integrator] = {
    "verlet": Integrator("verlet", 2, (1.0,), (0.5, 0.5),
                         "W. C. Swope et al., J. Chem. Phys. 76 (1982) 637, Eq. 7"),
    "yoshida4": _yoshida4(),
    "blanes_moan4": _blanes_moan4(),
}
"""The registered methods by name."""


def get_integrator(name: str | Integrator) -> Integrator:
    """The method called ``name`` (ValueError listing the choices otherwise)."""
    if isinstance(name, Integrator):
        return name
    try:
        return INTEGRATORS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown integrator {name!r}; choose one of "
                         f"{sorted(INTEGRATORS)}") from None


def step(u, v, a, dt, mass, k, delta0, wall_left=0.0, wall_right=0.0,
         integrator: str | Integrator = "verlet", *, law=None):
    """One step of ``integrator`` in plain NumPy (reference for the tests); new (u, v, a).

    ``law``: a conservative contact law (:mod:`discrete.laws`; default Hertz).
    """
    m = get_integrator(integrator)
    args = (mass, k, delta0, wall_left, wall_right)
    v = v + m.kick[0] * dt * a
    for s in range(m.stages):
        u = u + m.drift[s] * dt * v
        a = accelerations(u, *args, law=law)
        v = v + m.kick[s + 1] * dt * a
    return u, v, a


def run(chain, u, v, dt, nsteps, wall_left=0.0, wall_right=0.0,
        integrator: str | Integrator = "verlet", *, law=None):
    """Integrate ``nsteps`` steps of ``dt`` (s) from (u, v) in NumPy; returns (u, v)."""
    args = (chain.mass, chain.k, chain.delta0, wall_left, wall_right)
    u = np.array(u, dtype=float)
    v = np.array(v, dtype=float)
    a = accelerations(u, *args, law=law)
    for _ in range(int(nsteps)):
        u, v, a = step(u, v, a, dt, *args, integrator=integrator, law=law)
    return u, v
