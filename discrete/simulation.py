r"""The :class:`Simulation` object: a chain, its state, the time step and the recording.

Default time step
-----------------
The linearised stiffness of contact j at overlap δ is :math:`K_j = \tfrac32 k_j
\delta^{1/2}` (N/m, derivative of Eq. 1) and its two-body frequency
:math:`\omega_j = \sqrt{K_j (1/m_{j-1} + 1/m_j)}` (rad/s; one mass at a wall).  With
:math:`\delta` the *largest expected overlap* — the present overlap with the largest
single-grain kinetic energy :math:`E_1 = \max_i \tfrac12 m_i v_i^2` added,
:math:`\hat\delta_j = ([r_j]_+^{5/2} + \tfrac52 E_1/k_j)^{2/5}` (J, from the contact
energy (2/5) k δ^{5/2}) — the default is

.. math:: \Delta t = f\, \frac{2\pi}{\max_j \omega_j},\qquad f = 0.002 .

Velocity Verlet is linearly stable for :math:`\Delta t < 2/\omega_{\rm lat}` with
:math:`\omega_{\rm lat}^2 \le \max_i 2(K_i + K_{i+1})/m_i` (Gershgorin), i.e.
f < 0.225 for a uniform chain.  The dt study (``tests/discrete/test_dt_study.py``):
observables converge at second order (fitted slope ≈ 2).  The most dt-sensitive case
is the impact on a precompressed chain (δ0/d = 1e-3): its settled v̄max/v0 is
0.08241 / 0.08224 / 0.08220 at f = 0.01 / 0.005 / 0.0025 (relative error
≈ 2.9e-3 (f/0.01)²); f = 0.002 makes it ~1e-4.  Without precompression (f = 0.01:
error 7e-5) and for smooth solitary waves (cut or exact waves: energy conserved to
~1e-11 at f = 0.01) much larger steps would do.  For the paper's steel grains
(d = 5 mm, v0 = 1 m/s) f = 0.002 gives dt ≈ 4.4e-8 s, ~40× the paper's dt = 1e-9 s.

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
(``threads``; bitwise identical results).  Measured on the 2-core development machine
(``benchmarks/kernel.py``, recording on): 2.4–2.5e9 grain-updates/s on one core at 1e4
and 1e5 grains (10× the NumPy step), 4.0–4.7e9 on two cores at 5e4.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numba
import numpy as np

from . import kernels as K
from .chain import Chain
from .integrators import get_integrator
from .progress import RunProgress
from .recording import AtTime, Record, Recording, Snapshot, WaveAt, as_event, check_event
from .reference import overlaps as _overlaps

__all__ = ["Simulation", "State", "RunInfo", "InstabilityError", "default_dt", "stable_dt",
           "expected_overlaps", "DT_FRACTION", "PARALLEL_MIN_GRAINS"]

DT_FRACTION = 0.002
"""Default dt as a fraction of the shortest linearised contact period (module docstring)."""

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
    """The integration went unstable (NaN or energy drift beyond the tolerance)."""


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
    """max |E - E(start of run)| / |E(start of run)| over the run's monitor samples."""
    shadow_drift: float
    """The same for velocity Verlet's modified energy (secular drift only)."""


def expected_overlaps(chain: Chain, u, v, wall_left=0.0, wall_right=0.0) -> np.ndarray:
    """Largest expected overlap of each contact, m (module docstring)."""
    r = np.maximum(_overlaps(np.asarray(u, float), chain.delta0, wall_left, wall_right), 0.0)
    e1 = float(np.max(0.5 * chain.mass * np.asarray(v, float) ** 2))
    with np.errstate(divide="ignore"):
        extra = np.where(chain.k > 0, 2.5 * e1 / np.where(chain.k > 0, chain.k, 1.0), 0.0)
    return (r**2.5 + extra) ** 0.4


