"""Common base of the second-order-in-time chain PDEs (fields ``u`` and ``v``).

Each concrete PDE supplies the acceleration ``u_tt`` twice: as plain NumPy
(:meth:`ChainPDEBase._acceleration_numpy`, used by :meth:`evolution_rate`) and as a
numba-compiled function (:meth:`ChainPDEBase._make_acceleration_numba`, used by
:meth:`make_evolution_rate`), in the manner of ``pde.pdes.wave.WavePDE``; and its
conserved energy functional (:meth:`ChainPDEBase.energy`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numba as nb
import numpy as np
from pde import CartesianGrid, FieldCollection, ScalarField
from pde.pdes.base import PDEBase

from ._kernels import FREE, PERIODIC, WALL
from .medium import BOUNDARY_CONDITIONS, Discretisation, Medium

__all__ = ["ChainPDEBase", "WINDOW_TOLERANCE"]

WINDOW_TOLERANCE = 2.0**-52
"""Relative at-rest threshold of the active window (see :mod:`continuum._stepper`)."""

_BC_CODE = {"free": FREE, "wall": WALL, "periodic": PERIODIC}


class ChainPDEBase(PDEBase):
    """Base class: a :class:`Medium` on ``n`` nodes per grain with fields (u, v).

    Parameters
    ----------
    medium : Medium
        The chain (masses, contact stiffnesses, static overlaps, diameter).
    n : int
        Nodes per grain (odd).
    bc : {"free", "wall", "periodic"}
        Boundary condition at both ends (see :data:`continuum.medium.BOUNDARY_CONDITIONS`).
    """

    explicit_time_dependence = False

    def __init__(self, medium: Medium, n: int = 5, *, bc: str = "free") -> None:
        super().__init__()
        if bc not in BOUNDARY_CONDITIONS:
            raise ValueError(f"bc must be one of {BOUNDARY_CONDITIONS} (got {bc!r})")
        self.medium = medium
        self.bc = bc
        self.disc: Discretisation = medium.discretise(n, periodic=bc == "periodic")
        self._bc_code = _BC_CODE[bc]
        self.grid = CartesianGrid(
            [(-0.5, medium.n_grains - 0.5)], medium.n_grains * self.disc.n,
            periodic=bc == "periodic",
        )
        w = np.ones(self.disc.x_faces.size)
        if bc == "wall":
            w[0] = w[-1] = 0.5  # half interval between wall and first node
        elif bc == "free":
            w[0] = w[-1] = 0.0  # no dynamic strain at a free end
        self._face_weight = w

    # ------------------------------------------------------------------ states
    @property
    def n(self) -> int:
        """Nodes per grain."""
        return self.disc.n

    def get_initial_condition(self, u, v=None) -> FieldCollection:
        """Combine displacement u (m) and velocity v (m/s) into the solver state.

        ``u`` and ``v`` may be :class:`pde.ScalarField` or arrays on the nodes.
        """
        uf = u if isinstance(u, ScalarField) else ScalarField(self.grid, np.asarray(u, float))
        vf = ScalarField(self.grid) if v is None else (
            v if isinstance(v, ScalarField) else ScalarField(self.grid, np.asarray(v, float))
        )
        return FieldCollection([uf.copy(label="u"), vf.copy(label="v")], labels=["u", "v"])

    def _check(self, state) -> None:
        if not isinstance(state, FieldCollection) or len(state) != 2:
            raise TypeError("state must be a FieldCollection of the fields (u, v)")

    # ------------------------------------------------------------------ strains
    def strain(self, u: np.ndarray) -> np.ndarray:
        """Dynamic overlap change s = -u_X at the faces, m (NumPy; boundary ghosts)."""
        h = self.disc.h
        if self.bc == "periodic":
            return -(u - np.roll(u, 1)) / h
        s = np.empty(u.size + 1)
        s[1:-1] = -(u[1:] - u[:-1]) / h
        if self.bc == "wall":
            s[0], s[-1] = -2.0 * u[0] / h, 2.0 * u[-1] / h
        else:
            s[0] = s[-1] = 0.0
        return s

    def divergence(self, p: np.ndarray) -> np.ndarray:
        """Node force per grain length (P_q - P_{q+1})/h from face forces (NumPy), N."""
        if self.bc == "periodic":
            return (p - np.roll(p, -1)) / self.disc.h
        return (p[:-1] - p[1:]) / self.disc.h

    # ------------------------------------------------------------------ py-pde API
    def evolution_rate(self, state: FieldCollection, t: float = 0) -> FieldCollection:  # type: ignore[override]
        """Evaluate the right-hand side (u_t, v_t) = (v, u_tt) with NumPy."""
        self._check(state)
        u, v = state
        acc = self._acceleration_numpy(np.asarray(u.data))
        return FieldCollection(
            [v.copy(), ScalarField(self.grid, acc)], labels=["u", "v"]
        )

    def make_evolution_rate(self, state: FieldCollection, backend) -> Callable:
        """Compiled right-hand side (numba) with signature ``(state_data, t)``."""
        self._check(state)
        if getattr(backend, "name", str(backend)) == "numpy":
            raise NotImplementedError("the numpy backend uses evolution_rate")
        accel = self._make_acceleration_numba()

        @nb.njit
        def pde_rhs(state_data, t=0.0):
            out = np.empty_like(state_data)
            out[0] = state_data[1]
            accel(state_data[0], out[1])
            return out

        return pde_rhs

    # ------------------------------------------------------------------ fused stepper
    def _initial_window(self, u: np.ndarray, v: np.ndarray):
        """At-rest thresholds and active window of a state (:mod:`continuum._stepper`).

        ``tau_s`` and ``tau_v`` are 2^-52 of the state's largest strain (m) and
        velocity (m/s): below them a node counts as at rest.  Returns
        ``(tau_s, tau_v, window)`` with ``window`` = int64 [lo, hi] (-1: all at rest).
        """
        s = np.abs(self.strain(np.asarray(u)))
        va = np.abs(np.asarray(v))
        tau_s = WINDOW_TOLERANCE * float(s.max(initial=0.0))
        tau_v = WINDOW_TOLERANCE * float(va.max(initial=0.0))
        active = va > tau_v
        if self.bc == "periodic":
            active |= (s > tau_s) | np.roll(s > tau_s, -1)
        else:
            active |= (s[:-1] > tau_s) | (s[1:] > tau_s)
        idx = np.flatnonzero(active)
        win = np.array([idx[0], idx[-1]] if idx.size else [-1, -1], dtype=np.int64)
        return tau_s, tau_v, win

    # ------------------------------------------------------------------ to implement
    def _acceleration_numpy(self, u: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def _make_acceleration_numba(self) -> Callable:  # pragma: no cover
        raise NotImplementedError

    def energy_density(self, state: FieldCollection) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic energy per node and potential energy per face, J (sum = energy)."""
        raise NotImplementedError  # pragma: no cover

    def energy(self, state: FieldCollection) -> dict[str, float]:
        """Conserved energy functional of the semi-discrete equation, J.

        Returns ``kinetic``, ``potential`` and ``total``.  The potential energy is the
        *dynamic* part (contact energy minus the static energy minus F0 × overlap
        change), the quantity the flux form conserves for any boundary condition.
        """
        ek, ep = self.energy_density(state)
        return {"kinetic": float(ek.sum()), "potential": float(ep.sum()),
                "total": float(ek.sum() + ep.sum())}

    def invariants(self, state: FieldCollection) -> tuple[float, float]:
        """(energy J, momentum kg m/s): the quantities :func:`continuum.run` monitors."""
        return self.energy(state)["total"], self.momentum(state)

    def momentum(self, state: FieldCollection) -> float:
        """Total momentum h Σ m_p v_p, kg m/s (conserved for free/periodic ends)."""
        return float(self.disc.h * np.sum(self.disc.mass * state[1].data))

    def stable_dt(self, state: FieldCollection, safety: float = 0.5) -> float:
        """A stable explicit time step for the velocity-Verlet solver, s."""
        raise NotImplementedError  # pragma: no cover

    @property
    def parameters(self) -> dict[str, Any]:
        """Run parameters (JSON-friendly) for HDF5 attributes."""
        return {"pde": type(self).__name__, "nodes_per_grain": self.n, "bc": self.bc,
                **self.medium.to_dict()}
