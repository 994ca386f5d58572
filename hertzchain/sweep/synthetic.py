"""Synthetic point functions with the runner's signature, for tests and benchmarks.

:func:`synthetic_point` returns a deterministic run summary built from the linear-
acoustic theory of the scenario's first interface, after a CPU-bound numba kernel (a
small Hertz chain integrated with velocity Verlet, the same kind of work as the real
solver) whose cost is set by ``work``.  It is importable on Dask worker processes.
"""

from __future__ import annotations

import functools
import math
import time
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

import theory
from theory import jitcache

from ..scenario import Scenario

jitcache.configure()  # compiled kernels cached outside the package (theory/jitcache.py)

__all__ = ["synthetic_point", "paced_point", "benchmark_point", "hertz_chain_kernel"]


@njit(cache=True)
def hertz_chain_kernel(n: int, steps: int, v0: float) -> float:
    """Integrate a unit Hertz chain (``F = δ^{3/2}``) of ``n`` grains; return the energy drift.

    Dimensionless units (unit mass, unit Hertz constant, dt = 0.005); grain 0 starts
    with velocity ``v0``.  Returns the relative change of the total energy.
    """
    x = np.zeros(n)
    v = np.zeros(n)
    f = np.zeros(n)
    v[0] = v0
    dt = 0.005
    e0 = 0.5 * v0 * v0
    for _ in range(steps):
        for i in range(n):
            v[i] += 0.5 * dt * f[i]
            x[i] += dt * v[i]
        for i in range(n):
            f[i] = 0.0
        for i in range(n - 1):
            overlap = x[i] - x[i + 1]
            if overlap > 0.0:
                force = overlap**1.5
                f[i] -= force
                f[i + 1] += force
        for i in range(n):
            v[i] += 0.5 * dt * f[i]
    e = 0.0
    for i in range(n):
        e += 0.5 * v[i] * v[i]
    for i in range(n - 1):
        overlap = x[i] - x[i + 1]
        if overlap > 0.0:
            e += 0.4 * overlap**2.5
    return (e - e0) / e0


def _interface(scenario: Scenario) -> tuple[float, float]:
    s = scenario.chain.sections
    if len(s) < 2:
        return 1.0, 1.0
    return s[1].alpha_rho / s[0].alpha_rho, s[1].alpha_kn / s[0].alpha_kn


def synthetic_point(scenario: Scenario, *, out: Path | None = None, progress: bool = False,
                    work: int = 0, band: float = 0.0, fail_above: float | None = None,
                    sleep: float = 0.0) -> dict[str, Any]:
    """A deterministic stand-in for :func:`hertzchain.runner.run_scenario`.

    Parameters
    ----------
    scenario : Scenario
        The point; its first interface's (α_ρ, α_kn) set the result.
    out : pathlib.Path, optional
        If given, a small HDF5 file with the summary as attributes is written there.
    progress : bool
        Ignored.
    work : int
        Grain-steps of the numba kernel to burn (0: none); ~1e7 take ~0.05 s.
    band : float
        Half-width in |ln γ| around each theory line inside which the classification is
        "none" (a synthetic disagreement band).
    fail_above : float, optional
        Raise ``RuntimeError`` when α_ρ exceeds this (a synthetic instability).
    sleep : float
        Seconds to sleep first (a slow point that does not load the CPU).

    Returns
    -------
    dict
        The summary keys of the runner's contract.
    """
    t0 = time.perf_counter()
    if sleep > 0:
        time.sleep(sleep)
    ar, ak = _interface(scenario)
    if fail_above is not None and ar > fail_above:
        raise RuntimeError(f"synthetic instability at alpha_rho = {ar:g}")
    drift = 0.0
    if work > 0:
        n = 200
        drift = float(hertz_chain_kernel(n, max(1, work // n), 1.0))
    gc, gr = float(theory.gamma_c0(ar, ak)), float(theory.gamma_rg(ar, ak))
    lc, lr = math.log(gc), math.log(gr)
    tol = max(band, 1e-9)  # theory.region's tolerance for "on the line"
    transmitted = "fracture" if lc > tol else "squeeze" if lc < -tol else "none"
    reflected = "compressive" if lr > tol else "expansive" if lr < -tol else "none"
    re = float(theory.energy_reflection(gr))
    d0 = scenario.chain.delta0_over_d
    c0l = 1.0
    if d0 > 0:
        d = scenario.chain.diameter
        mat = theory.PAPER_MATERIAL
        c0l = float(theory.c0(theory.hertz_constant(d, mat), theory.grain_mass(d, mat.density),
                              d, d0 * d))
    summary = {
        "Ek_tr": 1.0 - re, "Ek_re": re, "Ep_tr": 1.0 - re, "Ep_re": re,
        "Et_tr": 1.0 - re, "Et_re": re,
        "front_speed_tr": gc * c0l, "front_speed_re": -c0l if gr != 1.0 else 0.0,
        "front_speed_tr_over_c0L": gc,
        "transmitted": transmitted, "reflected": reflected,
        "n_transmitted_pulses": 1 + (int(3 * lc) if transmitted == "fracture" else 0),
        "energy_drift": drift, "steps": int(work), "dt": 1e-8,
        "wall_time": time.perf_counter() - t0, "stopped_by": "t_end", "completed": True,
    }
    if out is not None:
        from theory.integrity import sealed_hdf5

        with sealed_hdf5(out) as fh:
            for key, value in summary.items():
                fh.attrs[key] = value
    return summary


paced_point = functools.partial(synthetic_point, sleep=0.2)
""":func:`synthetic_point` taking 0.2 s of sleep per point (for interruption tests)."""

benchmark_point = functools.partial(synthetic_point, work=40_000_000)
""":func:`synthetic_point` burning ~0.2 s of CPU per point in a numba Hertz-chain kernel."""
