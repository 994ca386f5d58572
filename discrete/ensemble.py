r"""Ensembles: many realisations of a small chain integrated together, and their statistics.

Disorder studies need 10³–10⁵ realisations of chains of a few hundred grains (Martínez,
Kevrekidis & Porter, Phys. Rev. E 93 (2016) 022902).  One :class:`~discrete.Simulation`
per realisation pays its per-step bookkeeping (the active window, the event tests, the
chunk calls) on a 200-grain chain as often as its arithmetic; :func:`run_ensemble`
integrates the realisations together in the batch kernel
(:func:`discrete.kernels.batch_kernel`: arrays realisations × grains, each
realisation's pass over its grains vectorised), each with its own chain, initial state
and time step, and returns per realisation what :meth:`Simulation.run
<discrete.Simulation.run>` would have left — bit for bit the same final state, running
maxima of v and energies — plus the time each grain's maximum was reached (the
arrival time of the wave's peak).

Per-realisation reductions (:func:`amplitude_decay`) and ensemble statistics
(:func:`ensemble_statistics`: mean, quantiles and their uncertainty) turn those into
the numbers of a disorder study: the transmitted amplitude against distance and its
decay length (docs/physics.md §18).

:func:`reference_ensemble` is the plain NumPy reference of the batch kernel
(:func:`discrete.integrators.step` per realisation).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from . import kernels as K
from .integrators import get_integrator
from .integrators import step as numpy_step
from .simulation import InstabilityError, Simulation

__all__ = ["EnsembleResult", "run_ensemble", "reference_ensemble", "default_batch",
           "amplitude_decay", "ensemble_statistics", "nanquantiles", "QUANTILES",
           "BATCH_GRAIN_SLOTS"]

BATCH_GRAIN_SLOTS = 65536
"""Grains × realisations of one kernel call by default (:func:`default_batch`): the
arrays of a call, 8 or 9 doubles per slot (u, v, a, the maximum of v and with
``times`` its time, 1/m, k, δ0, f0), are 4–4.5 MB."""


@dataclass(frozen=True)
class EnsembleResult:
    """Per-realisation results of :func:`run_ensemble`; arrays have the realisation first.

    Attributes
    ----------
    t, dt : (R,) float arrays
        End time and time step of each realisation, s.
    steps : (R,) int array
        Steps taken.
    u, v, a : (R, N) float arrays
        Final displacements (m), velocities (m/s) and accelerations (m/s²).
    vmax : (R, N) float array
        Running maximum of each grain's velocity over the steps, m/s (the transmitted
        amplitude at every grain, :attr:`discrete.Record.vmax`).
    vmax_time : (R, N) float array or None
        Time at which ``vmax`` was reached, s (the end of the step that raised it; the
        start time where it never rose): the arrival time of the wave's peak.  None
        unless asked for (``run_ensemble(..., times=True)``).
    energy0, energy : (R,) float arrays
        Total wave energy at the start and at the end, J
        (:meth:`discrete.Simulation.energy`).
    integrator : str
        The time-stepping method (:mod:`discrete.integrators`).
    """

    t: np.ndarray
    dt: np.ndarray
    steps: np.ndarray
    u: np.ndarray
    v: np.ndarray
    a: np.ndarray
    vmax: np.ndarray
    vmax_time: np.ndarray | None
    energy0: np.ndarray
    energy: np.ndarray
    integrator: str

    @property
    def n_realisations(self) -> int:
        """Number of realisations R."""
        return int(self.steps.size)

    @property
    def energy_error(self) -> np.ndarray:
        """|E(end) - E(0)| / |E(0)| of each realisation (the integrator's energy error)."""
        e0 = np.abs(self.energy0)
        return np.abs(self.energy - self.energy0) / np.where(e0 > 0, e0, 1.0)


def default_batch(n: int) -> int:
    """Realisations per kernel batch for chains of ``n`` grains (:data:`BATCH_GRAIN_SLOTS`).

    About :data:`BATCH_GRAIN_SLOTS` / n, within 8 … 256.
    """
    return int(min(256, max(8, BATCH_GRAIN_SLOTS // max(int(n), 1))))


ALIGN = 64
"""Byte alignment of the batch kernel's arrays: one cache line (64 bytes), so that the
vectorised pass never straddles lines at a random offset."""


def _aligned(x: np.ndarray) -> np.ndarray:
    """A C-contiguous float copy of ``x`` starting on an :data:`ALIGN`-byte boundary.

    The batch kernel's vectorised loads and stores of grain i then do not straddle
    cache lines (when a row's length is a multiple of 8 grains, in every row), which
    NumPy's 16-byte aligned allocations leave to chance.
    """
    x = np.asarray(x, dtype=np.float64)
    buf = np.empty(x.size + ALIGN // 8)
    off = (-buf.ctypes.data % ALIGN) // 8
    out = buf[off:off + x.size].reshape(x.shape)
    out[...] = x
    return out


def _check(sims: Sequence[Simulation]) -> None:
    if not sims:
        raise ValueError("sims must be a non-empty sequence of Simulation")
    first = sims[0]
    for q, s in enumerate(sims):
        if not isinstance(s, Simulation):
            raise ValueError(f"sims[{q}] must be a discrete.Simulation "
                             f"(got {type(s).__name__})")
        if s.chain.n != first.chain.n:
            raise ValueError(f"sims[{q}] has {s.chain.n} grains, sims[0] {first.chain.n}: "
                             "an ensemble's chains have one size")
        if s.law.key() != first.law.key() or s.integrator != first.integrator:
            raise ValueError(f"sims[{q}] has another contact law or integrator than sims[0] "
                             f"({s.law.describe()}, {s.integrator!r})")
        if s.law.dissipative or s.drag > 0:
            raise ValueError(f"sims[{q}]: the ensemble kernel integrates conservative "
                             "forces only (law dissipative or drag > 0 given)")
        if s.steps != 0:
            raise ValueError(f"sims[{q}] has taken {s.steps} steps: an ensemble starts "
                             "from freshly built simulations")
        rec = s.recording
        if (rec.events() or len(rec.series_grains) or rec.energy_every or len(rec.sensors)
                or rec.wall_forces or rec.strain_maxima or s.kernels.refined_maxima):
            raise ValueError(f"sims[{q}].recording asks for more than running maxima "
                             "(snapshots, series, an energy grid, sensors, wall forces, "
                             "strain or refined maxima): run it with Simulation.run")


def _energy(sim: Simulation, u: np.ndarray, v: np.ndarray) -> float:
    """:meth:`Simulation.energy` of the state (u, v) of ``sim``'s chain, J (same arithmetic)."""
    n = sim.chain.n
    ek, ep = np.empty(n), np.empty(n)
    tk, tp = sim.kernels.grain_energies(u, v, sim.chain.mass, sim.chain.k, sim.chain.delta0,
                                        sim.wall_left, sim.wall_right, 0, n - 1, ek, ep)
    if sim.chain.gravity:
        tp -= float(np.dot(sim.chain.body_force, u))
    return tk + tp


def run_ensemble(sims: Sequence[Simulation], t_end: float, *,
                 batch: int | None = None, times: bool = False) -> EnsembleResult:
    """Integrate many realisations of one chain size together until ``t_end`` (s).

    Parameters
    ----------
    sims : sequence of Simulation
        The realisations, freshly built (no step taken), each with its own chain,
        initial state, walls and time step; one grain count, one conservative contact
        law, one integrator, and a recording of running maxima only.  They are not
        changed.
    t_end : float
        End time, s: each realisation takes ``sim.step_of(t_end)`` steps, as
        :meth:`Simulation.run` does.
    batch : int, optional
        Realisations per kernel call (>= 1); default :func:`default_batch`.
    times : bool
        Also record the time at which each grain's maximum was reached
        (``vmax_time``: the arrival time of the peak, to one step): a second select
        per grain in the kernel's pass.

    Returns
    -------
    EnsembleResult
        Per realisation the state, running maxima and energies that ``sim.run(t_end)``
        leaves (bit for bit: ``u``, ``v``, ``a``, ``record.vmax``, ``energy()``), and
        with ``times`` the times of the maxima.

    Raises
    ------
    InstabilityError
        A realisation's final state is not finite (its step too large), as
        :meth:`Simulation.run` raises.
    """
    sims = list(sims)
    _check(sims)
    if not math.isfinite(float(t_end)):
        raise ValueError(f"t_end must be finite (got {t_end!r})")
    if batch is not None and (int(batch) != batch or batch < 1):
        raise ValueError(f"batch must be an integer >= 1 (got {batch!r})")
    n, nr = sims[0].chain.n, len(sims)
    nw = n if times else 0
    b = default_batch(n) if batch is None else int(batch)
    steps = np.array([s.step_of(float(t_end)) for s in sims], dtype=np.int64)
    for q, s in enumerate(sims):
        if float(t_end) < s.t - 0.5 * s.dt:
            raise ValueError(f"t_end = {t_end!r} s is before sims[{q}]'s time {s.t} s")
    kern = K.batch_kernel(sims[0].law)
    method = get_integrator(sims[0].integrator)
    p = K.kernel_params(sims[0].law)
    t0 = np.array([s.t0 for s in sims])
    dt = np.array([s.dt for s in sims])
    coefs = [method.coefficients(h) for h in dt]
    drift = np.array([c[0] for c in coefs])
    kick = np.array([c[1] for c in coefs])
    wl = np.array([s.wall_left for s in sims])
    wr = np.array([s.wall_right for s in sims])
    out = {name: np.empty((nr, n)) for name in ("u", "v", "a", "vmax")}
    tmax = _aligned(np.repeat(t0[:, None], nw, axis=1))
    for lo in range(0, nr, b):
        group = sims[lo:lo + b]
        hi = lo + len(group)

        def stack(get, group=group):
            return _aligned(np.stack([get(s) for s in group]))

        u, v = stack(lambda s: s.u), stack(lambda s: s.v)
        a = _aligned(np.zeros_like(u))
        vmax = _aligned(v)
        k, d0 = stack(lambda s: s.chain.k), stack(lambda s: s.chain.delta0)
        f0 = stack(lambda s: s.kernels.static_forces(s.chain.k, s.chain.delta0, p))
        inv_m = stack(lambda s: 1.0 / s.chain.mass)
        tm = tmax[lo:hi]
        coef = (drift[lo:hi], kick[lo:hi], t0[lo:hi], dt[lo:hi])
        kern((u, v, a, vmax, tm), (inv_m, k, d0, f0), p, (wl[lo:hi], wr[lo:hi]), coef,
             steps[lo:hi])
        bad = ~np.all(np.isfinite(u) & np.isfinite(v), axis=1)
        if bad.any():
            q = lo + int(np.flatnonzero(bad)[0])
            raise InstabilityError(
                f"sims[{q}]: non-finite state (NaN/inf) by t = {t_end} s with dt = "
                f"{sims[q].dt:.4g} s; likely cause: dt too large for the contact stiffness")
        for name, x in (("u", u), ("v", v), ("a", a), ("vmax", vmax)):
            out[name][lo:hi] = x
    energy0 = np.array([s.energy() for s in sims])
    energy = np.array([_energy(s, out["u"][q], out["v"][q]) for q, s in enumerate(sims)])
    return EnsembleResult(t=t0 + steps * dt, dt=dt, steps=steps, energy0=energy0,
                          energy=energy, integrator=method.name,
                          vmax_time=tmax if times else None, **out)


def reference_ensemble(sims: Sequence[Simulation], t_end: float) -> EnsembleResult:
    """Plain NumPy reference of :func:`run_ensemble` (for tests; slow).

    Each realisation is stepped by :func:`discrete.integrators.step` (the NumPy
    reference step: forces from :func:`discrete.reference.accelerations`), the
    running maximum and its time taken after every step on the synchronous velocity.
    Agrees with the kernel to round-off (not bit for bit: another force arithmetic).
    """
    sims = list(sims)
    _check(sims)
    cols = {name: [] for name in ("u", "v", "a", "vmax", "vmax_time")}
    steps, energy = [], []
    for s in sims:
        c = s.chain
        u, v, a = s.u.copy(), s.v.copy(), s.a.copy()
        vmax, tmax = v.copy(), np.full(c.n, s.t0)
        nsteps = s.step_of(float(t_end))
        for j in range(nsteps):
            u, v, a = numpy_step(u, v, a, s.dt, c.mass, c.k, c.delta0, s.wall_left,
                                 s.wall_right, s.integrator, law=s.law)
            up = v > vmax
            vmax = np.where(up, v, vmax)
            tmax = np.where(up, s.t0 + (j + 1) * s.dt, tmax)
        for name, x in (("u", u), ("v", v), ("a", a), ("vmax", vmax), ("vmax_time", tmax)):
            cols[name].append(x)
        steps.append(nsteps)
        energy.append(_energy(s, u, v))
    dt = np.array([s.dt for s in sims])
    st = np.array(steps, dtype=np.int64)
    return EnsembleResult(
        t=np.array([s.t0 for s in sims]) + st * dt, dt=dt, steps=st,
        energy0=np.array([s.energy() for s in sims]), energy=np.array(energy),
        integrator=sims[0].integrator, **{k: np.array(x) for k, x in cols.items()})


# ------------------------------------------------------------------ reductions
def amplitude_decay(vmax, first: int, last: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    r"""Exponential decay rate γ (1/grain) of each realisation's transmitted amplitude.

    A disordered chain scatters the travelling pulse, and its amplitude — the running
    maximum of the grain velocity, :math:`A_i = \max_t v_i(t)` — decays with the
    distance i travelled; over the range where the decay is exponential,
    :math:`A_i \simeq A_0 e^{-\gamma (i - i_0)}`, with the localisation length
    :math:`\xi = 1/\gamma` in grains (Martínez, Kevrekidis & Porter, Phys. Rev. E 93
    (2016) 022902; Kekić & Van Gorder, Physica D (2018); docs/physics.md §18).  Per
    realisation, the least-squares line through :math:`(i, \ln A_i)` for grains
    ``first .. last`` has the slope -γ (γ < 0: the amplitude grows); NaN where a grain
    of the range was never reached (A_i <= 0).  γ, unlike ξ, is finite for every
    realisation and its ensemble mean is the slope of the mean log amplitude (the
    fit is linear in ln A).

    Parameters
    ----------
    vmax : (R, N) or (N,) array
        Running maxima of v, m/s.
    first, last : int
        Grains of the fit, ``first <= i <= last`` (default: the last grain); at least
        two.

    Returns
    -------
    gamma, a0 : (R,) arrays
        Decay rate in 1/grain and the fitted amplitude at grain ``first`` (m/s).
    """
    a = np.atleast_2d(np.asarray(vmax, float))
    n = a.shape[1]
    last = n - 1 if last is None else int(last)
    if not (0 <= int(first) < last <= n - 1):
        raise ValueError(f"the fit range must satisfy 0 <= first < last <= {n - 1} "
                         f"(got first = {first!r}, last = {last!r})")
    x = np.arange(int(first), last + 1, dtype=float)
    y = a[:, int(first):last + 1]
    ok = np.all(y > 0, axis=1)
    ly = np.log(np.where(y > 0, y, 1.0))
    xc = x - x.mean()
    sxx = float(np.dot(xc, xc))
    slope, intercept = np.empty(a.shape[0]), np.empty(a.shape[0])
    for q in range(a.shape[0]):  # row by row: a realisation's fit does not depend on R
        mean = ly[q].mean()
        slope[q] = np.dot(ly[q] - mean, xc) / sxx
        intercept[q] = mean + slope[q] * (x[0] - x.mean())
    return np.where(ok, -slope, np.nan), np.where(ok, np.exp(intercept), np.nan)


QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)
"""The quantiles :func:`ensemble_statistics` reports."""


def ensemble_statistics(values, *, quantiles: Sequence[float] = QUANTILES,
                        n_boot: int = 200, seed: int = 0) -> dict[str, np.ndarray | int]:
    r"""Mean, standard error and quantiles (with bootstrap errors) over realisations.

    The realisations are independent draws, so the mean's standard error is
    :math:`s/\sqrt{R}` (s the sample standard deviation, ddof = 1); a quantile's
    uncertainty is the standard deviation of that quantile over ``n_boot`` bootstrap
    resamples of the realisations (Efron & Tibshirani, *An Introduction to the
    Bootstrap*, 1993, §6).  Non-finite values (a realisation that never reached the
    fit range, an infinite decay length) are left out and counted.

    Parameters
    ----------
    values : (R,) or (R, M) array
        One value (or a profile of M values) per realisation, realisations first.
    quantiles : sequence of float
        In [0, 1].
    n_boot : int
        Bootstrap resamples (>= 1; 0 skips the quantile errors: NaN).
    seed : int
        Seed of the resampling (the statistics are reproducible).

    Returns
    -------
    dict
        ``n`` (finite values per column), ``mean``, ``sem``, ``std``, and per quantile
        q ``q{100q:g}`` and ``q{100q:g}_err`` (e.g. ``q50``, ``q50_err``); each of shape
        () or (M,), NaN where a column has no finite value.
    """
    x = np.asarray(values, float)
    if x.ndim not in (1, 2) or x.shape[0] < 1:
        raise ValueError(f"values must have shape (R,) or (R, M) with R >= 1 (got {x.shape})")
    qs = [float(q) for q in quantiles]
    if any(not 0.0 <= q <= 1.0 for q in qs):
        raise ValueError(f"quantiles must lie in [0, 1] (got {list(quantiles)!r})")
    if int(n_boot) != n_boot or n_boot < 0:
        raise ValueError(f"n_boot must be an integer >= 0 (got {n_boot!r})")
    fin = np.isfinite(x)
    xm = np.where(fin, x, np.nan)
    cnt = fin.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"), _no_nan_warnings():
        mean = np.nanmean(xm, axis=0)
        std = np.where(cnt > 1, np.nanstd(xm, axis=0, ddof=1), np.nan)
        out: dict = {"n": cnt, "mean": mean, "std": std, "sem": std / np.sqrt(cnt)}
        qv = nanquantiles(xm, qs)
        boot = None
        if n_boot:
            rng = np.random.default_rng(int(seed))
            pick = rng.integers(0, x.shape[0], size=(int(n_boot), x.shape[0]))
            boot = nanquantiles(xm[pick.T], qs)  # (Q, n_boot, ...)
        for j, q in enumerate(qs):
            name = f"q{100 * q:g}"
            out[name] = qv[j]
            out[name + "_err"] = (np.nanstd(boot[j], axis=0, ddof=1) if boot is not None
                                  and n_boot > 1 else np.full_like(qv[j], np.nan))
    return out


def nanquantiles(x, quantiles: Sequence[float]) -> np.ndarray:
    """Quantiles over the first axis ignoring NaN: ``np.nanquantile(x, quantiles, axis=0)``.

    NumPy's default method ("linear", Hyndman & Fan's definition 7: the virtual index
    (n - 1) q into the n sorted finite values of a column, and NumPy's linear
    interpolation between its neighbours, ``a + (b - a) t``, or ``b - (b - a)(1 - t)``
    for t >= 1/2), so bit for bit NumPy's numbers, with every column at once (NumPy's
    ``nanquantile`` loops over the columns in Python).  NaN where a column has no
    finite value.

    Parameters
    ----------
    x : (R, ...) array
        Values, NaN for missing ones.
    quantiles : sequence of float
        In [0, 1].

    Returns
    -------
    (Q, ...) array
    """
    x = np.asarray(x, float)
    q = np.asarray(quantiles, float).reshape((-1,) + (1,) * (x.ndim - 1))
    srt = np.sort(x, axis=0)  # NaN last
    n = np.sum(~np.isnan(x), axis=0)
    top = np.maximum(n - 1, 0)
    vi = q * (n - 1)
    lo = np.floor(vi)
    t = vi - lo
    i = np.where(vi >= n - 1, top, np.clip(lo, 0, None)).astype(np.intp)
    j = np.minimum(i + 1, top)
    a = np.take_along_axis(srt, i, axis=0)
    b = np.take_along_axis(srt, j, axis=0)
    d = b - a
    out = np.where(t >= 0.5, b - d * (1 - t), a + d * t)
    return np.where(n > 0, out, np.nan)


class _no_nan_warnings:
    """Silence NumPy's RuntimeWarnings of all-NaN columns (they become NaN, as documented)."""

    def __enter__(self):
        import warnings

        self._ctx = warnings.catch_warnings()
        self._ctx.__enter__()
        warnings.simplefilter("ignore", RuntimeWarning)

    def __exit__(self, *exc):
        return self._ctx.__exit__(*exc)
