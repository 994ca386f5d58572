r"""Unidirectional (KdV) reduction of the corrected Eq. 4, with its exact sech² soliton.

For right-going waves of :math:`u_{tt} = c^2(u_{XX} + \tfrac1{12}u_{XXXX}
- \tfrac{1}{2\delta_0}u_X u_{XX})` (grain units, docs/physics.md §2) the overlap change
s = -u_X (m) obeys, to the same order,

.. math:: s_t + c\,s_X + \frac{c}{24}\,s_{XXX} + \frac{c}{4\delta_0}\,s\,s_X = 0,

whose soliton :math:`s = A\,\mathrm{sech}^2((X - X_0 - Vt)/\Lambda)` has
:math:`V = c\,(1 + A/(12\delta_0))` — exactly the paper's Eq. 5 with
:math:`\xi_{max} = A/d` — and :math:`\Lambda = \sqrt{2\delta_0/A}` grain diameters.
For any contact law the nonlinear coefficient c/(4δ0) is c b/K (K = F'(δ0),
b = F''(δ0)/2: ``quadratic`` = b/K, 1/m), the soliton's speed c(1 + (b/K)A/3) and
width 1/√(2(b/K)A) (docs/physics.md, "Long waves on any chain").
KdV is well-posed, so no regularisation is needed; it serves as the reference for the
solitary-wave speed and as a cheap model of a single wave in a uniform section.

Discretisation: py-pde's own central operators ``d_dx`` and ``d2_dx2`` on a periodic
:class:`~pde.CartesianGrid` (s_XXX = d_dx(d2_dx2 s)); the nonlinear term in the
skew-symmetric form (s s_X + (s²)_X)/3, which conserves ∫s dX and ∫s² dX exactly in
space.  Time stepping with py-pde's Runge–Kutta solver (fixed step, :meth:`stable_dt`).
An optional co-moving frame (``frame_speed``) removes most of the advection.
"""

from __future__ import annotations

from collections.abc import Callable

import numba as nb
import numpy as np
from pde import CartesianGrid, ScalarField
from pde.pdes.base import PDEBase

from . import _stepper

__all__ = ["KdVPDE"]