def _contact_omega(chain: Chain, delta: np.ndarray) -> np.ndarray:
    """ω_j = √(K_j (1/m_{j-1} + 1/m_j)), K_j = (3/2) k_j δ_j^{1/2}, rad/s."""
    inv = np.zeros(chain.n + 1)
    inv[:-1] += 1.0 / chain.mass
    inv[1:] += 1.0 / chain.mass
    return np.sqrt(1.5 * chain.k * np.sqrt(delta) * inv)


def default_dt(chain: Chain, u=None, v=None, wall_left=0.0, wall_right=0.0, *,
               fraction: float = DT_FRACTION) -> float:
    """Default time step f·2π/max ω_j at the largest expected overlap, s (module docstring)."""
    u = np.zeros(chain.n) if u is None else u
    v = np.zeros(chain.n) if v is None else v
    w = float(np.max(_contact_omega(chain, expected_overlaps(chain, u, v, wall_left, wall_right))))
    if w == 0:
        raise ValueError("cannot choose dt: no contact is loaded and nothing moves; give dt")
    return fraction * 2.0 * math.pi / w


def stable_dt(chain: Chain, delta) -> float:
    """Largest linearly stable Verlet step 2/ω_lat at overlaps ``delta`` (m), s.

    ω_lat² ≤ max_i (K_i + K_{i+1})·2/m_i (Gershgorin bound on M⁻¹K; exact for a
    uniform chain, where ω_lat = 2√(K/m) is the zone-edge frequency).
    """
    kk = 1.5 * chain.k * np.sqrt(np.maximum(delta, 0.0))
    w2 = np.max(2.0 * (kk[:-1] + kk[1:]) / chain.mass)
    return 2.0 / math.sqrt(w2) if w2 > 0 else math.inf


