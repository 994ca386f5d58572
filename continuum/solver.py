r"""Symplectic time stepping for the (u, v) chain PDEs, and a run helper with HDF5 output.

py-pde 0.59 offers explicit Euler, Runge–Kutta (fixed or adaptive), Adams–Bashforth,
Crank–Nicolson, implicit and scipy solvers, but no symplectic integrator.  For
Hamiltonian wave equations a symplectic one keeps the energy error bounded (no drift)
over arbitrarily long runs, so :class:`VerletSolver` adds the smallest such piece: the
position-Verlet (drift–kick–drift) step, and every other method of the one table of
splitting methods, :mod:`theory.splitting` (``method=``: e.g. Yoshida's fourth-order
composition, Phys. Lett. A 150 (1990) 262, Eq. 5.19, or Blanes & Moan's SRKN_6^b, J.
Comput. Appl. Math. 142 (2002) 313).  It plugs into py-pde's solver registry
(``solver="verlet"``) and works with the numpy and numba backends.

Kernel passes
-------------
The kernels step a sequence of P *passes* "drift α_j Δt, then kick β_j Δt" and a
closing drift α_P Δt (:func:`splitting_coefficients`).  A drift-first method is that
form as it stands (P = S); a kick-first one becomes α = (0, a_1, …, a_S, 0),
β = (b_1, …, b_{S+1}) (P = S + 1), and because its α_0 = α_P = 0 the kernels merge the
last kick of a step with the first of the next (one force evaluation for both, "first
same as last"): n steps in one chunk cost n S + 1 evaluations.

Compiled stepping
-----------------
With the numba backend the solver does what py-pde's own numba backend does for its
solvers (``pde.backends.numba._solvers``: a compiled loop over ``steps`` single steps
per call of the stepper, between tracker interrupts), but with one compiled loop per
*chunk* that fuses the whole step: the PDE's ``make_chunk_stepper`` returns it
(:mod:`continuum._stepper`: drift, flux-form right-hand side, tridiagonal solve and
kick in two sweeps per force evaluation, an active window, no allocation).  The PDE's
:meth:`evolution_rate` (NumPy, ``backend="numpy"``) stays the reference, and
``fused=False`` keeps py-pde's generic path (compiled ``make_evolution_rate`` called
once per step) for comparison.

Monitoring
----------
After every chunk (at most ``check_steps`` steps) the solver evaluates the equation's
conserved energy functional and momentum (compiled with the fused stepper) and raises
:class:`InstabilityError` on a non-finite state or a relative energy drift beyond
``drift_tolerance``, naming the cause and the stable step.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
from pde import FileStorage
from pde.solvers import Controller
from pde.solvers.base import SolverBase
from pde.trackers.base import TrackerBase

from theory import integrity
from theory.splitting import ORDER_METHODS, SPLITTINGS, Splitting, get_splitting

__all__ = ["VerletSolver", "RK4Solver", "run", "RunResult", "InstabilityError",
           "DRIFT_TOLERANCE", "MAX_STEPS", "ORDER_METHODS", "splitting_method",
           "splitting_coefficients"]


DRIFT_TOLERANCE = 1e-2
"""Default bound on the relative drift of the conserved energy, |E - E0|/|E0|."""

MAX_STEPS = 10**10
"""Largest number of time steps :func:`run` accepts (t_end/dt above it is an input error)."""


class InstabilityError(RuntimeError):
    """The integration went unstable (NaN/inf state or energy drift beyond the tolerance)."""


def splitting_method(method: str | Splitting | None = None,
                     order: int | None = None) -> Splitting:
    """The splitting method of :mod:`theory.splitting` named ``method``, or of ``order``.

    ``order`` (2 or 4) names the drift-first methods of :data:`ORDER_METHODS`; with both
    given, ``order`` must be the method's order.  Neither: position Verlet.
    """
    if method is None:
        order = 2 if order is None else order
        if order not in ORDER_METHODS:
            raise ValueError(f"order must be 2 or 4 (got {order!r})")
        return get_splitting(ORDER_METHODS[order])
    try:  # (the message starts with the parameter's name, as every error of run's)
        m = get_splitting(method)
    except ValueError:
        raise ValueError(f"method must be one of {sorted(SPLITTINGS)} (got {method!r})"
                         ) from None
    if order is not None and order != m.order:
        raise ValueError(f"order must be None or {m.order}, the order of method "
                         f"{m.name!r} (got {order!r})")
    return m


def splitting_coefficients(method: str | Splitting | int) -> tuple[np.ndarray, np.ndarray]:
    """Drift (α, P+1 entries) and kick (β, P entries) pass coefficients of one step.

    ``method``: a name or :class:`~theory.splitting.Splitting`, or an order (2: position
    Verlet α = (1/2, 1/2), β = (1,); 4: Yoshida-4 drift first).  A kick-first method
    gets α_0 = α_P = 0 (module docstring, "Kernel passes").
    """
    if isinstance(method, (int, np.integer)) and not isinstance(method, bool):
        m = splitting_method(order=int(method))
    else:
        m = splitting_method(method)
    if m.kick_first:
        return np.array((0.0, *m.drift, 0.0)), np.array(m.kick, dtype=float)
    return np.array(m.drift, dtype=float), np.array(m.kick, dtype=float)


def _check_positive(name: str, value, unit: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number > 0 {unit} (got {value!r})") from None
    if not (math.isfinite(x) and x > 0):
        raise ValueError(f"{name} must be a finite number > 0 {unit} (got {value!r})")
    return x


class _CheckedSolver(SolverBase):
    """py-pde solver with fused compiled chunks, energy monitoring and instability errors.

    Subclasses give the fused chunk (``_make_fused``) and py-pde's generic single step
    (``_make_single_step_fixed_dt``).  Not registered with py-pde (no ``name``).
    """

    def __init__(self, pde, *, backend="auto", fused: bool = True,
                 drift_tolerance: float = DRIFT_TOLERANCE, check_steps: int = 1024) -> None:
        super().__init__(pde, backend=backend)
        self.fused = bool(fused)
        self.drift_tolerance = _check_positive("drift_tolerance", drift_tolerance, "")
        if int(check_steps) != check_steps or check_steps < 1:
            raise ValueError(f"check_steps must be an integer >= 1 (got {check_steps!r})")
        self.check_steps = int(check_steps)
        self.monitor: dict[str, list[float]] = {"t": [], "energy": [], "momentum": []}
        # force evaluations of the generic path beyond _evaluations_per_step per step (a
        # kick-first step's first kick where the cached acceleration does not apply)
        self._extra_evaluations = 0

    def _make_fused(self, state, dt: float):  # pragma: no cover - abstract
        raise NotImplementedError

    def _evaluations_per_step(self) -> int:  # pragma: no cover - abstract
        raise NotImplementedError

    def make_stepper(self, state, dt: float | None = None):
        """Stepping function ``stepper(state, t_start, t_end) -> t`` with monitoring.

        Fused compiled chunks with the numba backend (unless ``fused=False``), py-pde's
        generic stepping otherwise; the conserved quantities are checked after every
        ``check_steps`` steps.
        """
        if dt is None:
            dt = self.pde.stable_dt(state)
        dt = _check_positive("dt", dt, "s")
        self.info["dt"] = dt
        self.info["steps"] = 0
        self.info["dt_adaptive"] = False
        self.info["stochastic"] = False
        self.info["node_updates"] = 0
        self._extra_evaluations = 0
        self._select_backend(state)
        fused = (self.fused and self.backend.name == "numba"
                 and hasattr(self.pde, "make_chunk_stepper"))
        self.info["fused"] = fused
        if fused:
            chunk = self._make_fused(state, dt)
            compiled_monitor = self.pde.make_monitor()

            def advance(st, t0, nsteps):
                self.info["node_updates"] += int(chunk(st.data, nsteps))

            def monitor(st):
                return compiled_monitor(st.data)

            self._chunk = chunk
        else:
            inner = self.backend.make_stepper(self, state)
            evals = self._evaluations_per_step()

            def advance(st, t0, nsteps):
                steps_before = self.info["steps"]
                extra_before = self._extra_evaluations
                inner(st, t0, t0 + nsteps * dt)
                self.info["steps"] = steps_before  # py-pde's loop counts too: count once
                # the evaluations performed, as the fused kernels count theirs: S per
                # step, and a kick-first method's first kick where the cached
                # acceleration does not apply (first step of the run, after a replay):
                # n S + 1 for a run of n steps
                evaluations = nsteps * evals + self._extra_evaluations - extra_before
                self.info["node_updates"] += evaluations * st.data.shape[-1]

            def monitor(st):
                return self.pde.invariants(st)

        with np.errstate(all="ignore"):
            e0, p0 = monitor(state)
        if not (math.isfinite(e0) and math.isfinite(p0)):
            raise ValueError("the initial state must be finite (its conserved quantities "
                             f"are {e0!r}, {p0!r})")
        initial = {"state": state.copy(), "recorded": False}
        last = {"state": state.copy(), "t": None}  # last state that passed the checks
        tol = self.drift_tolerance
        check = self.check_steps

        def bad(e: float, p: float) -> str:
            if not (math.isfinite(e) and math.isfinite(p)):
                return "non-finite state (NaN/inf)"
            drift = abs(e - e0) / abs(e0) if e0 != 0 else 0.0
            if drift > tol:
                return (f"relative drift {drift:.3g} of the conserved energy beyond the "
                        f"tolerance {tol:g}")
            return ""

        def stepper(st, t_start: float, t_end: float) -> float:
            if not initial["recorded"]:
                self._record(t_start, e0, p0)
                initial["recorded"] = True
                last["t"] = t_start
            steps = max(1, round((t_end - t_start) / dt))
            done = 0
            e = p = float("nan")
            with np.errstate(all="ignore"):  # a NaN is ours to report, not numpy's
                while done < steps:
                    n = min(check, steps - done)
                    advance(st, t_start + done * dt, n)
                    done += n
                    self.info["steps"] += n
                    e, p = monitor(st)
                    t_now = t_start + done * dt
                    cause = bad(e, p)
                    if cause:
                        # replay from the last checked state step by step, to report the
                        # state just before the failure
                        t_bad = self._replay(st, last, advance, monitor, bad)
                        raise self._instability(cause, t_bad, initial["state"], last)
                    last["state"].data[...] = st.data
                    last["t"] = t_now
            self._record(t_start + steps * dt, e, p)
            return t_start + steps * dt

        return stepper

    def _replay(self, st, last: dict, advance, monitor, bad) -> float:
        """Redo the steps from ``last`` one by one until the check fails; return that time.

        Leaves in ``last`` the last state that passed (for the error message).
        """
        window = getattr(getattr(self, "_chunk", None), "window", None)
        if window is not None:  # integrate the whole chain: the window may be garbage
            window[:] = [0, st.data.shape[-1] - 1]
        st.data[...] = last["state"].data
        t = last["t"]
        dt = self.info["dt"]
        for _ in range(self.check_steps):
            advance(st, t, 1)
            t += dt
            if bad(*monitor(st)):
                return t
            last["state"].data[...] = st.data
            last["t"] = t
        return t  # pragma: no cover - the failure did not reproduce

    def _record(self, t: float, e: float, p: float) -> None:
        self.monitor["t"].append(float(t))
        self.monitor["energy"].append(float(e))
        self.monitor["momentum"].append(float(p))

    def _instability(self, cause: str, t: float, state0, last: dict) -> InstabilityError:
        """The error for ``cause`` at time ``t``: dt, the stable steps, the PDE's hint."""
        dt = self.info["dt"]
        parts = []
        with np.errstate(all="ignore"):
            for label, st in (("the initial state", state0),
                              (f"the last checked state (t = {last['t']:.6g} s)",
                               last["state"])):
                try:
                    stable = float(self.pde.stable_dt(st))
                except Exception:  # pragma: no cover - a PDE without a usable estimate
                    continue
                if math.isfinite(stable) and stable > 0:
                    parts.append(f"{stable:.4g} s for {label}")
            hint = getattr(self.pde, "instability_hint", None)
            more = hint(last["state"]) if hint is not None else ""
        stable_txt = ("; stable step (pde.stable_dt) " + ", ".join(parts)) if parts else ""
        return InstabilityError(
            f"{type(self.pde).__name__}: {cause} at t = {t:.6g} s with dt = {dt:.4g} s"
            f"{stable_txt}. Likely cause: "
            f"{more or 'dt too large for the stiffness of the state: lower dt'}")


