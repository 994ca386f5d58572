r"""Ensembles in sweeps: a seed axis run in batches, per-realisation reductions, statistics.

A sweep file with an ``[ensemble]`` table (:mod:`hertzchain.sweep.spec`) adds a seed
axis: every point of the other axes becomes ``seeds`` realisations of its disorder.
Each realisation is a point of its own (its own row, id and record: a resumed sweep
reruns only the missing ones), but the engine hands the realisations of one point to
a Dask worker in batches (:data:`EnsembleSpec.batch` at a time, the unit a worker
takes), which integrates them together in the batch kernel
(:func:`discrete.ensemble.run_ensemble`).

Per realisation (:func:`realisation`, :func:`realisations`: the same record bit for bit
whether run alone or in a batch) the summary holds the transmitted amplitude — the
running maximum of the grain velocity, :math:`A_i = \max_t v_i(t)` — at the last grain
and sampled along the chain (``amplitude_profile``, at :func:`profile_grains`), its
exponential decay rate (:func:`discrete.ensemble.amplitude_decay`), the arrival time
of the peak at the last grain and the front speed fitted to the arrival times
(:func:`front_speeds`), the final energy and the energy error.  The ensemble
statistics over the realisations of each point of the other axes
(:func:`ensemble_table`: mean, standard error, quantiles with bootstrap errors; the
mean log-amplitude profile and the localisation length
:math:`\xi = 1/\langle\gamma\rangle`) go to the ``/ensemble`` table of
``results.h5`` (:func:`hertzchain.sweep.store.write_table`), and
:func:`hertzchain.sweep_plot.plot_ensemble` draws the amplitude decay.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ..scenario import Scenario, ScenarioError

__all__ = ["ENSEMBLE_POINT_FUNCTION", "SCALARS", "realisation", "realisations",
           "profile_grains", "fit_range", "front_speeds", "ensemble_table",
           "PROFILE_POINTS"]

ENSEMBLE_POINT_FUNCTION = "hertzchain.sweep.ensemble:realisation"
"""The point function of a sweep with an ``[ensemble]`` table."""

PROFILE_POINTS = 64
"""Grains at which a realisation's amplitude profile is kept (all grains of a shorter chain)."""

SCALARS = ("amplitude_last", "decay_rate", "amplitude_fit", "arrival_time_last",
           "front_speed_tr", "energy_final", "energy_drift")
"""The per-realisation numbers whose ensemble statistics :func:`ensemble_table` reports."""


def profile_grains(n: int) -> np.ndarray:
    """The grains where the amplitude profile is kept (:data:`PROFILE_POINTS`).

    All grains of a chain of up to that many, else that many evenly spaced from 0 to n-1.
    """
    if n <= PROFILE_POINTS:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, PROFILE_POINTS)).astype(np.int64))