class Simulation:
    """Velocity-Verlet integration of a :class:`Chain` (paper Eq. 2), pyro2 style.

    Parameters
    ----------
    chain : Chain
        The chain.
    u, v : (N,) arrays, optional
        Initial displacements from static equilibrium (m) and velocities (m/s); zero.
    dt : float, optional
        Time step, s (> 0); default :func:`default_dt`.
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
        Relative drift of velocity Verlet's modified energy (:func:`kernels.shadow_correction`)
        that counts as an instability.  The modified energy has no O(dt²) oscillation, so
        its drift measures only accumulated error (1e-8–1e-5 in sane runs).
    chunk : int
        Largest number of steps per kernel call.
    integrator : str
        Time-stepping method (:data:`discrete.integrators.INTEGRATORS`): ``"verlet"``
        (velocity Verlet, the paper's; default), ``"yoshida4"``, ``"blanes_moan4"``.
    threads : int, optional
        Threads for the kernel, used only while the active window has at least
        :data:`PARALLEL_MIN_GRAINS` grains.  None (default): all numba threads
        (``numba.get_num_threads()``), where they are measured to be faster than one
        (the machine may be busy; :meth:`_tune_choose`); n: n threads; 1: one.  Results
        are bitwise identical for every choice (:mod:`discrete.kernels`).  Threads work
        through the temporally blocked kernel, which is not used while a time-series
        grain sampled in the block lies within reach of the active window.
    check_dt : bool
        Reject a ``dt`` above the largest linearly stable step :func:`stable_dt` at the
        expected overlaps (ValueError naming the allowed range); False only for tests
        of the run-time instability detection.
    """

    def __init__(self, chain: Chain, u=None, v=None, *, dt: float | None = None,
                 wall_left: float = 0.0, wall_right: float = 0.0,
                 record: Recording | None = None, t: float = 0.0, active_window: bool = True,
                 drift_tolerance: float = 1e-4, chunk: int = 4096,
                 integrator: str = "verlet", threads: int | None = None,
                 check_dt: bool = True) -> None:
        if not isinstance(chain, Chain):
            raise ValueError(f"chain must be a Chain (got {type(chain).__name__})")
        n = chain.n
        self.chain = chain
        self.u = self._vec("u", u, n)
        self.v = self._vec("v", v, n)
        for name, w in (("wall_left", wall_left), ("wall_right", wall_right), ("t", t)):
            if not math.isfinite(float(w)):
                raise ValueError(f"{name} must be finite (got {w!r})")
        self.wall_left, self.wall_right = float(wall_left), float(wall_right)
        self.recording = Recording() if record is None else record
        self.recording.validate(n)
        self._delta_expected = expected_overlaps(chain, self.u, self.v, self.wall_left,
                                                 self.wall_right)
        w = float(np.max(_contact_omega(chain, self._delta_expected)))
        method = get_integrator(integrator)
        self.dt_default = method.dt_fraction * 2.0 * math.pi / w if w > 0 else math.inf
        if dt is None:
            dt = default_dt(chain, self.u, self.v, self.wall_left, self.wall_right,
                            fraction=method.dt_fraction)
        dt = float(dt) if isinstance(dt, int | float | np.floating) else dt
        if not isinstance(dt, float) or not math.isfinite(dt) or dt <= 0:
            raise ValueError(f"dt must be a finite number > 0 s (got {dt!r})")
        if check_dt:
            limit = stable_dt(chain, self._delta_expected)
            if dt > limit:
                raise ValueError(
                    f"dt = {dt:.4g} s is above the largest linearly stable time step "
                    f"{limit:.4g} s at the expected overlaps (Gershgorin bound 2/ω_lat of "
                    f"velocity Verlet); allowed range (0, {limit:.4g}] s, default "
                    f"{self.dt_default:.4g} s (check_dt=False skips this check)")
        self.dt = dt
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
        if threads is None:
            self.threads = int(numba.get_num_threads())
            self.min_parallel = PARALLEL_MIN_GRAINS
        else:
            nmax = int(numba.config.NUMBA_NUM_THREADS)
            if int(threads) != threads or not 1 <= threads <= nmax:
                raise ValueError(f"threads must be None or an integer in [1, {nmax}] "
                                 f"(got {threads!r})")
            self.threads, self.min_parallel = int(threads), PARALLEL_MIN_GRAINS
        self._rates = {1: None, self.threads: None}
        self.active_window = bool(active_window)
        # blocks shrink the window to the active grains: not with active_window=False
        # blocks shrink the window to the active grains, and carry the threads: not with
        # active_window=False
        self.block_steps = max(4, BLOCK_SUBSTEPS // method.stages) if active_window else 0
        self.t0 = float(t)
        self.steps = 0
        self._inv_m = 1.0 / chain.mass
        self._f0 = chain.f0
        self._k, self._d0 = chain.k, chain.delta0
        self._runs = K.chain_runs(self._inv_m, self._k, self._d0, self._f0)
        self.a = np.zeros(n)
        K.accelerations(self.u, self.a, self._inv_m, self._k, self._d0, self._f0,
                        self.wall_left, self.wall_right, 0, n - 1)
        self._lo, self._hi = 0, n - 1
        self._shrink()
        rec = self.recording
        self.record = Record(series_grains=np.asarray(rec.series_grains, dtype=np.int64),
                             energy_coarsen=int(rec.energy_coarsen))
        if rec.maxima:
            self.record.vmax = self.v.copy()
            self.record.umax = self.u.copy()
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

    def _shrink(self) -> None:
        if not self.active_window:
            self._lo, self._hi = 0, self.chain.n - 1
            return
        if self._lo < 0:
            return
        self._lo, self._hi = K.active_window(self.u, self.v, self._k, self.wall_left,
                                             self.wall_right, self._lo, self._hi)

    @property
    def t(self) -> float:
        """Present time t0 + steps·dt, s."""
        return self.t0 + self.steps * self.dt

    @property
    def state(self) -> State:
        """A copy of the present state."""
        return State(self.u.copy(), self.v.copy(), self.t, self.wall_left, self.wall_right)

    @property
    def window(self) -> tuple[int, int]:
        """The active window (lo, hi); (-1, -1) when every grain is at rest in equilibrium."""
        return self._lo, self._hi

    def overlaps(self) -> np.ndarray:
        """Present contact overlaps δ0_j + (u_{j-1} - u_j), m (Eq. 1)."""
        return _overlaps(self.u, self._d0, self.wall_left, self.wall_right)

    def energy(self) -> float:
        """Total wave energy Σ ½mv² + Σ (2/5)k([r]_+^{5/2} - δ0^{5/2}), J (docs/physics.md §6)."""
        if self._lo < 0:
            return 0.0
        ek = np.empty(self.chain.n)
        ep = np.empty(self.chain.n)
        tk, tp = K.grain_energies(self.u, self.v, self.chain.mass, self._k, self._d0,
                                  self.wall_left, self.wall_right, self._lo, self._hi, ek, ep)
        return tk + tp

    def grain_energy(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-grain kinetic and potential energy (half of each contact), J (Fig. 8)."""
        ek = np.zeros(self.chain.n)
        ep = np.zeros(self.chain.n)
        if self._lo >= 0:
            K.grain_energies(self.u, self.v, self.chain.mass, self._k, self._d0,
                             self.wall_left, self.wall_right, self._lo, self._hi, ek, ep)
        return ek, ep

    def _monitor(self) -> tuple[float, float]:
        e = self.energy()
        sh = 0.0
        if self._lo >= 0 and self.integrator == "verlet":
            sh = K.shadow_correction(self.u, self.v, self.a, self.chain.mass, self._k,
                                     self._d0, self.wall_left, self.wall_right,
                                     self._lo, self._hi)
        es = e + self.dt**2 * sh
        r = self.record
        r.monitor_t.append(self.t)
        r.monitor_energy.append(e)
        r.monitor_shadow.append(es)
        return e, es

    def _energy_row(self) -> None:
        every = self.recording.energy_every
        if every is None or self.steps % every:
            return
        ek, ep = self.grain_energy()
        c = self.record.energy_coarsen
        if c > 1:
            starts = np.arange(0, ek.size, c)
            ek, ep = np.add.reduceat(ek, starts), np.add.reduceat(ep, starts)
        self.record.energy_t.append(self.t)
        self.record.energy_kinetic.append(ek)
        self.record.energy_potential.append(ep)

    def _snapshot(self, label: str) -> None:
        if self.record.umax is not None:
            np.maximum(self.record.umax, self.u, out=self.record.umax)
        self.record.snapshots.append(Snapshot(label, self.t, self.steps, self.u.copy(),
                                              self.v.copy(), self.overlaps()))

    def _instability(self, cause: str) -> InstabilityError:
        # quote the bound at the expected overlaps of the initial state: after a blow-up
        # the present overlaps are meaningless (they gave ~1e-78 s)
        dmax = self._delta_expected
        return InstabilityError(
            f"{cause} at t = {self.t:.6g} s (step {self.steps}) with dt = {self.dt:.4g} s; "
            f"likely cause: dt too large for the contact stiffness. The largest linearly "
            f"stable dt at the expected overlaps is about {stable_dt(self.chain, dmax):.4g} s "
            f"(Gershgorin bound 2/ω_lat, velocity Verlet); the default "
            f"{get_integrator(self.integrator).dt_fraction}·2π/ω_max is "
            f"{self.dt_default:.4g} s")

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
            limit = t_step = self._step_of(float(t_end))
        if max_steps is not None:
            if int(max_steps) != max_steps or max_steps < 0:
                raise ValueError(f"max_steps must be an integer >= 0 (got {max_steps!r})")
            limit = min(limit, self.steps + int(max_steps))
        events = list(self._pending) + ([stop_event] if stop_event is not None else [])
        e_start, es_start = self._monitor()
        drift = [0.0, 0.0]
        rec = self.recording
        s_idx = self.record.series_grains
        s_every = int(rec.series_every)
        ts_buf = np.zeros((self.chunk // s_every + 1, s_idx.size, 4))
        vmax = self.record.vmax if rec.maxima else np.zeros(n)
        umax = self.record.umax if rec.maxima else np.zeros(n)
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
                    if self.steps >= self._step_of(e.t):
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
                        nsteps = min(nsteps, max(self._step_of(e.t) - self.steps, 1))
                nsteps = min(nsteps, self._until_multiple(rec.monitor_every))
                if rec.energy_every is not None:
                    nsteps = min(nsteps, self._until_multiple(rec.energy_every))
                if self._lo < 0:
                    if waves:
                        raise RuntimeError("every grain is at rest in equilibrium: the "
                                           f"events {[e.label for e in waves]} cannot happen")
                    if s_idx.size:  # nothing moves: still sample the series
                        nsteps = min(nsteps, self._until_multiple(s_every))
                    self.steps += nsteps
                    if s_idx.size and self.steps % s_every == 0:
                        self._append_series(self._series_row(), self.steps)
                else:
                    lo, hi = self._lo, self._hi
                    nthreads, nsteps = self._tune_choose(nsteps)
                    clock = time.perf_counter()
                    threads0 = numba.get_num_threads()
                    numba.set_num_threads(nthreads)
                    try:
                        done, rows, fired, lo, hi = K.run_chunk(
                            self.u, self.v, self.a, self._inv_m, self._k, self._d0,
                            self._f0, *self._runs, self.wall_left, self.wall_right, self.dt,
                            self._drift, self._kick, nsteps, lo, hi, vmax, umax, rec.maxima,
                            watch, wmax, wthr, s_idx, s_every, self.steps, ts_buf, nthreads,
                            self.min_parallel, self.block_steps, TILE_GRAINS,
                            SERIAL_BLOCK_MIN_GRAINS)
                    finally:
                        numba.set_num_threads(threads0)
                    self._tune_record(nthreads, nsteps, done, lo, hi, clock)
                    phase = self.steps % s_every
                    if rows:
                        first = self.steps + (s_every - phase if phase else s_every)
                        steps_r = first + s_every * np.arange(rows)
                        self.record.series_t.extend((self.t0 + steps_r * self.dt).tolist())
                        self.record.series.append(ts_buf[:rows].copy())
                    self.steps += done
                    if not np.isfinite(self.v[lo:hi + 1]).all():
                        raise self._instability("non-finite state (NaN/inf)")
                    self._lo, self._hi = lo, hi
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
        if nt == 1 or not self._auto_threads or self._hi - self._lo + 1 < self.min_parallel:
            return nt, nsteps
        rates = self._rates
        self._tune_count += 1
        if rates[nt] is None:
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
        g = self.record.series_grains
        r = self.overlaps()
        return np.stack([self.u[g], self.v[g], r[g], r[g + 1]], axis=-1)[None]

    def _append_series(self, row: np.ndarray, step: int) -> None:
        self.record.series_t.append(self.t0 + step * self.dt)
        self.record.series.append(row)

    def _step_of(self, t: float) -> int:
        """First step whose time is >= t (to within 1e-9 dt)."""
        return max(0, math.ceil((t - self.t0) / self.dt - 1e-9))

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
        scale = abs(e_start) if e_start != 0 else 1.0
        scale_s = abs(es_start) if es_start != 0 else 1.0
        drift[0] = max(drift[0], abs(e - e_start) / scale)
        drift[1] = max(drift[1], abs(es - es_start) / scale_s)
        es0 = self.record.monitor_shadow[0]
        total = abs(es - es0) / (abs(es0) if es0 else 1.0)
        if total > self.drift_tolerance:
            raise self._instability(f"relative drift {total:.3g} of the (modified) energy "
                                    f"beyond the tolerance {self.drift_tolerance:g}")

    @property
    def energy_drift(self) -> float:
        """Max |E - E(0)|/|E(0)| over all monitor samples since the start."""
        e = np.asarray(self.record.monitor_energy)
        return float(np.max(np.abs(e - self.energy0)) / (abs(self.energy0) or 1.0))