class VerletSolver(_CheckedSolver):
    r"""Symplectic splitting stepper for states ``(u, v)`` with ``u_t = v``.

    Default: position Verlet, one step of size Δt (order 2; one evaluation of the
    acceleration a(u)):

    .. math:: u \mathrel{+}= \tfrac{Δt}{2} v,\quad v \mathrel{+}= Δt\,a(u),\quad
              u \mathrel{+}= \tfrac{Δt}{2} v

    ``order=4`` composes three such steps with Yoshida's weights
    (w1, w0, w1) = (1/(2-2^{1/3}), -2^{1/3}/(2-2^{1/3}), 1/(2-2^{1/3})); ``method``
    takes any method of :mod:`theory.splitting` (kick-first ones with the FSAL merge:
    module docstring, "Kernel passes").  Requires that the acceleration does not depend
    on v (the conservative forces of the chain PDEs; a dissipative medium's
    velocity-dependent forces are split off by Strang splitting, the PDE's
    ``dissipate`` sub-step).

    Parameters
    ----------
    pde : ChainPDEBase
        A PDE whose state is a FieldCollection ``(u, v)`` with ``u_t = v``.
    backend : str
        py-pde backend ("numpy", "numba" or "auto").
    order : {2, 4}, optional
        Order of accuracy in time: the drift-first method of
        :data:`ORDER_METHODS` (default 2, unless ``method`` is given).
    method : str or Splitting, optional
        A method of :data:`theory.splitting.SPLITTINGS` (e.g. ``"blanes_moan4"``).
    fused : bool
        With the numba backend, use the PDE's fused compiled chunk stepper (default);
        ``False``: py-pde's generic compiled loop over single steps.
    drift_tolerance : float
        Largest relative drift of the energy functional before
        :class:`InstabilityError` (default :data:`DRIFT_TOLERANCE`).
    check_steps : int
        Steps between two stability checks within a stepper call.
    """

    name = "verlet"

    def __init__(self, pde, *, backend="auto", order: int | None = None,
                 method: str | Splitting | None = None, **kwargs) -> None:
        super().__init__(pde, backend=backend, **kwargs)
        self.method = splitting_method(method, order)
        self.alpha, self.beta = splitting_coefficients(self.method)
        self.order = self.method.order
        self.info["order"] = self.order
        self.info["method"] = self.method.name

    def _evaluations_per_step(self) -> int:
        return self.method.stages

    def _make_fused(self, state, dt: float):
        return self.pde.make_chunk_stepper(state, dt, self.alpha, self.beta)

    def _make_single_step_fixed_dt(self, state, dt: float):
        """Return the compiled-or-plain function performing one step of size ``dt``.

        A kick-first method reuses the acceleration of the previous step's last
        evaluation for its first kick when u is (bitwise) the u it was evaluated at
        (FSAL: S evaluations per step; one more, counted in ``_extra_evaluations``,
        where it does not: the run's first step and a replay's); the two kicks are
        applied one after the other (the fused kernels add their coefficients: equal to
        round-off).
        """
        if getattr(self.pde, "dissipative", False):
            return self._dissipative_step(dt)
        if self.method.kick_first and self.backend.name == "numba":
            # py-pde compiles the single step; the kick-first one caches the last
            # acceleration in a Python dict, which numba cannot type (a TypingError)
            raise ValueError(f"fused=False with backend 'numba' steps drift-first "
                             f"methods only (method {self.method.name!r} is kick "
                             "first): use fused=True (default) or backend='numpy'")
        rhs = self.backend.make_pde_rhs(self.pde, state)
        alpha, beta = self.alpha, self.beta
        nsub = beta.size
        if not self.method.kick_first:
            def single_step(state_data, t):
                for i in range(nsub):
                    state_data[0] += alpha[i] * dt * state_data[1]
                    acc = rhs(state_data, t)
                    state_data[1] += beta[i] * dt * acc[1]
                state_data[0] += alpha[nsub] * dt * state_data[1]
                return state_data

            return single_step

        last: dict[str, np.ndarray] = {}

        def single_step_fsal(state_data, t):
            u = state_data[0]
            if "u" in last and np.array_equal(last["u"], u):
                acc1 = last["a"]
            else:
                acc1 = rhs(state_data, t)[1]  # (a fresh array)
                self._extra_evaluations += 1
            state_data[1] += beta[0] * dt * acc1
            for i in range(1, nsub):
                state_data[0] += alpha[i] * dt * state_data[1]
                acc1 = rhs(state_data, t)[1]  # (a fresh array)
                state_data[1] += beta[i] * dt * acc1
            last["u"] = state_data[0].copy()
            last["a"] = acc1
            return state_data

        return single_step_fsal


    def _dissipative_step(self, dt: float):
        """NumPy step of a dissipative PDE: D(Δt/2) ∘ V(Δt) ∘ D*(Δt/2) (Strang).

        V the splitting method with the conservative acceleration
        (``pde.acceleration``), D the PDE's dissipative sub-step (``pde.dissipate``,
        booking the dissipated energy in the state's third field): the reference of the
        fused dissipative kernels (:mod:`continuum._stepper`, "Dissipation").
        """
        if self.backend.name != "numpy":
            raise ValueError("a dissipative medium steps with the fused kernels "
                             "(backend 'numba', fused=True) or backend='numpy'")
        pde, alpha, beta = self.pde, self.alpha, self.beta
        nsub = beta.size

        def single_step(state_data, t):
            pde.dissipate(state_data, 0.5 * dt, True)
            for i in range(nsub):
                state_data[0] += alpha[i] * dt * state_data[1]
                state_data[1] += beta[i] * dt * pde.acceleration(state_data[0])
            state_data[0] += alpha[nsub] * dt * state_data[1]
            pde.dissipate(state_data, 0.5 * dt, False)
            return state_data

        return single_step


