r"""The :class:`Simulation` object: a chain, a contact law, its state, the time step, the recording.

The time step is chosen by :class:`discrete.timestep.TimeStep` (default, stability
bound, expected overlaps: see that module).  The contact law (:mod:`theory.laws`,
Hertz by default) and an optional on-site drag select the compiled kernels
(:func:`discrete.kernels.make_kernels`).

Energy balance
--------------
The monitor checks :math:`E(t) + D(t) = E(0)` with E the wave energy (kinetic plus the
elastic contact energies, docs/physics.md §6) and D the energy dissipated so far
(0 for a conservative law; :meth:`Simulation.dissipated`): a relative violation beyond
``drift_tolerance`` is an instability, with or without dissipation.  For velocity
Verlet the modified energy replaces E (below).  D is the energy the kernels' exact
dissipative sub-steps removed (:mod:`discrete.kernels`, "Dissipation"), equal to the
kinetic energy they took to round-off, so the balance carries only velocity Verlet's
own O(Δt²) error (docs/physics.md §11).

Energy: velocity Verlet conserves a modified energy :math:`\tilde H = H + O(\Delta t^2)`
(Hairer, Lubich & Wanner 2006, §IX; :func:`discrete.kernels.shadow_correction`).  The
physical energy H differs from it by O(Δt²), which does not accumulate.  Measured at the
default dt (relative max |H - H(0)|): < 1e-10 for precompressed cut or exact waves
(their O(Δt²) term travels with them unchanged); 2-3e-6 for δ0 = 0 waves (the narrow
wave's O(Δt²) term is modulated by its lattice phase, and every contact closes from
zero overlap, where Eq. 1 is not smooth) and for impacts, which excite the grid-scale
modes (1.8e-5 at δ0/d = 1e-3, ≈ (ω_lat Δt)²/24).  The drift of :math:`\tilde H` is
2e-10 … 2e-7 in those runs.  H reaches 1e-8 only near the paper's dt (Δt/20).

Integrators
-----------
``integrator="verlet"`` (default, the paper's), ``"yoshida4"`` or ``"blanes_moan4"``
(:mod:`discrete.integrators`; default dt S × the above, i.e. the same number of force
evaluations per unit time).  Measured on the Fig. 5 scattering runs (precompressed, no
gaps; ``benchmarks/fig5_full.py``, section energies and front speed against velocity
Verlet at dt = 1e-9 s): velocity Verlet at its default is within 1.3e-6, Blanes–Moan
at 48× that dt (1/8 of the force evaluations) within 1e-7, with fitted orders 2.00
and 3.9–4.0.  With gaps opening (δ0 = 0 scattering; the Hertz force is only C¹ at
r = 0) Blanes–Moan's order drops to ~3.3 with errors no longer monotone in dt (still 5×
more accurate than velocity Verlet's default at 1/8 of the force evaluations), and the
per-step running maxima (Fig. 2) carry an O(Δt²) sampling error whatever the method.
Velocity Verlet stays the default: its convergence is a clean 2nd order in every
regime, it has the modified-energy monitor, and results of existing runs do not change;
use ``blanes_moan4`` with ``dt = default_dt(..., fraction=0.096)`` for precompressed
runs without gaps.  The modified-energy column of the monitor is H itself for the
4th-order methods (their O(Δt⁴) energy error needs no correction).

Threads and speed
-----------------
The kernel (:mod:`discrete.kernels`) runs one fused pass per force evaluation over the
active window, temporally blocked and on several threads for large windows
(``threads``; bitwise identical results).  Its speed, in grain-updates per second against
the NumPy step and against LAMMPS, is ``benchmarks/kernel.py``'s and
``benchmarks/lammps.py``'s (docs/benchmarks.md).
Writing and reading
-------------------
:meth:`Simulation.saved` returns everything that continues the run bit for bit (chain,
law, state, recording, record, pending events, the time step's bounds) as a
:class:`SavedSimulation`; :meth:`Simulation.restore` rebuilds the simulation from one.
:mod:`discrete.io` only maps that to and from HDF5.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numba
import numpy as np

from theory.laws import ContactLaw, as_law

from . import kernels as K
from .chain import Chain
from .integrators import get_integrator
from .progress import RunProgress
from .recording import (
    AtTime,
    Record,
    Recording,
    Snapshot,
    WaveAt,
    as_event,
    check_event,
)
from .reference import overlaps as _overlaps
from .timestep import DT_FRACTION, TimeStep, default_dt, expected_overlaps, stable_dt

__all__ = ["Simulation", "SavedSimulation", "State", "RunInfo", "InstabilityError",
           "default_dt", "stable_dt", "expected_overlaps", "DT_FRACTION",
           "PARALLEL_MIN_GRAINS"]

RESTORE_A_RTOL = 1e-9
"""Relative tolerance of a damped run's restored acceleration against the elastic
acceleration recomputed from its positions (:meth:`Simulation.restore`): the kernels and
the constructor form it in different orders (round-off, ~1e-15 of its largest value);
the total acceleration of an older file differs by the damping force."""

BLOCK_SUBSTEPS = 256
"""Substeps (force evaluations) per block of the temporally blocked kernel
(:mod:`discrete.kernels`): 256 velocity-Verlet steps, 42 of a 6-stage method."""

TILE_GRAINS = 8192
"""Grains per tile of the temporally blocked kernel (u, v, max v: 192 kB, in L2)."""

SERIAL_BLOCK_MIN_GRAINS = 400_000
"""On one thread, windows from this size use temporal blocking (memory-bound beyond L3).

Measured (benchmarks/README.md): at 1e4–2e5 grains the per-step pass is compute-bound
(one square root per grain) and blocking gains nothing; at 1e6 it gains ~5–10 %."""

_TUNE_PROBE = 16
"""Every this many chunks the thread choice re-measures the other mode."""

PARALLEL_MIN_GRAINS = 10_000
"""Windows of at least this many grains are split over the threads (``threads=None``).

Measured with ``benchmarks/kernel.py --threads 2`` (benchmarks/README.md): below ~1e4
grains a substep takes a few microseconds and the fork/join of the parallel region
(~1.5 µs each) eats the gain."""


class InstabilityError(RuntimeError):
    """The integration went unstable (NaN or a violated energy balance)."""


@dataclass
class State:
    """Displacements u (m), velocities v (m/s), time t (s), wall displacements (m)."""

    u: np.ndarray
    v: np.ndarray
    t: float
    wall_left: float
    wall_right: float


@dataclass
class RunInfo:
    """Summary of one call of :meth:`Simulation.run`."""

    steps: int
    t: float
    stopped_by: str
    """What ended the call: the stop event's label, ``"t_end"`` (the end time was
    reached) or ``"max_steps"`` (the step bound came first)."""
    energy_drift: float
    """max |(E + D) - (E + D)(start of run)| / |E(start of run)| over the run's monitor
    samples (D the dissipated energy: 0 for a conservative law)."""
    shadow_drift: float
    """The same for velocity Verlet's modified energy (secular drift only)."""

    def _repr_html_(self) -> str:
        """Jupyter display: a table with units (:func:`discrete.display.run_info_html`)."""
        from .display import run_info_html

        return run_info_html(self)