def fit_range(n: int) -> tuple[int, int]:
    """Grains (first, last) of the decay fit.

    From a tenth of the chain (past the struck end's transient, where the pulse
    forms) to the last grain.
    """
    return max(1, n // 10), n - 1


def front_speeds(x, t, reached) -> np.ndarray:
    r"""Front speed (m/s) of each row: 1 / the least-squares slope of t against x.

    The peak reaches grain i (centre :math:`x_i`, m) at :math:`t_i` (s); a pulse of
    speed c gives :math:`t_i = t_0 + x_i/c`, and the least-squares line through the
    points :math:`(x_i, t_i)` of the reached grains has the slope
    :math:`\sum_i (x_i - \bar x)(t_i - \bar t) / \sum_i (x_i - \bar x)^2 = 1/c`
    (means over the reached grains of the row; the normal equations of the fit,
    ``np.polyfit(x, t, 1)``).  NaN where fewer than 5 grains were reached, the times do
    not vary or the slope is not positive.

    Parameters
    ----------
    x, t : (R, K) arrays
        Grain centres (m) and arrival times (s).
    reached : (R, K) bool array
        The grains of each row that the pulse reached.

    Returns
    -------
    (R,) array
    """
    x, t = np.asarray(x, float), np.asarray(t, float)
    w = np.asarray(reached, bool)
    cnt = w.sum(axis=1)
    out = np.full(x.shape[0], math.nan)
    for q in np.flatnonzero(cnt >= 5):  # row by row: a row's result does not depend on R
        xr, tr = x[q, w[q]], t[q, w[q]]
        if np.ptp(tr) > 0:
            xc = xr - xr.mean()
            slope = float(np.dot(xc, tr - tr.mean()) / np.dot(xc, xc))  # s/m
            out[q] = 1.0 / slope if slope > 0 else math.nan
    return out


def _unseeded(scenario: Scenario) -> Scenario:
    """The scenario with every section's seed 0 and no name.

    Equal for the realisations of one point of the other axes.
    """
    secs = tuple(replace(x, seed=0) for x in scenario.chain.sections)
    return scenario.replace(chain=replace(scenario.chain, sections=secs), name="")


def _chains(scenarios: Sequence[Scenario]) -> list:
    """The chains of the scenarios, as :func:`hertzchain.runner.build_chain` builds them.

    Scenarios that differ only in the seed of one disordered section are built together
    by :meth:`discrete.Chain.from_sections_seeds` (bit for bit ``from_sections``'s
    chains, the geometry built once); the others one by one.  The chains carry no
    ``scenario_chain`` parameter (a realisation's summary does not read it).
    """
    import discrete

    from ..runner import build_chain, chain_inputs

    out: list = [None] * len(scenarios)
    groups: list[tuple[Scenario, list[int]]] = []
    for q, s in enumerate(scenarios):
        key = _unseeded(s)
        for k, idx in groups:
            if k == key:
                idx.append(q)
                break
        else:
            groups.append((key, [q]))
    try:
        for _, idx in groups:
            specs = [scenarios[q].chain for q in idx]
            seeds = np.array([[x.seed for x in c.sections] for c in specs])
            varying = np.flatnonzero(np.any(seeds != seeds[0], axis=0))
            sections, kwargs = chain_inputs(specs[0])
            disordered = [i for i, x in enumerate(sections) if x.disorder is not None]
            section = (int(varying[0]) if varying.size == 1 else
                       disordered[0] if varying.size == 0 and len(disordered) == 1 else None)
            if section is None or section not in disordered:
                for q in idx:
                    out[q] = build_chain(scenarios[q].chain)
                continue
            chains = discrete.Chain.from_sections_seeds(
                sections, [int(x) for x in seeds[:, section]], section=section, **kwargs)
            for q, c in zip(idx, chains, strict=True):
                out[q] = c
    except ValueError as exc:
        raise ScenarioError(f"[chain] non-physical chain: {exc}") from None
    return out


def _build(scenarios: Sequence[Scenario]) -> list:
    """The scenarios' simulations with running maxima only (the runner's chain, state, dt).

    Each realisation's chain (:func:`_chains`), initial state
    (:func:`hertzchain.runner.build_initial_checked`, :func:`~hertzchain.runner.check_run`)
    and time step (:func:`hertzchain.runner.choose_time_step`, the run's horizon its
    ``t_end``) are those of :func:`hertzchain.runner.build_simulation`; the recording
    keeps only the running maxima (all an ensemble reads).
    """
    import discrete

    from .. import runner as R

    for s in scenarios:
        R.check_size(s)
        if s.run.t_end is None or s.run.until_front_at is not None:
            raise ScenarioError("[run] an ensemble realisation runs to t_end (s): give "
                                "t_end and no until_front_at")
    sims = []
    for s, chain in zip(scenarios, _chains(scenarios), strict=True):
        init = R.build_initial_checked(s, chain)
        R.check_run(s, init)
        law, drag = R.build_law(s.chain)
        step = R.choose_time_step(s, init, float(s.run.t_end))
        sims.append(init.simulation(dt=step, law=law, drag=drag, record=discrete.Recording(
            maxima=True, refined_maxima=False)))
    return sims


def _summaries(sims, res, t_end: float, wall: float) -> list[dict[str, Any]]:
    """Each realisation's summary (the sweep's record) from the ensemble's results.

    ``front_speed_tr``: :func:`front_speeds` of the arrival times of the grains of the
    fit range (:func:`fit_range`) that the pulse reached (``vmax > 0``).
    """
    from discrete.ensemble import amplitude_decay

    n = res.vmax.shape[1]
    first, last = fit_range(n)
    rate, a0 = amplitude_decay(res.vmax, first, last)
    grains = profile_grains(n)
    fit = slice(first, last + 1)
    diam = np.array([sim.chain.diameter for sim in sims])
    centres = np.cumsum(diam, axis=1) - 0.5 * diam  # grain centres, m
    speed = front_speeds(centres[:, fit], res.vmax_time[:, fit], res.vmax[:, fit] > 0)
    t_last = res.vmax_time[:, -1]
    nan_keys = dict.fromkeys(("Ek_tr", "Ek_re", "Ep_tr", "Ep_re", "Et_tr", "Et_re",
                              "front_speed_re", "front_speed_tr_over_c0L"), math.nan)
    drift = res.energy_error
    out = []
    for q in range(len(sims)):
        s = dict(nan_keys)
        s.update(transmitted=None, reflected=None, n_transmitted_pulses=None,
                 front_speed_tr=float(speed[q]),
                 energy_drift=float(drift[q]), steps=int(res.steps[q]),
                 dt=float(res.dt[q]), t=float(res.t[q]), wall_time=wall,
                 stopped_by="t_end", completed=True, n_grains=int(n),
                 integrator=res.integrator,
                 amplitude_last=float(res.vmax[q, -1]),
                 decay_rate=float(rate[q]), amplitude_fit=float(a0[q]),
                 arrival_time_last=float(t_last[q]) if res.vmax[q, -1] > 0 else math.nan,
                 energy_initial=float(res.energy0[q]), energy_final=float(res.energy[q]),
                 amplitude_profile=res.vmax[q, grains].tolist())
        out.append(s)
    return out


def realisation(scenario: Scenario, *, out=None, progress: bool = False) -> dict[str, Any]:
    """One realisation's summary, run alone (a batch of one): the sweep point function.

    The same numbers bit for bit as the realisation's record from a batch
    (:func:`realisations`); ``wall_time`` is this run's.  ``out`` (a full per-run
    file) is not written by ensembles; ``progress`` is ignored.
    """
    return realisations([scenario])[0]


def realisations(scenarios: Sequence[Scenario]) -> list[dict[str, Any]]:
    """The summaries of realisations of one chain size, integrated together.

    Every scenario is built as the runner builds it (:func:`hertzchain.runner.
    build_simulation`: chain, initial state, time step) and all run to their
    ``[run] t_end`` in :func:`discrete.ensemble.run_ensemble`, grouped by end time.
    ``wall_time`` is the batch's wall time divided among its realisations.
    """
    from discrete.ensemble import run_ensemble

    t0 = time.perf_counter()
    sims = _build(scenarios)
    sizes = {s.chain.n for s in sims}
    if len(sizes) != 1:
        raise ScenarioError(f"an ensemble batch needs one chain size, got {sorted(sizes)}")
    by_end: dict[float, list[int]] = {}
    for q, s in enumerate(scenarios):
        by_end.setdefault(float(s.run.t_end), []).append(q)
    out: list[dict[str, Any]] = [{} for _ in scenarios]
    done = []
    for t_end, idx in by_end.items():
        res = run_ensemble([sims[q] for q in idx], t_end, times=True)  # arrival times
        done.append((idx, [sims[q] for q in idx], res, t_end))
    wall = (time.perf_counter() - t0) / len(scenarios)
    for idx, group, res, t_end in done:
        for q, summary in zip(idx, _summaries(group, res, t_end, wall), strict=True):
            out[q] = summary
    return out


realisation.batch = realisations  # the engine batches points of a point function with it


# ------------------------------------------------------------------ statistics
def _finite_rows(rows: list) -> np.ndarray:
    width = max((len(r) for r in rows if isinstance(r, list)), default=0)
    return np.array([r if isinstance(r, list) and len(r) == width else [math.nan] * width
                     for r in rows], dtype=float).reshape(len(rows), width)


def ensemble_table(group_values: Sequence[Mapping[str, Any]],
                   summaries: Sequence[Sequence[Mapping[str, Any]]], *,
                   n_boot: int = 200) -> dict[str, np.ndarray]:
    r"""Ensemble statistics per group of realisations (one row per point of the other axes).

    Parameters
    ----------
    group_values : sequence of dict
        The values of the other axes of each group (its columns).
    summaries : sequence of sequences of dict
        The summaries of each group's finished realisations.
    n_boot : int
        Bootstrap resamples for the quantiles' errors.

    Returns
    -------
    dict of str to array
        Per group: the axis values, ``n_realisations``; for every name X of
        :data:`SCALARS` ``X_mean``, ``X_sem``, ``X_std``, ``X_q5`` … ``X_q95`` and
        ``X_q5_err`` … (:func:`discrete.ensemble.ensemble_statistics`, NumPy's
        arithmetic); ``localisation_length`` :math:`\xi = 1/\langle\gamma\rangle` in
        grains (γ the decay rate; the slope of the mean log amplitude, the
        self-averaging quantity of a disordered chain, docs/physics.md §18) with
        ``localisation_length_err`` :math:`\sigma_{\langle\gamma\rangle}/\langle\gamma
        \rangle^2` (NaN where ⟨γ⟩ <= 0); and 2-D columns (groups × profile grains)
        ``profile_mean``, ``profile_sem``, ``profile_q50``, ``log_profile_mean``,
        ``log_profile_sem`` (of ln A, 1/ln(m/s)).
    """
    from discrete.ensemble import ensemble_statistics

    cols: dict[str, list] = {}
    for values, recs in zip(group_values, summaries, strict=True):
        for name, v in values.items():
            cols.setdefault(name, []).append(v)
        cols.setdefault("n_realisations", []).append(len(recs))
        for key in SCALARS:
            x = np.array([np.nan if r.get(key) is None else float(r[key]) for r in recs]
                         if recs else [np.nan])
            st = ensemble_statistics(x, n_boot=n_boot)
            for stat, val in st.items():
                if stat != "n":
                    cols.setdefault(f"{key}_{stat}", []).append(float(val))
        rate = cols["decay_rate_mean"][-1]
        ok = math.isfinite(rate) and rate > 0
        cols.setdefault("localisation_length", []).append(1.0 / rate if ok else math.nan)
        cols.setdefault("localisation_length_err", []).append(
            cols["decay_rate_sem"][-1] / rate**2 if ok else math.nan)
        prof = _finite_rows([r.get("amplitude_profile") for r in recs]) if recs \
            else np.zeros((1, 0))
        st = ensemble_statistics(prof, n_boot=0) if prof.size else None
        with np.errstate(divide="ignore", invalid="ignore"):
            lp = np.log(np.where(prof > 0, prof, np.nan))
        st_log = ensemble_statistics(lp, n_boot=0) if prof.size else None
        for name, src, stat in (("profile_mean", st, "mean"), ("profile_sem", st, "sem"),
                                ("profile_q50", st, "q50"), ("log_profile_mean", st_log, "mean"),
                                ("log_profile_sem", st_log, "sem")):
            cols.setdefault(name, []).append(None if src is None else np.asarray(src[stat]))
    out: dict[str, np.ndarray] = {}
    for name, vals in cols.items():
        if name.startswith(("profile_", "log_profile_")):
            width = max((v.size for v in vals if v is not None), default=0)
            out[name] = np.array([v if v is not None and v.size == width
                                  else np.full(width, np.nan) for v in vals]).reshape(
                len(vals), width)
        elif all(isinstance(v, str) for v in vals):
            out[name] = np.array(vals, dtype=object)
        else:
            out[name] = np.array(vals)
    return out