class RK4Solver(_CheckedSolver):
    """Classical fourth-order Runge–Kutta with fused compiled chunks (KdV).

    With the numba backend the PDE's ``make_chunk_stepper(state, dt)`` advances whole
    chunks (:func:`continuum._stepper.kdv_chunk`); otherwise py-pde's generic loop over
    single steps of :meth:`evolution_rate` / ``make_evolution_rate``.  Monitors the
    PDE's invariants (``pde.invariants``) like :class:`VerletSolver`.
    """

    name = "fused-rk4"

    def _evaluations_per_step(self) -> int:
        return 4

    def _make_fused(self, state, dt: float):
        return self.pde.make_chunk_stepper(state, dt)

    def _make_single_step_fixed_dt(self, state, dt: float):
        """Classical RK4 step (as py-pde's fixed-step ``runge-kutta``)."""
        rhs = self.backend.make_pde_rhs(self.pde, state)

        def single_step(state_data, t):
            k1 = dt * rhs(state_data, t)
            k2 = dt * rhs(state_data + 0.5 * k1, t + 0.5 * dt)
            k3 = dt * rhs(state_data + 0.5 * k2, t + 0.5 * dt)
            k4 = dt * rhs(state_data + k3, t + dt)
            state_data += (k1 + 2 * k2 + 2 * k3 + k4) / 6
            return state_data

        return single_step