@dataclass
class SavedSimulation:
    """Everything that continues a :class:`Simulation` bit for bit (:meth:`Simulation.saved`).

    Attributes
    ----------
    attrs : dict
        Scalars (float, int, bool, str): ``dt``, ``steps``, ``t``, ``t0``, ``energy0``,
        ``energy_drift``, ``wall_left``, ``wall_right``, ``drift_tolerance``, ``chunk``,
        ``active_window``, ``default_threshold``, ``integrator``, ``drag`` (1/s),
        ``dissipation_rate0`` (W), ``dt_default`` (s).
    chain : Chain
    law : ContactLaw
    state : dict of arrays
        ``u`` (m), ``v`` (m/s), ``a`` (m/s²), ``dissipated`` (J, booked per contact) and
        ``delta_expected`` (m, the expected overlaps of the run's initial state).
    recording : Recording
    record : Record
    pending : list of events
        Snapshot events that have not happened yet.
    """

    attrs: dict[str, Any]
    chain: Chain
    law: ContactLaw
    state: dict[str, np.ndarray]
    recording: Recording
    record: Record
    pending: list = field(default_factory=list)


class Simulation:
    """Integration of a :class:`Chain` (paper Eq. 2) with a contact law, pyro2 style.

    Parameters
    ----------
    chain : Chain
        The chain.
    u, v : (N,) arrays, optional
        Initial displacements from static equilibrium (m) and velocities (m/s); zero.
    dt : float or TimeStep, optional
        Time step, s (> 0), or one chosen by :meth:`TimeStep.choose
        <discrete.timestep.TimeStep.choose>` (its integrator then wins); default
        :class:`~discrete.timestep.TimeStep`'s.
    wall_left, wall_right : float
        Wall displacements, m (fixed during the run).
    record : Recording, optional
        What to record; default: running maxima and the energy monitor.
    t : float
        Initial time, s.
    active_window : bool
        Integrate only the grains not exactly at rest in equilibrium (bitwise identical
        results; False integrates every grain, one step at a time on one thread — for
        tests).
    drift_tolerance : float
        Relative violation of the energy balance E + D = E(0) (for velocity Verlet: of
        its modified energy, :func:`kernels` ``shadow_correction``, which has no O(dt²)
        oscillation) that counts as an instability (1e-8–1e-5 in sane runs).
    chunk : int
        Largest number of steps per kernel call.
    integrator : str
        Time-stepping method (:data:`discrete.integrators.INTEGRATORS`): ``"verlet"``
        (velocity Verlet, the paper's; default), ``"yoshida4"``, ``"blanes_moan4"``.
        Velocity-dependent forces (a dissipative law, drag) take velocity Verlet for the
        elastic force between exact dissipative sub-steps (:mod:`discrete.kernels`).
    threads : int, optional
        Threads for the kernel, used only while the active window has at least
        :data:`PARALLEL_MIN_GRAINS` grains.  None (default): all numba threads
        (``numba.get_num_threads()``), where they are measured to be faster than one
        (the machine may be busy; :meth:`_tune_choose`); n: n threads; 1: one.  Results
        are bitwise identical for every choice (:mod:`discrete.kernels`).  Threads work
        through the temporally blocked kernel, which is not used while a time-series
        grain sampled in the block lies within reach of the active window, nor for
        velocity-dependent forces.
    check_dt : bool
        Reject a ``dt`` above the largest linearly stable step at the expected overlaps
        (ValueError naming the allowed range); False only for tests of the run-time
        instability detection.
    law : ContactLaw, optional
        The contact law (:mod:`theory.laws`); default Hertz (paper Eq. 1).
    drag : float
        On-site viscous drag rate β, 1/s (>= 0): force -m_i β v_i on every grain.
    rtol : float, optional
        Relative accuracy of the recorded quantities, in (0, 1): dt is chosen from a
        step-doubling probe (:mod:`discrete.timestep`; ``integrator="auto"``: the method
        too) and the estimate kept in ``time_step.error_estimate``.  An explicit ``dt``
        wins.
    """

    def __init__(self, chain: Chain, u=None, v=None, *, dt: float | None = None,
                 wall_left: float = 0.0, wall_right: float = 0.0,
                 record: Recording | None = None, t: float = 0.0, active_window: bool = True,
                 drift_tolerance: float = 1e-4, chunk: int = 4096,
                 integrator: str = "verlet", threads: int | None = None,
                 check_dt: bool = True, law: ContactLaw | dict | None = None,
                 drag: float = 0.0, rtol: float | None = None) -> None:
        if not isinstance(chain, Chain):
            raise ValueError(f"chain must be a Chain (got {type(chain).__name__})")
        n = chain.n
        self.chain = chain
        self.law = as_law(law)
        try:
            self.drag = float(drag)
        except (TypeError, ValueError):
            raise ValueError(f"drag must be a real number >= 0 1/s (got {drag!r})") from None
        if not (math.isfinite(self.drag) and self.drag >= 0):
            raise ValueError(f"drag must be finite and >= 0 1/s (got {drag!r})")
        self.u = self._vec("u", u, n)
        self.v = self._vec("v", v, n)
        for name, w in (("wall_left", wall_left), ("wall_right", wall_right), ("t", t)):
            if not math.isfinite(float(w)):
                raise ValueError(f"{name} must be finite (got {w!r})")
        self.wall_left, self.wall_right = float(wall_left), float(wall_right)
        self.recording = Recording() if record is None else record
        self.recording.validate(n)
        if isinstance(dt, TimeStep):  # chosen beforehand (a runner's rtol probe)
            integrator = dt.integrator
        elif rtol is not None and dt is None:
            dt = TimeStep.choose(chain, self.u, self.v, self.wall_left, self.wall_right,
                                 rtol=rtol, integrator=None if integrator == "auto"
                                 else integrator, law=self.law, drag=self.drag,
                                 check=check_dt, recording=self.recording,
                                 drift_tolerance=drift_tolerance)
            integrator = dt.integrator
        method = get_integrator(integrator)
        vd = bool(self.law.dissipative or self.drag > 0)  # velocity-dependent forces
        if vd and method.name != "verlet":
            raise ValueError(f"integrator {method.name!r} needs forces that depend on "
                             "positions only; a dissipative law or drag runs with 'verlet' "
                             "(velocity Verlet between exact dissipative sub-steps, "
                             "discrete.kernels)")
        if isinstance(dt, TimeStep):
            self.time_step = dt
            if check_dt:
                dt.check()
        else:
            self.time_step = TimeStep.choose(chain, self.u, self.v, self.wall_left,
                                             self.wall_right, dt=dt, integrator=method,
                                             law=self.law, drag=self.drag, check=check_dt)
        self.dt = self.time_step.dt
        self.kernels = K.make_kernels(self.law, self.drag > 0, self.recording.strain_maxima,
                                      self._refined_maxima(vd))
        if not (drift_tolerance > 0):
            raise ValueError(f"drift_tolerance must be > 0 (got {drift_tolerance!r})")
        self.drift_tolerance = float(drift_tolerance)
        if int(chunk) < 1:
            raise ValueError(f"chunk must be an integer >= 1 (got {chunk!r})")
        self.chunk = int(chunk)
        self.integrator = method.name
        self._drift, self._kick = method.coefficients(self.dt)
        self._auto_threads = threads is None
        self._tune_count = 0
        self.min_parallel = PARALLEL_MIN_GRAINS
        self._threads: int | None = None  # threads=None: numba's count, read when needed
        if threads is not None:
            nmax = int(numba.config.NUMBA_NUM_THREADS)
            if int(threads) != threads or not 1 <= threads <= nmax:
                raise ValueError(f"threads must be None or an integer in [1, {nmax}] "
                                 f"(got {threads!r})")
            self._threads = int(threads)
        self._rates: dict[int, float | None] = {1: None}
        self.active_window = bool(active_window)
        # blocks shrink the window to the active grains, and carry the threads: not with
        # active_window=False, nor for velocity-dependent forces (discrete.kernels)
        self.block_steps = (max(4, BLOCK_SUBSTEPS // method.stages)
                            if active_window and not self.kernels.velocity_dependent else 0)
        self.t0 = float(t)
        self.steps = 0
        self._p = K.kernel_params(self.law, self.drag)
        self._inv_m = 1.0 / chain.mass
        self._k, self._d0 = chain.k, chain.delta0
        self._f0 = self.kernels.static_forces(self._k, self._d0, self._p)
        self._check_equilibrium()
        self._runs = K.chain_runs(self._inv_m, self._k, self._d0, self._f0)
        self._dis = np.zeros(n + 1)  # dissipated energy booked per contact, J
        self.a = np.zeros(n)
        self.kernels.accelerations(self.u, self.v, self.a, self._constants(), self._p,
                                   self.wall_left, self.wall_right, 0, n - 1)
        self._p0 = self._dissipation_rate()
        self._lo, self._hi = 0, n - 1
        self._shrink()
        rec = self.recording
        self.record = Record(series_grains=np.asarray(rec.series_grains, dtype=np.int64),
                             energy_coarsen=int(rec.energy_coarsen),
                             sensor_grains=np.asarray(rec.sensors, dtype=np.int64),
                             wall_forces=bool(rec.wall_forces))
        self._ts_grains = self._sampled_grains()
        if rec.maxima:
            self.record.vmax = self.v.copy()
            self.record.umax = self.u.copy()
            if self.kernels.refined_maxima:
                self.record.vmax_refined = self.v.copy()
                self.record.vmax_time = np.full(n, self.t0)
                self.record.peak_state = np.zeros((K.PEAK_ROWS, n))
                self.record.peak_state[0] = self.v  # the gate's copy (discrete.kernels)
        if rec.strain_maxima:
            self.record.overlap_max = self.overlaps()
        self._pending = rec.events()
        vmax0 = float(np.max(np.abs(self.v))) if n else 0.0
        self._default_threshold = 0.01 * vmax0 if vmax0 > 0 else 1e-12
        self.energy0 = self.energy()
        self._monitor()
        self._energy_row()

    # ------------------------------------------------------------------ helpers
    @staticmethod
    def _vec(name: str, x, n: int) -> np.ndarray:
        if x is None:
            return np.zeros(n)
        a = np.array(x, dtype=float)
        if a.shape != (n,):
            raise ValueError(f"{name} must have shape ({n},) (got {a.shape})")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be finite (got NaN or inf)")
        return a

    def _check_equilibrium(self) -> None:
        """ValueError unless every grain is in static equilibrium under this law.

        The kernels subtract the static force f0 per contact (:mod:`discrete.kernels`):
        that is Eq. 2 (with the body force m g of a vertical chain) only if
        f0_i - f0_{i+1} + m_i g = 0 for every grain i.
        """
        f0, b = self._f0, self.chain.body_force
        scale = max(float(np.max(np.abs(f0))), float(np.max(np.abs(b))))
        if scale == 0:
            return
        residual = float(np.max(np.abs(f0[:-1] - f0[1:] + b))) / scale
        if residual > 1e-9:
            raise ValueError(
                f"the chain's static overlaps are not in force equilibrium under the "
                f"{self.law.describe()} (net static force {residual:.3g} of the largest "
                f"contact force; allowed 1e-9): build the chain with "
                f"exponent={self.law.exponent:g} (it was built for exponent "
                f"{self.chain.exponent:g}), with both walls if it is precompressed")

    def _constants(self) -> tuple:
        """(1/m, k, δ0, f0, run starts, run table): the kernels' chain constants."""
        return (self._inv_m, self._k, self._d0, self._f0, *self._runs)

    def _shrink(self) -> None:
        if not self.active_window:
            self._lo, self._hi = 0, self.chain.n - 1
            return
        if self._lo < 0:
            return
        self._lo, self._hi = K.active_window(self.u, self.v, self.a, self._k,
                                             self.wall_left, self.wall_right, self._lo,
                                             self._hi, self.kernels.velocity_dependent)

    @property
    def t(self) -> float:
        """Present time t0 + steps·dt, s."""
        return self.t0 + self.steps * self.dt

    @property
    def dt_default(self) -> float:
        """The default time step of the run's initial state, s (:class:`TimeStep`)."""
        return self.time_step.default

    @property
    def state(self) -> State:
        """A copy of the present state."""
        return State(self.u.copy(), self.v.copy(), self.t, self.wall_left, self.wall_right)

    @property
    def window(self) -> tuple[int, int]:
        """The active window (lo, hi); (-1, -1) when every grain is at rest in equilibrium."""
        return self._lo, self._hi

    @property
    def restart_period(self) -> int:
        """Steps between the points where a run can be cut, bit for bit.

        A run cut there into separate :meth:`run` calls (or saved and restored) gives
        bit for bit the uninterrupted result.  The least common multiple of
        ``Recording.monitor_every`` (chunks end there, and the monitor samples) and the
        kernel's running-maximum period of u.
        """
        return math.lcm(int(self.recording.monitor_every), int(K.UMAX_EVERY))

    def step_of(self, t: float) -> int:
        """The first step whose time is >= t (to within 1e-9 dt), as :meth:`run` rounds."""
        return max(0, math.ceil((t - self.t0) / self.dt - 1e-9))

    def overlaps(self) -> np.ndarray:
        """Present contact overlaps δ0_j + (u_{j-1} - u_j), m (Eq. 1)."""
        return _overlaps(self.u, self._d0, self.wall_left, self.wall_right)

    def energy(self) -> float:
        """Total wave energy Σ ½mv² + Σ (U(r_j) - U(δ0_j)) - Σ m_i g u_i, J.

        (docs/physics.md §6; the last term, the potential energy of the body force, only
        for a vertical chain.)
        """
        if self._lo < 0:
            return 0.0
        ek = np.empty(self.chain.n)
        ep = np.empty(self.chain.n)
        tk, tp = self.kernels.grain_energies(self.u, self.v, self.chain.mass, self._k,
                                             self._d0, self.wall_left, self.wall_right,
                                             self._lo, self._hi, ek, ep)
        if self.chain.gravity:
            tp -= float(np.dot(self.chain.body_force, self.u))
        return tk + tp

    def grain_energy(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-grain kinetic and potential energy (half of each contact), J (Fig. 8)."""
        ek = np.zeros(self.chain.n)
        ep = np.zeros(self.chain.n)
        if self._lo >= 0:
            self.kernels.grain_energies(self.u, self.v, self.chain.mass, self._k, self._d0,
                                        self.wall_left, self.wall_right, self._lo,
                                        self._hi, ek, ep)
        if self.chain.gravity:
            ep -= self.chain.body_force * self.u
        return ek, ep

    def _dissipation_rate(self) -> float:
        if not self.kernels.velocity_dependent:
            return 0.0
        return float(self.kernels.dissipation_rate(self.u, self.v, self.chain.mass, self._k,
                                                   self._d0, self._p, self.wall_left,
                                                   self.wall_right))

    def dissipated(self) -> float:
        r"""Energy dissipated since the start of the run, J (0 for conservative forces).

        The sum of what the dissipative sub-steps removed (:mod:`discrete.kernels`,
        "Dissipation"): per contact :math:`P_j\bar w_j` and per grain
        :math:`\tfrac12 m_i(v_i^2 - v_i'^2)`, the integrator's own discrete work, equal
        to the kinetic energy those sub-steps took to round-off.  It approximates
        :math:`\int_{t_0}^t P\,dt` (P the dissipated power) at second order, like the
        integration itself.
        """
        if not self.kernels.velocity_dependent:
            return 0.0
        return float(np.sum(self._dis))

    def dissipated_per_contact(self) -> np.ndarray:
        """The dissipated energy booked per contact j (with the drag of grain j-1), J."""
        return self._dis.copy()

    def _monitor(self) -> tuple[float, float]:
        e = self.energy()
        sh = 0.0
        if self._lo >= 0 and self.integrator == "verlet":
            sh = self.kernels.shadow_correction(self.u, self.v, self.a, self.chain.mass,
                                                self._k, self._d0, self.wall_left,
                                                self.wall_right, self._lo, self._hi)
        es = e + self.dt**2 * sh
        d = self.dissipated()
        r = self.record
        r.monitor_t.append(self.t)
        r.monitor_energy.append(e)
        r.monitor_shadow.append(es)
        r.monitor_dissipated.append(d)
        return e + d, es + d

    def _energy_row(self) -> None:
        every = self.recording.energy_every
        if every is None or self.steps % every:
            return
        c = self.record.energy_coarsen
        if not self.chain.gravity:  # the arithmetic of the kernel's rows inside chunks
            m = -(-self.chain.n // c)
            ek, ep = np.empty(m), np.empty(m)
            self.kernels.grid_row(self.u, self.v, self.chain.mass, self._k, self._d0,
                                  self.wall_left, self.wall_right, self._lo, self._hi, c,
                                  ek, ep)
            self.record.energy.append(self.t, ek, ep)
            return
        ek, ep = self.grain_energy()
        if c > 1:
            starts = np.arange(0, ek.size, c)
            ek, ep = np.add.reduceat(ek, starts), np.add.reduceat(ep, starts)
        self.record.energy.append(self.t, ek, ep)

    def _snapshot(self, label: str) -> None:
        if self.record.umax is not None:
            np.maximum(self.record.umax, self.u, out=self.record.umax)
        self.record.snapshots.append(Snapshot(label, self.t, self.steps, self.u.copy(),
                                              self.v.copy(), self.overlaps()))

    def _instability(self, cause: str) -> InstabilityError:
        # quote the bound at the expected overlaps of the initial state: after a blow-up
        # the present overlaps are meaningless (they gave ~1e-78 s)
        return InstabilityError(
            f"{cause} at t = {self.t:.6g} s (step {self.steps}) with dt = {self.dt:.4g} s; "
            f"likely cause: dt too large for the contact stiffness. "
            f"{self.time_step.explain()}")

    def _refined_maxima(self, velocity_dependent: bool) -> bool:
        """Whether this run keeps refined maxima (``Recording.refined_maxima``).

        None (default): with a time step chosen for ``rtol`` (whose accuracy statement is
        about them).  Never with velocity-dependent forces: the split step stores the
        elastic acceleration, not dv/dt, so the cubic Hermite interpolant of (v, a) would
        not be the velocity between the steps (True is refused there).  The kernels are
        compiled with or without them (:func:`discrete.kernels.make_kernels`).
        """
        rec = self.recording
        refined = rec.refined_maxima
        if refined and velocity_dependent:
            raise ValueError(
                "recording.refined_maxima=True needs forces that depend on positions "
                "only: with a dissipative law or drag the stored acceleration is the "
                "elastic one, not dv/dt, so the cubic Hermite interpolant of (v, a) "
                "would not be the velocity between the steps; use refined_maxima=None "
                "or False (sampled maxima)")
        if refined is None:
            refined = self.time_step.source == "rtol" and not velocity_dependent
        return bool(rec.maxima and refined)

    # ------------------------------------------------------------------ writing, reading
    def saved(self) -> SavedSimulation:
        """Everything that continues this simulation bit for bit (module docstring).

        Arrays are the simulation's own (not copies): write them before running on.
        """
        a = {"dt": self.dt, "steps": self.steps, "t": self.t, "t0": self.t0,
             "energy0": self.energy0, "energy_drift": self.energy_drift,
             "wall_left": self.wall_left, "wall_right": self.wall_right,
             "drift_tolerance": self.drift_tolerance, "chunk": self.chunk,
             "active_window": self.active_window,
             "default_threshold": self._default_threshold, "integrator": self.integrator,
             "drag": self.drag, "dissipation_rate0": self._p0,
             "dt_default": self.time_step.default,
             **{k: v for k, v in self.time_step.to_dict().items() if k.startswith("rtol")},
             "dt_source": self.time_step.source}
        state = {"u": self.u, "v": self.v, "a": self.a, "dissipated": self._dis,
                 "delta_expected": self.time_step.delta_expected}
        return SavedSimulation(a, self.chain, self.law, state, self.recording, self.record,
                               list(self._pending))

    @classmethod
    def restore(cls, saved: SavedSimulation, *, threads: int | None = None) -> Simulation:
        """The simulation :meth:`saved` described; continuing it gives the same bits.

        ``saved.state`` needs ``u``, ``v``, ``a``; ``dissipated`` (zeros),
        ``delta_expected`` and the attributes ``dt_default``, ``drag`` (0),
        ``dissipation_rate0`` (0), ``integrator`` ("verlet") are optional (files of
        older versions).  ValueError for inconsistent parts.
        """
        at, st = saved.attrs, saved.state
        kwargs = {} if threads is None else {"threads": threads}
        sim = cls(saved.chain, st["u"], st["v"], dt=float(at["dt"]),
                  wall_left=float(at["wall_left"]), wall_right=float(at["wall_right"]),
                  record=saved.recording, t=float(at["t0"]),
                  active_window=bool(at["active_window"]),
                  drift_tolerance=float(at["drift_tolerance"]), chunk=int(at["chunk"]),
                  integrator=str(at.get("integrator", "verlet")), law=saved.law,
                  drag=float(at.get("drag", 0.0)), check_dt=False, **kwargs)
        # (dt was checked against the stability bound when the run was created; the
        # saved state's present overlaps are not the initial ones)
        steps = int(at["steps"])
        if steps < 0:
            raise ValueError(f"steps = {steps} must be >= 0")
        sim.steps = steps
        n = sim.chain.n
        for name, shape in (("a", (n,)), ("dissipated", (n + 1,))):
            if name not in st:
                continue
            x = np.asarray(st[name], float)
            if x.shape != shape or not np.all(np.isfinite(x)):
                raise ValueError(f"state/{name} must be finite with shape {shape} "
                                 f"(got {x.shape})")
        if sim.kernels.velocity_dependent:
            # The split dissipative step (discrete.kernels, "Dissipation") carries the
            # elastic acceleration of u; the step before it carried the total one (with
            # the damping force), which would continue with a wrong first step.
            a_el = sim.a.copy()  # the constructor's elastic acceleration of state/u
            scale = float(np.max(np.abs(a_el))) if n else 0.0
            err = float(np.max(np.abs(np.asarray(st["a"], float) - a_el))) if n else 0.0
            if err > RESTORE_A_RTOL * scale + 1e-300:
                raise ValueError(
                    f"state/a is not the elastic acceleration of state/u (max difference "
                    f"{err:.3g} m/s^2 of {scale:.3g}; allowed {RESTORE_A_RTOL:g} of it): a "
                    f"damped run saved by an earlier 0.1.0 development version (before "
                    f"dissipation became a split step) cannot be continued; run it again")
        sim.a[:] = st["a"]
        if "dissipated" in st:
            sim._dis[:] = st["dissipated"]
        sim._p0 = float(at.get("dissipation_rate0", 0.0))
        sim.energy0 = float(at["energy0"])
        if "delta_expected" in st and "dt_default" in at:
            d = np.asarray(st["delta_expected"], float)
            if d.shape != (n + 1,):
                raise ValueError(f"state/delta_expected must have shape ({n + 1},)")
            sim.time_step = dataclasses.replace(
                sim.time_step, delta_expected=d, default=float(at["dt_default"]),
                stable=stable_dt(sim.chain, d, law=sim.law, drag=sim.drag))
        if "dt_source" in at:  # how dt was chosen (and the estimate of an rtol run)
            sim.time_step = dataclasses.replace(sim.time_step, source=str(at["dt_source"]))
        if "rtol" in at and math.isfinite(float(at["rtol"])):
            sim.time_step = dataclasses.replace(
                sim.time_step, rtol=float(at["rtol"]), error_estimate=float(at["rtol_estimate"]),
                order=float(at["rtol_order"]), probe_steps=int(at["rtol_probe_steps"]),
                maxima=str(at.get("rtol_maxima", "")) or None)
        sim._default_threshold = float(at["default_threshold"])
        sim._pending = list(saved.pending)
        rec = saved.record
        rec.check(n, saved.recording)
        refined = rec.vmax_refined is not None
        if refined and sim.kernels.velocity_dependent:
            raise ValueError("record/vmax_refined with a dissipative law or drag: refined "
                             "maxima need forces that depend on positions only")
        if refined != sim.kernels.refined_maxima:  # (the kernels of the saved run)
            sim.kernels = K.make_kernels(sim.law, sim.drag > 0,
                                         sim.recording.strain_maxima, refined)
        sim.record = rec
        return sim

    # ------------------------------------------------------------------ running
    def run(self, t_end: float | None = None, *, until=None, max_steps: int | None = None,
            progress: bool = True) -> RunInfo:
        """Integrate until ``t_end`` (s), the event ``until``, or ``max_steps`` steps.

        Parameters
        ----------
        t_end : float, optional
            Absolute end time, s (>= present time).
        until : WaveAt, AtTime, int or float, optional
            Stop when this event happens (an int is a grain: :class:`WaveAt`); a snapshot
            labelled with the event is taken there.
        max_steps : int, optional
            Upper bound on the steps of this call.  With only ``until`` the run is
            unbounded (it stops with RuntimeError only if every grain comes to rest):
            give ``t_end`` or ``max_steps`` as a safety bound.
        progress : bool
            Show a progress bar towards the stop condition (grains to the ``WaveAt``
            grain, else simulated time; :class:`discrete.progress.RunProgress`) for runs
            longer than a second, and say so when the kernels are being compiled.

        Returns
        -------
        RunInfo
            Steps, end time, what stopped the run, and the relative energy drift.
        """
        # a NaN or overflow is this object's to detect and report (InstabilityError),
        # whatever numpy error state the caller has set
        with np.errstate(invalid="ignore", over="ignore"):
            return self._run(t_end, until=until, max_steps=max_steps, progress=progress)

    def _run(self, t_end, *, until, max_steps, progress) -> RunInfo:
        n = self.chain.n
        if t_end is None and until is None and max_steps is None:
            raise ValueError("give t_end (s), until (event) or max_steps")
        stop_event = None
        if until is not None:
            stop_event = as_event(until)
            check_event(stop_event, n)
        limit = t_step = math.inf
        if t_end is not None:
            if not math.isfinite(float(t_end)) or float(t_end) < self.t - 0.5 * self.dt:
                raise ValueError(f"t_end must be finite and >= the present time {self.t} s "
                                 f"(got {t_end!r})")
            limit = t_step = self.step_of(float(t_end))
        if max_steps is not None:
            if int(max_steps) != max_steps or max_steps < 0:
                raise ValueError(f"max_steps must be an integer >= 0 (got {max_steps!r})")
            limit = min(limit, self.steps + int(max_steps))
        events = list(self._pending) + ([stop_event] if stop_event is not None else [])
        e_start, es_start = self._monitor()
        drift = [0.0, 0.0]
        rec = self.recording
        s_idx = self._ts_grains
        s_every = int(rec.series_every)
        ts_buf = np.zeros((self.chunk // s_every + 1, s_idx.size, 4))
        # energy-grid rows inside a chunk are the kernel's (no kernel call per row); a
        # vertical chain's rows carry the body-force energy of every grain: per chunk
        e_every = int(rec.energy_every or 0)
        e_kernel = e_every > 0 and not self.chain.gravity
        c = int(self.record.energy_coarsen)
        e_cols = -(-n // c) if e_kernel else 1
        no_rows = (np.empty((0, e_cols)), np.empty((0, e_cols)))
        erow = (e_every if e_kernel else 0, c, *no_rows, self.chain.mass)
        # the rows up to t_end, stored once: a run cut into segments (run_segmented,
        # max_steps per call, t_end in each) reserves them in its first call, and the
        # later calls find the room (the rows at the multiples of e_every in
        # (steps, bound]; the end row is _energy_row's)
        bound = t_step if math.isfinite(t_step) else limit
        if e_kernel and math.isfinite(bound):
            self.record.energy.reserve(
                max(0, int(bound) // e_every - self.steps // e_every), e_cols)
        vmax = self.record.vmax if rec.maxima else np.zeros(n)
        umax = self.record.umax if rec.maxima else np.zeros(n)
        rmax = self.record.overlap_max if rec.strain_maxima else np.zeros(n + 1)
        waves = [e for e in events if isinstance(e, WaveAt)]
        watch = np.array([e.grain for e in waves], dtype=np.int64)
        wthr = np.array([self._default_threshold if e.threshold is None else e.threshold
                         for e in waves], dtype=float)
        wmax = np.array([self.v[g] for g in watch], dtype=float)
        start_steps = self.steps
        bar = RunProgress(self, t_end=t_end, until=stop_event,
                          step_limit=None if max_steps is None else limit, enabled=progress)
        stopped_by = "t_end" if t_end is not None else "max_steps"
        try:
            while True:
                # time events due now
                for e in [e for e in events if isinstance(e, AtTime)]:
                    if self.steps >= self.step_of(e.t):
                        self._fire(e, events)
                        if e is stop_event:
                            stopped_by = e.label
                if stopped_by != "t_end" and stopped_by != "max_steps":
                    break
                if self.steps >= limit:
                    break
                nsteps = int(min(self.chunk, limit - self.steps))
                for e in events:
                    if isinstance(e, AtTime):
                        nsteps = min(nsteps, max(self.step_of(e.t) - self.steps, 1))
                nsteps = min(nsteps, self._until_multiple(rec.monitor_every))
                if e_every and (not e_kernel or self._lo < 0):
                    nsteps = min(nsteps, self._until_multiple(e_every))
                if self._lo < 0:
                    if waves:
                        raise RuntimeError("every grain is at rest in equilibrium: the "
                                           f"events {[e.label for e in waves]} cannot happen")
                    if s_idx.size:  # nothing moves: still sample the series
                        nsteps = min(nsteps, self._until_multiple(s_every))
                    self.steps += nsteps
                    if s_idx.size and self.steps % s_every == 0:
                        self._append_rows(self._series_row(),
                                          np.array([self.t0 + self.steps * self.dt]))
                else:
                    if e_kernel:  # the kernel writes the chunk's rows (each row zeroed
                        # by it) straight into the record's storage, no copy: exactly
                        # the multiples of e_every in (steps, steps + nsteps) (the
                        # chunk's last step's row is _energy_row's, after the chunk)
                        e_rows = (self.steps + nsteps - 1) // e_every - self.steps // e_every
                        erow = (e_every, c, *self.record.energy.block(e_rows, e_cols),
                                self.chain.mass)
                    try:
                        done, rows, fired, erows = self._chunk(nsteps, vmax, umax, rmax,
                                                               watch, wmax, wthr, ts_buf, erow)
                    except BaseException:
                        if e_kernel:  # (no row taken: the grid stays readable)
                            self.record.energy.commit(())
                        raise
                    if e_kernel:  # the rows at the multiples of e_every inside the chunk
                        if erows > e_rows or (done == nsteps and erows != e_rows):
                            raise RuntimeError(f"the kernel wrote {erows} energy rows in "
                                               f"{done} steps from step {self.steps}, "
                                               f"expected {e_rows}")  # (never silent)
                        first = (self.steps // e_every + 1) * e_every
                        self.record.energy.commit(
                            self.t0 + (first + e_every * np.arange(erows)) * self.dt)
                    phase = self.steps % s_every
                    if rows:
                        first = self.steps + (s_every - phase if phase else s_every)
                        steps_r = first + s_every * np.arange(rows)
                        self._append_rows(ts_buf[:rows].copy(), self.t0 + steps_r * self.dt)
                    self.steps += done
                    if not np.isfinite(self.v[self._lo:self._hi + 1]).all():
                        raise self._instability("non-finite state (NaN/inf)")
                    self._shrink()
                    if fired >= 0:
                        ev = waves[fired]
                        self._fire(ev, events)
                        keep = [q for q in range(len(waves)) if q != fired]
                        waves = [waves[q] for q in keep]
                        watch, wmax, wthr = watch[keep], wmax[keep], wthr[keep]
                        if ev is stop_event:
                            stopped_by = ev.label
                            break
                bar.update()
                if self.steps % rec.monitor_every == 0 and self.steps < limit:
                    self._check(e_start, es_start, drift)
                self._energy_row()
        finally:
            bar.close()
            if rec.maxima:
                np.maximum(umax, self.u, out=umax)
        self._check(e_start, es_start, drift)
        if stopped_by in ("t_end", "max_steps"):  # no event: which bound ended the run
            stopped_by = "t_end" if self.steps >= t_step else "max_steps"
        return RunInfo(self.steps - start_steps, self.t, stopped_by, drift[0], drift[1])

    def _chunk(self, nsteps, vmax, umax, rmax, watch, wmax, wthr, ts_buf, erow
               ) -> tuple[int, int, int, int]:
        """One kernel call of up to ``nsteps`` steps on the window.

        Returns (steps, series rows, fired, energy rows written into ``erow``'s buffer).
        """
        rec = self.recording
        r = self.record
        refine = rec.maxima and r.vmax_refined is not None
        if refine != self.kernels.refined_maxima:  # (never silently unrefined)
            raise RuntimeError(f"the record {'has' if refine else 'lacks'} refined maxima "
                               f"but the kernels were built "
                               f"{'without' if refine else 'with'} them")
        k0 = float(self._kick[0])
        peak = ((refine, r.peak_state, r.vmax_refined, r.vmax_time, self.t0, k0) if refine
                else (False, np.zeros((K.PEAK_ROWS, 0)), np.zeros(0), np.zeros(0), self.t0,
                      k0))
        plain = self._plain_only()
        if plain:  # no parallel region: numba's thread count is neither read nor set
            nthreads = threads0 = 1
        else:
            nthreads, nsteps = self._tune_choose(nsteps)
            threads0 = numba.get_num_threads()
        clock = time.perf_counter()
        if nthreads != threads0:  # (setting it costs ~15 µs per call)
            numba.set_num_threads(nthreads)
        try:
            done, rows, fired, lo, hi, erows = self._kernel(nthreads)(
                (self.u, self.v, self.a, self._dis), self._constants(), self._p,
                self.wall_left, self.wall_right, self.dt, self._drift, self._kick, nsteps,
                self._lo, self._hi, vmax, umax, rmax, rec.maxima, rec.strain_maxima, watch,
                wmax, wthr, self._ts_grains, int(rec.series_every), self.steps, ts_buf,
                (nthreads, self.min_parallel, self.block_steps, TILE_GRAINS,
                 SERIAL_BLOCK_MIN_GRAINS), erow, peak)
        finally:
            if nthreads != threads0:
                numba.set_num_threads(threads0)
        if not plain:
            self._tune_record(nthreads, nsteps, done, lo, hi, clock)
        self._lo, self._hi = lo, hi
        return done, rows, fired, erows

    @property
    def threads(self) -> int:
        """Threads of the kernel (``threads`` of the constructor; None: numba's count).

        numba's count is read when first needed (a chain large enough for the blocked
        kernel, :meth:`_plain_only`): reading it starts numba's threading layer.
        """
        if self._threads is None:
            self._threads = int(numba.get_num_threads())
        return self._threads

    def _can_block(self, several: bool) -> bool:
        """Whether the blocked kernel is chosen, on several threads (``several``) or one.

        Only for chains of at least ``min_parallel`` grains on several threads, or of
        :data:`SERIAL_BLOCK_MIN_GRAINS` (and a law with a blocked kernel, blocking on).
        """
        n = self.chain.n
        return self.block_steps > 0 and self.kernels.run_blocked is not None and (
            (several and n >= self.min_parallel) or n >= SERIAL_BLOCK_MIN_GRAINS)

    def _plain_only(self) -> bool:
        """Whether every chunk runs the plain kernel, whatever the threads.

        The plain kernel (``Kernels.run_steps``) has no parallel region and reads no
        thread count: :meth:`_can_block` with ``threads`` None (numba's count, not read)
        or > 1 counted as several.
        """
        return not self._can_block(self._threads is None or self._threads > 1)

    @property
    def kernel(self):
        """The compiled kernel (numba dispatcher) the next chunk will run on all threads."""
        return self.kernels.run_steps if self._plain_only() else self._kernel(self.threads)

    def _kernel(self, nthreads: int):
        """The blocked kernel if the chain is large enough to ever block, else the plain one.

        (Bitwise the same results; the plain one compiles in a fraction of the time, so
        a small run never compiles the blocked kernel, :mod:`discrete.kernels`.)
        """
        return self.kernels.run_blocked if self._can_block(nthreads > 1) else \
            self.kernels.run_steps

    # ------------------------------------------------------------------ threads
    def _tune_choose(self, nsteps: int) -> tuple[int, int]:
        """Threads for the next chunk (and its length), measured where it pays.

        With ``threads=None`` and a window of at least ``min_parallel`` grains both
        modes are timed (grain-steps per second, exponential average) and the faster is
        used; every ``_TUNE_PROBE``-th chunk re-measures the other one on a short chunk
        (1/8 of the steps), so a load change on the machine (other processes taking a
        core) switches back to one thread.  Results do not depend on the choice.
        """
        nt = self.threads
        if (nt == 1 or not self._auto_threads or self.block_steps == 0
                or self._hi - self._lo + 1 < self.min_parallel):
            return nt, nsteps
        rates = self._rates
        self._tune_count += 1
        if rates.get(nt) is None:
            return nt, nsteps
        if rates[1] is None:
            return 1, max(1, nsteps // 8)
        best = nt if rates[nt] >= rates[1] else 1
        if self._tune_count % _TUNE_PROBE == 0:
            return (1 if best == nt else nt), max(1, nsteps // 8)
        return best, nsteps

    def _tune_record(self, nthreads: int, nsteps: int, done: int, lo: int, hi: int,
                     clock: float) -> None:
        if not self._auto_threads or self.threads == 1 or done < 16:
            return
        el = time.perf_counter() - clock
        if el <= 0:
            return
        rate = done * (hi - lo + 1) / el
        old = self._rates.get(nthreads)
        self._rates[nthreads] = rate if old is None else 0.5 * (old + rate)

    def _series_row(self) -> np.ndarray:
        g = self._ts_grains
        r = self.overlaps()
        return np.stack([self.u[g], self.v[g], r[g], r[g + 1]], axis=-1)[None]

    # ------------------------------------------------------------------ sensors
    def _sampled_grains(self) -> np.ndarray:
        """Grains the kernel samples: the series grains, then those the sensors need.

        A sensor at grain g reads the overlaps of its two contacts (and, for velocity-
        dependent forces, the velocities of g-1, g+1); a wall force that of the end grain.
        """
        rec, n = self.recording, self.chain.n
        extra = []
        for g in rec.sensors:
            extra.append(int(g))
            if self.kernels.velocity_dependent:
                extra += [x for x in (int(g) - 1, int(g) + 1) if 0 <= x < n]
        if rec.wall_forces:
            extra += [0, n - 1]
        return np.r_[np.asarray(rec.series_grains, dtype=np.int64),
                     np.asarray(extra, dtype=np.int64)].astype(np.int64)

    def _append_rows(self, rows: np.ndarray, t: np.ndarray) -> None:
        """Append sampled rows (R, S, 4) at times t: the series, and the sensor forces."""
        rec = self.record
        ns = rec.series_grains.size
        rec.series_t.extend(np.asarray(t, float).tolist())
        rec.series.append(rows[:, :ns])
        if rec.sensor_grains.size or rec.wall_forces:
            sensors, walls = self._sensor_forces(rows)
            if rec.sensor_grains.size:
                rec.sensor_force.append(sensors)
            if rec.wall_forces:
                rec.wall_force.append(walls)

    def _sensor_forces(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Sensor readings (R, S) and wall forces (R, 2) from sampled rows, N.

        A sensor grain reads the mean of its two contact forces (an embedded sensor
        particle; Daraio, Nesterenko, Herbold & Jin, Phys. Rev. E 73 (2006) 026610); a
        wall the force of its contact.  Total forces F(r, ṙ) of the law (static part
        included), from the synchronous sampled state.
        """
        col = {}
        for q, g in enumerate(self._ts_grains):
            col.setdefault(int(g), q)
        n, k, law = self.chain.n, self._k, self.law

        def vel(g):
            return rows[:, col[g], 1] if 0 <= g < n and g in col else 0.0

        out = np.empty((rows.shape[0], self.record.sensor_grains.size))
        for s, g in enumerate(self.record.sensor_grains):
            g = int(g)
            vg = rows[:, col[g], 1]
            fl = law.force(rows[:, col[g], 2], vel(g - 1) - vg, k[g])
            fr = law.force(rows[:, col[g], 3], vg - vel(g + 1), k[g + 1])
            out[:, s] = 0.5 * (fl + fr)
        walls = np.zeros((rows.shape[0], 2))
        if self.record.wall_forces:
            walls[:, 0] = law.force(rows[:, col[0], 2], -rows[:, col[0], 1], k[0])
            walls[:, 1] = law.force(rows[:, col[n - 1], 3], rows[:, col[n - 1], 1], k[n])
        return out, walls

    def _until_multiple(self, every: int) -> int:
        return every - self.steps % every

    def _fire(self, e, events: list) -> None:
        self._snapshot(e.label)
        events.remove(e)
        if e in self._pending:
            self._pending.remove(e)

    def _check(self, e_start: float, es_start: float, drift: list) -> None:
        if self.steps == 0:
            return
        e, es = self._monitor()
        if not (math.isfinite(e) and math.isfinite(es)):
            raise self._instability("non-finite state (NaN/inf)")
        r = self.record
        e0 = abs(e_start) if e_start != 0 else 1.0
        es0 = abs(es_start) if es_start != 0 else 1.0
        drift[0] = max(drift[0], abs(e - e_start) / e0)
        drift[1] = max(drift[1], abs(es - es_start) / es0)
        first = r.monitor_shadow[0] + r.monitor_dissipated[0]
        total = abs(es - first) / (abs(first) if first else 1.0)
        if total > self.drift_tolerance:
            what = ("energy balance E + D = E(0)" if self.kernels.velocity_dependent
                    else "(modified) energy")
            cause = (f"relative drift {total:.3g} of the {what} beyond the tolerance "
                     f"{self.drift_tolerance:g}")
            floor = self.roundoff_floor()
            drift_j = abs(es - first)
            if drift_j <= floor:  # round-off of the static energy, not an instability
                raise InstabilityError(
                    f"{cause} at t = {self.t:.6g} s (step {self.steps}): this is round-off, "
                    f"not a too large dt. The drift {drift_j:.3g} J is below the round-off "
                    f"floor {floor:.3g} J of the total energy (ε·Σ F(δ0)·δ0, the static "
                    f"contact energy the overlaps carry), and the wave carries only "
                    f"{abs(first):.3g} J, so the relative drift grows as 1/amplitude² and a "
                    f"smaller dt makes it worse (more steps). Give the wave more energy "
                    f"(a larger amplitude, e.g. v0) or less static load (precompression, "
                    f"gravity), or allow drift_tolerance >= {floor / abs(first or 1.0):.2g}")
            raise self._instability(cause)

    def roundoff_floor(self) -> float:
        r"""Round-off floor of the energy monitor, J: ε Σ_j |F(δ0_j)| δ0_j.

        Each overlap r_j = δ0_j + (u_{j-1} - u_j) is a double near δ0_j, resolved to
        about ε δ0_j (ε the machine epsilon), and the static force F(δ0_j) times that is
        the energy the contact's wave energy U(r_j) - U(δ0_j) ≈ F(δ0_j)(r_j - δ0_j) + …
        cannot resolve (docs/physics.md §13); the sum over the contacts
        bounds the round-off of the monitored total, independent of the wave's
        amplitude and of dt (measured: the drift of a v0 = 1e-6 m/s impact on δ0/d =
        1e-3 stays at ~2 % of this bound at every dt).  Zero without static load.
        """
        d0 = np.asarray(self._d0, float)
        f0 = np.abs(np.asarray(self.law.elastic(d0, self._k), float))
        return float(np.finfo(float).eps * np.sum(f0 * d0))

    def _repr_html_(self) -> str:
        """Jupyter display: parameters and state with units (:mod:`discrete.display`)."""
        from .display import simulation_html

        return simulation_html(self)

    def to_xarray(self):
        """The recorded data as an :class:`xarray.Dataset` (:func:`discrete.io.to_xarray`)."""
        from .io import to_xarray

        return to_xarray(self)

    @property
    def energy_drift(self) -> float:
        """Max |(E + D) - E(0)|/|E(0)| over all monitor samples since the start."""
        r = self.record
        e = np.asarray(r.monitor_energy) + np.asarray(r.monitor_dissipated)
        return float(np.max(np.abs(e - self.energy0)) / (abs(self.energy0) or 1.0))