class KdVPDE(PDEBase):
    r"""KdV reduction of Eq. 4 for the overlap change s (m), X in grains.

    .. math:: \partial_t s = -(c - c_f)\,\partial_X s - \frac{c}{24}\,\partial_X^3 s
              - \frac{c\,b}{3K}\big(s\,\partial_X s + \partial_X s^2\big)

    (Hertz, paper Eq. 4: b/K = 1/(4δ0), the last coefficient c/(12δ0)).

    Parameters
    ----------
    speed : float
        Sound speed c = √(K/m), grains per second (paper Eq. 4: c0/d).
    quadratic : float
        b/K = F''(δ0)/(2F'(δ0)) of the contact law at the static overlap, 1/m (> 0;
        :func:`continuum.boussinesq.law_curvature`): 1/(4δ0) for Hertz.
    frame_speed : float
        Speed c_f of the co-moving frame, grains/s (0: laboratory frame).
    """

    explicit_time_dependence = False

    def __init__(self, speed: float, quadratic: float, *, frame_speed: float = 0.0) -> None:
        super().__init__()
        if not (speed > 0 and quadratic > 0):
            raise ValueError(f"speed (grains/s) and quadratic (b/K, 1/m) must be > 0 "
                             f"(got {speed}, {quadratic})")
        self.speed = float(speed)
        self.quadratic = float(quadratic)
        self.frame_speed = float(frame_speed)
        self._nl = self.speed * self.quadratic / 3.0  # of the skew form (s s_X + (s²)_X)
        self.bc = "periodic"

    @classmethod
    def for_medium(cls, medium, grain: int = 0, **kwargs) -> KdVPDE:
        """KdV equation of the section around ``grain`` of a :class:`~continuum.Medium`.

        c = √(K/m) and b/K = F''(δ0)/(2K) with the law's stiffness K = F'(δ0) at the
        grain's right contact (paper Eq. 4: K = (3/2) k δ0^{1/2}, b/K = 1/(4δ0) for Hertz).
        """
        from .boussinesq import law_curvature

        m, k, d0 = medium.mass[grain], medium.k[grain + 1], medium.delta0[grain + 1]
        law = medium.law
        k_lin = float(law.stiffness(d0, k))
        quadratic = float(0.5 * law_curvature(law, d0, k)) / k_lin
        return cls(np.sqrt(k_lin / m), quadratic, **kwargs)

    @staticmethod
    def grid(n_grains: int, n: int = 5) -> CartesianGrid:
        """Periodic grid over ``n_grains`` grain diameters with ``n`` points per grain."""
        return CartesianGrid([(-0.5, n_grains - 0.5)], n_grains * n, periodic=True)

    # ------------------------------------------------------------------ soliton
    def soliton_speed(self, amplitude: float) -> float:
        """V = c (1 + (b/K) A/3), grains/s in the laboratory frame (Hertz: paper Eq. 5)."""
        return self.speed * (1.0 + self.quadratic * amplitude / 3.0)

    def soliton_width(self, amplitude: float) -> float:
        """Λ = 1/√(2 (b/K) A) (Hertz: √(2 δ0/A)), grains."""
        return float(np.sqrt(0.5 / (self.quadratic * amplitude)))

    def soliton(self, grid: CartesianGrid, amplitude: float, center: float,
                t: float = 0.0) -> ScalarField:
        """Exact soliton s = A sech²((X - X0 - (V - c_f) t)/Λ) on a periodic grid, m.

        The periodic image nearest to the domain is used, so ``t`` may be large.
        """
        x = grid.axes_coords[0]
        length = grid.cuboid.size[0]
        xc = center + (self.soliton_speed(amplitude) - self.frame_speed) * t
        y = (x - xc + 0.5 * length) % length - 0.5 * length
        lam = self.soliton_width(amplitude)
        return ScalarField(grid, amplitude / np.cosh(y / lam) ** 2, label="s")

    # ------------------------------------------------------------------ py-pde API
    def evolution_rate(self, state: ScalarField, t: float = 0) -> ScalarField:  # type: ignore[override]
        """Right-hand side with py-pde's NumPy operators."""
        c, cf, nl = self.speed, self.frame_speed, self._nl
        s_x = state.apply_operator("d_dx", bc="periodic")
        s_xxx = state.apply_operator("d2_dx2", bc="periodic").apply_operator(
            "d_dx", bc="periodic")
        s2_x = (state * state).apply_operator("d_dx", bc="periodic")
        return -(c - cf) * s_x - (c / 24.0) * s_xxx - nl * (state * s_x + s2_x)

    def make_evolution_rate(self, state: ScalarField, backend) -> Callable:
        """Compiled right-hand side from the grid's compiled operators."""
        if getattr(backend, "name", str(backend)) == "numpy":
            raise NotImplementedError("the numpy backend uses evolution_rate")
        c, cf, nl = self.speed, self.frame_speed, self._nl
        grid = state.grid
        d_dx = grid.make_operator("d_dx", bc="periodic", backend=backend)
        d2 = grid.make_operator("d2_dx2", bc="periodic", backend=backend)
        a1, a3 = c - cf, c / 24.0

        @nb.njit
        def pde_rhs(s, t=0.0):
            s_x = d_dx(s)
            s_xxx = d_dx(d2(s))
            s2_x = d_dx(s * s)
            return -a1 * s_x - a3 * s_xxx - nl * (s * s_x + s2_x)

        return pde_rhs

    def stable_dt(self, state: ScalarField, safety: float = 0.5) -> float:
        """RK4 time step from the largest eigenvalue on the imaginary axis, s.

        |λ| ≤ (|c - c_f| + 2 c (b/K) |s|max)/h + (c/24)(4/h³) max_θ sinθ sin²(θ/2)
        for the central operators, max_θ = 3√3/8; RK4 is stable for |λ| Δt ≤ 2√2.
        """
        h = state.grid.discretization[0]
        smax = float(np.max(np.abs(state.data)))
        nonlinear = 2.0 * self.speed * smax * self.quadratic  # c |s| (b/K)·2: c|s|/(2δ0) Hertz
        lam = ((abs(self.speed - self.frame_speed) + nonlinear) / h
               + self.speed / 24.0 * 4.0 * (3.0 * np.sqrt(3.0) / 8.0) / h**3)
        return float(safety * 2.0 * np.sqrt(2.0) / lam)

    # ------------------------------------------------------------------ fused stepper
    def check_state(self, state) -> None:
        """Raise unless ``state`` is a ScalarField on a periodic 1-d Cartesian grid."""
        grid = getattr(state, "grid", None)
        if (not isinstance(state, ScalarField) or not isinstance(grid, CartesianGrid)
                or grid.num_axes != 1 or not grid.periodic[0]):
            raise TypeError("state must be a ScalarField s on a periodic 1-d CartesianGrid "
                            "(KdVPDE.grid)")

    def _coefficients(self) -> tuple[float, float, float]:
        return self.speed - self.frame_speed, self.speed / 24.0, self._nl

    def make_chunk_stepper(self, state: ScalarField, dt: float) -> Callable:
        """Compiled chunk stepper: ``chunk(data, nsteps)`` does ``nsteps`` RK4 steps.

        :func:`continuum._stepper.kdv_chunk`, the same central differences as
        :meth:`evolution_rate`; returns the node-updates (points × stages).
        """
        self.check_state(state)
        h = float(state.grid.discretization[0])
        a1, a3, nl = self._coefficients()
        size = state.data.size
        acc, sa, sb = np.zeros(size), np.zeros(size), np.zeros(size)
        dt = float(dt)

        def chunk(data: np.ndarray, nsteps: int) -> int:
            return _stepper.kdv_chunk(data, acc, sa, sb, int(nsteps), dt, a1, a3, nl, h)

        self._h = h
        return chunk

    def make_monitor(self) -> Callable:
        """Compiled ``monitor(data) -> (∫s² dX, ∫s dX)`` on the grid of the last chunk."""
        h = self._h

        def monitor(data: np.ndarray) -> tuple[float, float]:
            return _stepper.kdv_monitor(data, h)

        return monitor

    def invariants(self, state: ScalarField) -> tuple[float, float]:
        """(∫s² dX, ∫s dX): m² grains and m grains, conserved by the scheme in space."""
        e = self.energy(state)
        return e["l2"], e["mass"]

    @property
    def parameters(self) -> dict:
        """Run parameters for HDF5 attributes."""
        return {"pde": type(self).__name__, "speed_grains_per_s": self.speed,
                "quadratic_1_per_m": self.quadratic, "frame_speed_grains_per_s": self.frame_speed,
                "bc": "periodic"}

    def energy(self, state: ScalarField) -> dict[str, float]:
        """Conserved quantities ∫s dX (m) and ∫s² dX (m²) (the KdV mass and momentum)."""
        return {"mass": float(state.integral), "l2": float((state * state).integral)}