class RunResult(dict):
    """Result of :func:`run`: ``state``, ``times``, ``energy``, ``momentum``, ``info``."""

    @property
    def energy_drift(self) -> float:
        """Max |E(t) - E(0)| / |E(0)| over the recorded times."""
        e = np.asarray(self["energy"])
        if not e.size:
            return float("nan")
        if e[0] == 0:
            return float(np.max(np.abs(e)))
        return float(np.max(np.abs(e - e[0])) / abs(e[0]))


def run(
    pde,
    state,
    t_end: float,
    *,
    dt: float | None = None,
    order: int | None = None,
    method: str | None = None,
    backend: str = "numba",
    interval: float | None = None,
    storage: str | Path | None = None,
    extra_info: dict[str, Any] | None = None,
    trackers: list | None = None,
    drift_tolerance: float = DRIFT_TOLERANCE,
    fused: bool = True,
) -> RunResult:
    """Integrate a continuum equation, monitoring its conserved quantities.

    Chain PDEs (:class:`BoussinesqPDE`, :class:`NesterenkoPDE`) are integrated with
    :class:`VerletSolver` and monitor their energy functional and momentum;
    :class:`KdVPDE` with :class:`RK4Solver`, monitoring its invariants ∫s² dX
    (reported as ``energy``: to leading order the wave energy divided by K) and ∫s dX
    (``momentum``).

    Parameters
    ----------
    pde : ChainPDEBase or KdVPDE
        The equation (carries the medium and its parameters).
    state : FieldCollection or ScalarField
        Initial (u, v) of a chain PDE, or the overlap change s of KdV; not modified.
    t_end : float
        Final time, s (finite, >= 0).
    dt : float, optional
        Time step, s (finite, > 0; default ``pde.stable_dt(state)``); shortened to
        t_end/ceil(t_end/dt) so that a whole number of steps ends at t_end (recorded as
        ``info["dt_s"]``).
    order : {2, 4}, optional
        Order of the symplectic stepper of a chain PDE: the drift-first method of
        :data:`ORDER_METHODS` (default 2 unless ``method`` is given); KdV: 4 (RK4) only.
    method : str, optional
        The splitting method of a chain PDE, any of :data:`theory.splitting.SPLITTINGS`
        (e.g. ``"blanes_moan4"``; ``order``, if also given, must be its order).  KdV:
        none.
    backend : {"numba", "numpy"}
        py-pde backend: "numba" (default: compiled fused chunks) or "numpy" (the
        reference: :meth:`evolution_rate` per step).
    interval : float, optional
        Time between energy records and stored frames, s (finite, > 0; default t_end/20).
    storage : path, optional
        HDF5 file (py-pde :class:`~pde.FileStorage`) receiving the frames, with the
        run's parameters (``pde.parameters``, dt, order, t_end, ``extra_info``) as
        attributes; sealed once complete (:func:`theory.integrity.seal_file`: py-pde
        reads it as before, :func:`theory.integrity.verify` finds any change).
    extra_info : dict, optional
        More attributes for the storage (e.g. the scenario).
    trackers : list, optional
        Further py-pde trackers.
    drift_tolerance : float
        Largest relative drift of the energy functional (default
        :data:`DRIFT_TOLERANCE`); beyond it, or on a NaN/inf state, the run raises
        :class:`InstabilityError`.
    fused : bool
        Use the fused compiled stepper with the numba backend (default; ``False`` is
        py-pde's generic per-step loop, kept for comparison).

    Returns
    -------
    RunResult
        Final ``state``, the monitor ``times`` (s), ``energy`` (J) and ``momentum``
        (kg m/s), and ``info`` (run parameters, ``steps``, ``node_updates``).

    Raises
    ------
    ValueError
        A parameter outside its range (named in the message).
    InstabilityError
        The integration went unstable (message: cause, time, dt and the stable step).
    """
    try:
        t_end = float(t_end)
    except (TypeError, ValueError):
        raise ValueError(f"t_end must be a finite number >= 0 s (got {t_end!r})") from None
    if not (math.isfinite(t_end) and t_end >= 0):
        raise ValueError(f"t_end must be a finite number >= 0 s (got {t_end!r})")
    if backend not in ("numba", "numpy"):
        raise ValueError(f"backend must be 'numba' or 'numpy' (got {backend!r})")
    from .kdv import KdVPDE

    kdv = isinstance(pde, KdVPDE)
    if kdv:
        if order not in (None, 4):
            raise ValueError(f"KdV is integrated with RK4: order must be 4 (got {order!r})")
        if method is not None:
            raise ValueError(f"KdV is integrated with RK4: method must be None (got "
                             f"{method!r})")
        order = 4
        method_name = "rk4"
        pde.check_state(state)
    else:
        split = splitting_method(method, order)  # validates order and method
        order, method_name = split.order, split.name
        pde._check(state)
        if state.grid != pde.grid:
            raise ValueError("state must live on the PDE's grid (pde.get_initial_condition)")
    with np.errstate(all="ignore"):
        finite = bool(np.all(np.isfinite(state.data)))
    if not finite:
        raise ValueError("state must be finite (it holds NaN or inf)")
    if dt is None:
        with np.errstate(all="ignore"):
            dt = float(pde.stable_dt(state))
    dt = _check_positive("dt", dt, "s")
    if t_end / dt > MAX_STEPS:
        raise ValueError(f"dt = {dt:.4g} s needs {t_end / dt:.3g} steps to t_end = "
                         f"{t_end:.4g} s; dt must be >= t_end/{MAX_STEPS:.0e} "
                         f"= {t_end / MAX_STEPS:.4g} s")
    if t_end > 0:
        # a whole number of steps to t_end, so that the run ends at t_end exactly (not
        # within ±dt/2): the step is shortened by less than one part in t_end/dt
        dt = t_end / math.ceil(t_end / dt * (1 - 1e-12))
    if interval is None:
        interval = t_end / 20 if t_end > 0 else 1.0
    interval = _check_positive("interval", interval, "s")
    info = {**pde.parameters, "dt_s": dt, "order": order, "method": method_name,
            "t_end_s": t_end,
            "time_unit": "s", "length_unit": "grain diameters (X = x/d)",
            "u_unit": "m", "v_unit": "m/s", **(extra_info or {})}
    if kdv:
        solver = RK4Solver(pde, backend=backend, fused=fused, drift_tolerance=drift_tolerance)
    else:
        solver = VerletSolver(pde, backend=backend, method=split, fused=fused,
                              drift_tolerance=drift_tolerance)
    all_trackers = list(trackers or [])
    store = tmp = None
    if storage is not None:
        # write to a temporary name beside the target and rename when complete, so no
        # reader ever sees a half-written file (a crash leaves the old file or none)
        target = Path(storage)
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
        store = FileStorage(tmp, info=info, write_mode="truncate")
        all_trackers.append(store.tracker(interrupts=interval))
    # the monitor interval sets the chunks (one energy record per chunk)
    all_trackers.append(_Interrupts(interrupts=interval))
    controller = Controller(solver, t_range=t_end, tracker=all_trackers)
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
    mon = solver.monitor
    if not mon["t"]:  # t_end = 0: no step was taken
        e0, p0 = pde.invariants(state)
        mon = {"t": [0.0], "energy": [e0], "momentum": [p0]}
    return RunResult(state=final, times=np.asarray(mon["t"]),
                     energy=np.asarray(mon["energy"]), momentum=np.asarray(mon["momentum"]),
                     info={**info, **controller.diagnostics.get("solver", {})})


class _Interrupts(TrackerBase):
    """A tracker that only interrupts the stepping (one energy record per interval)."""

    def handle(self, field, t: float) -> None:
        """Nothing to do: the solver records its monitor at every interrupt."""
