r"""Symplectic time stepping for the (u, v) chain PDEs, and a run helper with HDF5 output.

py-pde 0.59 offers explicit Euler, Runge–Kutta (fixed or adaptive), Adams–Bashforth,
Crank–Nicolson, implicit and scipy solvers, but no symplectic integrator.  For
Hamiltonian wave equations a symplectic one keeps the energy error bounded (no drift)
over arbitrarily long runs, so :class:`VerletSolver` adds the smallest such piece: the
position-Verlet (drift–kick–drift) step, and its fourth-order Yoshida composition
(Yoshida, Phys. Lett. A 150 (1990) 262, Eq. 5.19).  It plugs into py-pde's solver
registry (``solver="verlet"``) and works with the numpy and numba backends.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from pde import FileStorage
from pde.solvers import Controller
from pde.solvers.base import SolverBase
from pde.trackers import DataTracker

from theory import integrity

__all__ = ["VerletSolver", "run", "RunResult"]

_CBRT2 = 2.0 ** (1.0 / 3.0)
_YOSHIDA = (1.0 / (2.0 - _CBRT2), -_CBRT2 / (2.0 - _CBRT2), 1.0 / (2.0 - _CBRT2))


class VerletSolver(SolverBase):
    r"""Symplectic position-Verlet stepper for states ``(u, v)`` with ``u_t = v``.

    One step of size Δt (order 2; one evaluation of the acceleration a(u)):

    .. math:: u \mathrel{+}= \tfrac{Δt}{2} v,\quad v \mathrel{+}= Δt\,a(u),\quad
              u \mathrel{+}= \tfrac{Δt}{2} v

    ``order=4`` composes three such steps with Yoshida's weights
    (w1, w0, w1) = (1/(2-2^{1/3}), -2^{1/3}/(2-2^{1/3}), 1/(2-2^{1/3})).
    Requires that the acceleration does not depend on v (true for all chain PDEs).

    Parameters
    ----------
    pde : PDEBase
        A PDE whose state is a FieldCollection ``(u, v)`` with ``u_t = v``.
    backend : str
        py-pde backend ("numpy", "numba" or "auto").
    order : {2, 4}
        Order of accuracy in time.
    """

    name = "verlet"

    def __init__(self, pde, *, backend="auto", order: int = 2) -> None:
        super().__init__(pde, backend=backend)
        if order not in (2, 4):
            raise ValueError(f"order must be 2 or 4 (got {order})")
        self.order = order
        self.info["order"] = order

    def _make_single_step_fixed_dt(self, state, dt: float):
        """Return the compiled-or-plain function performing one step of size ``dt``."""
        rhs = self.backend.make_pde_rhs(self.pde, state)
        if self.order == 2:
            w1 = w0 = 1.0
            nsub = 1
        else:
            w1, w0, _ = _YOSHIDA
            nsub = 3

        def single_step(state_data, t):
            for i in range(nsub):
                w = w0 if i == 1 else w1
                h = w * dt
                state_data[0] += 0.5 * h * state_data[1]
                acc = rhs(state_data, t)
                state_data[1] += h * acc[1]
                state_data[0] += 0.5 * h * state_data[1]
            return state_data

        return single_step


class RunResult(dict):
    """Result of :func:`run`: ``state``, ``times``, ``energy``, ``momentum``, ``info``."""

    @property
    def energy_drift(self) -> float:
        """Max |E(t) - E(0)| / |E(0)| over the recorded times."""
        e = np.asarray(self["energy"])
        return float(np.max(np.abs(e - e[0])) / abs(e[0])) if e.size else float("nan")


def run(
    pde,
    state,
    t_end: float,
    *,
    dt: float | None = None,
    order: int = 2,
    backend: str = "numba",
    interval: float | None = None,
    storage: str | Path | None = None,
    extra_info: dict[str, Any] | None = None,
    trackers: list | None = None,
) -> RunResult:
    """Integrate a chain PDE with :class:`VerletSolver`, monitoring energy and momentum.

    Parameters
    ----------
    pde : ChainPDEBase
        The equation (carries the medium and its parameters).
    state : FieldCollection
        Initial (u, v); not modified.
    t_end : float
        Final time, s.
    dt : float, optional
        Time step, s (default ``pde.stable_dt(state)``).
    order : {2, 4}
        Order of the symplectic stepper.
    backend : str
        py-pde backend, "numba" (default) or "numpy".
    interval : float, optional
        Time between energy records and stored frames, s (default t_end/20).
    storage : path, optional
        HDF5 file (py-pde :class:`~pde.FileStorage`) receiving the frames, with the
        run's parameters (``pde.parameters``, dt, order, t_end, ``extra_info``) as
        attributes; sealed once complete (:func:`theory.integrity.seal_file`: py-pde
        reads it as before, :func:`theory.integrity.verify` finds any change).
    extra_info : dict, optional
        More attributes for the storage (e.g. the scenario).
    trackers : list, optional
        Further py-pde trackers.
    """
    dt = float(pde.stable_dt(state)) if dt is None else float(dt)
    interval = t_end / 20 if interval is None else float(interval)
    info = {**pde.parameters, "dt_s": dt, "order": order, "t_end_s": float(t_end),
            "time_unit": "s", "length_unit": "grain diameters (X = x/d)",
            "u_unit": "m", "v_unit": "m/s", **(extra_info or {})}
    monitor = DataTracker(lambda s, t: (pde.energy(s)["total"], pde.momentum(s)),
                          interrupts=interval)
    all_trackers = [monitor, *(trackers or [])]
    store = tmp = None
    if storage is not None:
        # write to a temporary name beside the target and rename when complete, so no
        # reader ever sees a half-written file (a crash leaves the old file or none)
        target = Path(storage)
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
        store = FileStorage(tmp, info=info, write_mode="truncate")
        all_trackers.append(store.tracker(interrupts=interval))
    solver = VerletSolver(pde, backend=backend, order=order)
    controller = Controller(solver, t_range=float(t_end), tracker=all_trackers)
    try:
        final = controller.run(state.copy(), dt)
        if store is not None:
            store.close()
            integrity.seal_file(tmp, target)  # sealed copy, atomically (theory.integrity)
    finally:
        if tmp is not None and tmp.exists():
            if store is not None:
                store.close()
            tmp.unlink()
    data = np.asarray(monitor.data, dtype=float).reshape(-1, 2)
    return RunResult(state=final, times=np.asarray(monitor.times), energy=data[:, 0],
                     momentum=data[:, 1], info={**info, **controller.diagnostics.get(
                         "solver", {})})
