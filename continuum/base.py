"""Common base of the second-order-in-time chain PDEs (fields ``u``, ``v`` [, ``w``]).

Each concrete PDE supplies the conservative acceleration ``u_tt`` twice: as plain NumPy
(:meth:`ChainPDEBase._acceleration_numpy`, used by :meth:`evolution_rate`) and as a
numba-compiled function (:meth:`ChainPDEBase._make_acceleration_numba`, used by
:meth:`make_evolution_rate`), in the manner of ``pde.pdes.wave.WavePDE``; its
dissipative sub-step (:meth:`ChainPDEBase.dissipate`, NumPy; compiled in the fused
stepper) when the medium has velocity-dependent forces; and its energy functional
(:meth:`ChainPDEBase.energy`).

A medium with a dissipative contact law or on-site drag (:attr:`theory.medium.Medium.dissipative`)
adds a third field ``w``: the energy (J) dissipated so far, booked per node where it
was dissipated; the energy functional plus Σ w is then the conserved quantity the
solvers monitor.

Models register themselves by name in :data:`continuum.MODELS`
(:func:`continuum.register_model`): a model class gives ``name``, ``label``,
:meth:`ChainPDEBase.for_chain`, the constructor the scenario runner calls, and its own
time step (``default_integrator``, ``default_dt_safety``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numba as nb
import numpy as np
from pde import CartesianGrid, FieldCollection, ScalarField
from pde.pdes.base import PDEBase

from ._kernels import FREE, PERIODIC, WALL
from .cells import homogenise
from .medium import BOUNDARY_CONDITIONS, Discretisation, Medium, discretise

__all__ = ["ChainPDEBase", "WINDOW_TOLERANCE"]

WINDOW_TOLERANCE = 2.0**-52
"""Relative at-rest threshold of the active window (see :mod:`continuum._stepper`)."""

_BC_CODE = {"free": FREE, "wall": WALL, "periodic": PERIODIC}


class ChainPDEBase(PDEBase):
    """Base class: a :class:`Medium` on ``n`` nodes per grain with fields (u, v[, w]).

    Periodic sections of the medium (dimers, trimers: ``medium.cells``) are replaced by
    their homogenised long-wave medium (:func:`continuum.cells.homogenise`); every other
    chain enters with its own per-grain and per-contact coefficients.

    Parameters
    ----------
    medium : Medium
        The chain (:class:`theory.medium.Medium`: masses, contact constants, static
        overlaps, law, drag, gravity).
    n : int
        Nodes per grain (odd).
    bc : {"free", "wall", "periodic"}
        Boundary condition at both ends (see :data:`continuum.medium.BOUNDARY_CONDITIONS`).
    """

    explicit_time_dependence = False

    name: ClassVar[str] = ""
    """Key of the model in :data:`continuum.MODELS`."""
    label: ClassVar[str] = ""
    """Legend text of the model (e.g. ``"Eq. 4"``)."""
    smooth_interpolation: ClassVar[str] = "spline"
    """How :func:`continuum.from_grains` takes a smooth grain state (``"smooth"``) onto
    this model's nodes: ``"spline"`` or ``"band_limited"``."""
    default_integrator: ClassVar[str]
    """The model's own splitting method (a name of :data:`theory.splitting.SPLITTINGS`):
    the step of a scenario whose ``[models] integrator`` is not given.  Each registered
    model declares it (:func:`continuum.register_model` checks it)."""
    default_dt_safety: ClassVar[float]
    """The model's own ``safety`` of :meth:`stable_dt` (``[models] dt_safety`` not given):
    ω_max Δt = 2 × safety against velocity Verlet's bound 2/ω_max, strictly below
    half its :attr:`default_integrator`'s limit (:data:`theory.splitting.STABILITY_LIMITS`;
    :func:`continuum.register_model` checks it)."""

    def __init__(self, medium: Medium, n: int = 5, *, bc: str = "free") -> None:
        super().__init__()
        if not isinstance(medium, Medium):
            raise ValueError(f"medium must be a theory.medium.Medium (got "
                             f"{type(medium).__name__}; discrete.Chain.medium() builds one)")
        if bc not in BOUNDARY_CONDITIONS:
            raise ValueError(f"bc must be one of {BOUNDARY_CONDITIONS} (got {bc!r})")
        if bc == "wall" and not np.all(medium.k[[0, -1]] > 0):
            raise ValueError("bc='wall' needs both end contacts (k[0], k[N] > 0); a free end "
                             "(k = 0) takes bc='free'")
        if medium.dissipative and bc == "periodic":
            raise ValueError("dissipative media (a dissipative law or drag) take bc='free' or "
                             "'wall' (the dissipative sub-steps are not periodic)")
        self.medium = medium
        self.effective, dispersion = homogenise(medium)
        self.law = medium.law
        self.bc = bc
        self.disc: Discretisation = discretise(self.effective, n, periodic=bc == "periodic",
                                               dispersion=dispersion)
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

    # ------------------------------------------------------------------ registry
    @classmethod
    def for_chain(cls, medium: Medium, *, nodes_per_grain: int, bc: str,
                  options: Mapping[str, Any]) -> ChainPDEBase:
        """The model for a scenario's chain (the constructor :data:`continuum.MODELS` users call).

        ``options`` holds the scenario's continuum settings (``nonlinearity``,
        ``delta_floor`` as a fraction of the incident peak overlap, ``dispersion_cap``)
        and ``incident_overlap`` (m, the incident wave's peak overlap change); a model
        reads what it needs.  ValueError if the model cannot describe ``medium``.
        """
        raise NotImplementedError  # pragma: no cover

    # ------------------------------------------------------------------ states
    @property
    def n(self) -> int:
        """Nodes per grain."""
        return self.disc.n

    @property
    def face_weight(self) -> np.ndarray:
        """Weight of each face in the energy: 1, ½ at a wall face, 0 at a free end face."""
        return self._face_weight

    @property
    def dissipative(self) -> bool:
        """Velocity-dependent forces (a dissipative law or drag): state (u, v, w)."""
        return self.medium.dissipative

    @property
    def n_fields(self) -> int:
        """Fields of the state: 2 (u, v), 3 with the dissipated energy w."""
        return 3 if self.dissipative else 2

    def get_initial_condition(self, u, v=None, w=None) -> FieldCollection:
        """Combine displacement u (m), velocity v (m/s) [and dissipated energy w, J] into a state.

        Arrays on the nodes or :class:`pde.ScalarField`; ``w`` only for a dissipative
        medium (default 0).
        """
        def field(x, label):
            if isinstance(x, ScalarField):
                return x.copy(label=label)
            data = None if x is None else np.asarray(x, float)
            return ScalarField(self.grid, data, label=label)

        fields = [field(u, "u"), field(v, "v")]
        labels = ["u", "v"]
        if self.dissipative:
            fields.append(field(w, "w"))
            labels.append("w")
        elif w is not None:
            raise ValueError("w (dissipated energy) applies only to a dissipative medium")
        return FieldCollection(fields, labels=labels)

    def _check(self, state) -> None:
        if not isinstance(state, FieldCollection) or len(state) != self.n_fields:
            names = "(u, v, w)" if self.dissipative else "(u, v)"
            raise TypeError(f"state must be a FieldCollection of the fields {names}")

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

    def acceleration(self, u: np.ndarray) -> np.ndarray:
        """Acceleration of the conservative forces at displacements ``u`` (NumPy), m/s²."""
        return self._acceleration_numpy(np.asarray(u, float))

    def damping_coefficients(self, u: np.ndarray) -> np.ndarray:
        """The law's damping coefficient c(δ0 + s) of every face, N·s/m (0: conservative)."""
        d = self.disc
        return self.law.damping(d.delta0 + self.strain(u), d.k)

    # ------------------------------------------------------------------ py-pde API
    def evolution_rate(self, state: FieldCollection, t: float = 0) -> FieldCollection:  # type: ignore[override]
        """Evaluate the right-hand side (u_t, v_t[, w_t]) with NumPy.

        v_t is the conservative acceleration plus, for a dissipative medium, that of
        the viscous flux and the drag (:meth:`_dissipative_rate`); w_t the power
        dissipated per node.
        """
        self._check(state)
        u, v = np.asarray(state[0].data), np.asarray(state[1].data)
        acc = self._acceleration_numpy(u)
        fields = [state[1].copy(), ScalarField(self.grid, acc)]
        if self.dissipative:
            a_d, power = self._dissipative_rate(u, v)
            fields[1] = ScalarField(self.grid, acc + a_d)
            fields.append(ScalarField(self.grid, power))
        return FieldCollection(fields, labels=[f.label or "" for f in state])

    def make_evolution_rate(self, state: FieldCollection, backend) -> Callable:
        """Compiled right-hand side (numba) with signature ``(state_data, t)``.

        Conservative media only (a dissipative one steps with the fused kernels or the
        NumPy backend).
        """
        self._check(state)
        if getattr(backend, "name", str(backend)) == "numpy":
            raise NotImplementedError("the numpy backend uses evolution_rate")
        if self.dissipative:
            raise NotImplementedError("a dissipative medium steps with the fused stepper "
                                      "(backend='numba') or backend='numpy'")
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

    def _dissipative_rate(self, u: np.ndarray, v: np.ndarray):  # pragma: no cover
        """(acceleration of the viscous flux and drag, dissipated power per node J/s)."""
        raise NotImplementedError

    def dissipate(self, state_data: np.ndarray, tau: float, forward: bool = True) -> None:
        """Dissipative sub-step of ``tau`` (s) at fixed positions, in place (NumPy).

        Books the removed energy into ``state_data[2]``; ``forward=False`` is the
        adjoint (reverse) composition (:mod:`continuum._stepper`, "Dissipation").
        """
        raise NotImplementedError  # pragma: no cover

    def energy_density(self, state: FieldCollection) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic energy per node and potential energy per face, J (sum = energy)."""
        raise NotImplementedError  # pragma: no cover

    def energy(self, state: FieldCollection) -> dict[str, float]:
        """Energy functional of the semi-discrete equation, J.

        Returns ``kinetic``, ``potential``, ``dissipated`` (Σ w; 0 for a conservative
        medium) and ``total`` = their sum, the conserved quantity.  The potential energy
        is the *dynamic* part (contact energy minus the static energy minus F0 × overlap
        change), the quantity the flux form conserves for any boundary condition.
        """
        ek, ep = self.energy_density(state)
        dis = float(np.sum(state[2].data)) if self.dissipative else 0.0
        return {"kinetic": float(ek.sum()), "potential": float(ep.sum()), "dissipated": dis,
                "total": float(ek.sum() + ep.sum()) + dis}

    def invariants(self, state: FieldCollection) -> tuple[float, float]:
        """(energy J, momentum kg m/s): the quantities :func:`continuum.run` monitors."""
        return self.energy(state)["total"], self.momentum(state)

    def momentum(self, state: FieldCollection) -> float:
        """Total momentum h Σ m_p v_p, kg m/s (conserved for free/periodic ends, no drag)."""
        return float(self.disc.h * np.sum(self.disc.mass * state[1].data))

    def stable_dt(self, state: FieldCollection, safety: float = 0.5) -> float:
        """A stable explicit time step for the velocity-Verlet solver, s."""
        raise NotImplementedError  # pragma: no cover

    @property
    def parameters(self) -> dict[str, Any]:
        """Run parameters (JSON-friendly) for HDF5 attributes."""
        return {"pde": type(self).__name__, "nodes_per_grain": self.n, "bc": self.bc,
                **self.medium.to_dict()}
