r"""Compiled time-stepping kernels for the Hertz chain (pyro2 style: plain arrays).

Equation of motion (paper Eq. 2) with the contact law Eq. 1, written relative to the
static force :math:`f_{0,j} = k_j\delta_{0,j}^{3/2}`:

.. math::
    m_i \ddot u_i = \varphi_i - \varphi_{i+1},\qquad
    \varphi_j = k_j [r_j]_+^{3/2} - f_{0,j},\qquad
    r_j = \delta_{0,j} + (u_{j-1} - u_j)

(u in m, forces in N, :math:`u_{-1} = w_L`, :math:`u_N = w_R` the walls).  Since every
static force is the same F0 (force equilibrium), subtracting f0 per contact changes
Eq. 2 by at most one rounding error of F0; it makes a grain at rest with unstrained
contacts (:math:`u_{j-1} = u_j`, evaluated as a difference first so that
:math:`r_j = \delta_{0,j}` *exactly*) have exactly zero acceleration: it is *inert*
and stays so until a neighbour moves.  In one (sub)step a disturbance moves at most
one grain (the force pass reads the drifted neighbours), so integrating only the window
``[lo, hi]`` outside which every grain is inert, grown by one grain on a side before
each substep at which its edge grain is not inert, is bitwise identical to integrating
the whole chain.

Time stepping
-------------
A step is a splitting method of "kick-drift-...-kick" form (:mod:`discrete.integrators`):

.. math::
    v \mathrel{+}= b_1 h\,a,\quad u \mathrel{+}= a_1 h\, v,\quad v \mathrel{+}= b_2 h\,a,
    \quad\dots,\quad u \mathrel{+}= a_S h\, v,\quad v \mathrel{+}= b_{S+1} h\,a ,

velocity Verlet (the paper's Section 2; Swope et al., J. Chem. Phys. 76 (1982) 637,
Eq. 7) being S = 1, a = (1), b = (1/2, 1/2).  The closing kick of a step and the
opening kick of the next one are applied in the same pass (``v = (v + b_{S+1} h a) +
b_1 h a``: the arithmetic of kick–drift–kick, without storing a); only the last step
of a chunk stores a and stops at the synchronous velocity.

One substep is **one fused pass** over the window: at grain i it drifts grain i+1
(``u += a_s h v``, stored), evaluates contact i+1 from the two drifted positions, and
kicks grain i with the contact forces on both sides (the left one carried from the
previous grain).  Per grain and substep the pass reads u, v and the running maximum of
v and writes u, v (and the maximum only where it is exceeded).  The per-grain and
per-contact constants (1/m, k, δ0, f0) are piecewise constant in the chains of the
paper: they are then passed as a table of *runs* of equal constants (scalars in the
loop, no memory traffic); arbitrary chains (random, tapered) read them from arrays.

Pieces, blocks and threads
--------------------------
A substep of grains ``[i0, i1)`` can be done as one *piece* given the drifted
positions of its two outer neighbours, :math:`u_{i0-1}^{new}` and :math:`u_{i1}^{new}`
(or the walls), computed with the same arithmetic ``u + a_s h v`` as their own pass
uses; the piece recomputes the contact force at its left edge.  Every grain's
arithmetic is therefore the same however the window is cut, which gives

* **temporal blocking** (trapezoid tiles, see the section above :func:`_trapezoid`):
  a block advances the window by up to 256 substeps in two phases of independent
  tiles, each tile staying in L2 while it takes its substeps;
* **threads**: the tiles of a phase run concurrently (numba ``prange``, two parallel
  regions per block) — results are bitwise identical with 1 or more threads and with
  or without blocking (``tests/discrete/test_parallel.py``);
* **events inside a block**: the synchronous velocities of watched grains are recorded
  per step; if a block overshoots an event it is rolled back (state kept at the block
  start while a watched grain is within reach) and redone step by step.

The recording (running maxima of v every step, of u every ``UMAX_EVERY`` steps, the
event test on watched grains, time series of chosen grains) is fused into these passes.
No ``fastmath``: the tests rely on bitwise determinism.
"""

from __future__ import annotations

import os

# Threads that wait at the end of a parallel region sleep instead of spinning.  On a
# shared machine (other processes on the cores) a spinning thread takes the core from
# the thread it waits for: measured 2-thread / 1-thread ratio 0.3-0.6 with libgomp's
# default spinning, 1.0 passive (benchmarks/README.md); the cost, a ~10 µs wake-up per
# region, is small at two regions per block of 256 substeps.  Read by libgomp when numba
# first starts its OpenMP threads; an explicit setting is kept.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numba  # noqa: E402
import numpy as np  # noqa: E402

from theory import jitcache  # noqa: E402

jitcache.configure()  # compiled kernels cached outside the package (theory/jitcache.py)

__all__ = [
    "accelerations",
    "run_chunk",
    "chain_runs",
    "active_window",
    "grain_energies",
    "contact_energies",
    "shadow_correction",
]

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}

UMAX_EVERY = 8
"""Steps between updates of the running maximum of u (see :func:`run_chunk`)."""

RUNS_MIN_LENGTH = 32
"""Mean run length from which :func:`chain_runs` returns a run table (else: arrays)."""


def chain_runs(inv_m, k, d0, f0, min_length: int = RUNS_MIN_LENGTH):
    """Runs of grains with equal constants, for :func:`run_chunk`.

    Grain i's constants are (1/m_i, k_{i+1}, δ0_{i+1}, f0_{i+1}) (its mass and its right
    contact).  Returns ``(starts, table)``: grains ``starts[q] .. starts[q+1]-1`` share
    the row ``table[q] = (1/m, k, δ0, f0)``.  If the mean run is shorter than
    ``min_length`` grains (random or tapered chains) the table is not worth it and
    empty arrays are returned: the kernels then read the per-grain arrays.
    """
    c = np.stack([np.asarray(inv_m, float), np.asarray(k, float)[1:],
                  np.asarray(d0, float)[1:], np.asarray(f0, float)[1:]], axis=1)
    n = c.shape[0]
    change = np.flatnonzero(np.any(c[1:] != c[:-1], axis=1)) + 1
    starts = np.r_[0, change, n].astype(np.int64)
    if n < min_length * (starts.size - 1):
        return np.zeros(0, np.int64), np.zeros((0, 4))
    return starts, np.ascontiguousarray(c[starts[:-1]])


@numba.njit(**_JIT)
def accelerations(u, a, inv_m, k, d0, f0, wl, wr, lo, hi):
    """Set a[lo:hi+1] = (φ_i - φ_{i+1})/m_i (Eq. 2), m/s²; other entries untouched."""
    n = u.size
    ul = wl if lo == 0 else u[lo - 1]
    r = d0[lo] + (ul - u[lo])
    r = max(r, 0.0)
    phi_l = k[lo] * (r * np.sqrt(r)) - f0[lo]
    for i in range(lo, hi + 1):
        ur = wr if i == n - 1 else u[i + 1]
        r = d0[i + 1] + (u[i] - ur)
        r = max(r, 0.0)
        phi_r = k[i + 1] * (r * np.sqrt(r)) - f0[i + 1]
        a[i] = (phi_l - phi_r) * inv_m[i]
        phi_l = phi_r


@numba.njit(inline="always", **_JIT)
def _active(u, v, k, wl, wr, i):
    """Grain i is not inert: it moves, or one of its (present) contacts is strained."""
    n = u.size
    ul = wl if i == 0 else u[i - 1]
    ur = wr if i == n - 1 else u[i + 1]
    return v[i] != 0.0 or (k[i] != 0.0 and ul != u[i]) or (k[i + 1] != 0.0 and ur != u[i])


# ----------------------------------------------------------------------------- passes
# The fused loops below advance grains 0..m-1 of the views (uw, vw, ... start at the
# first grain), drifting grain i+1 at grain i; ``un``/``phi_l`` are the drifted position
# of grain 0 and the force of its left contact.  They return the carried pair for
# grain m.  Views starting at the loop's first grain let numba prove the indices
# non-negative (no wrap-around test) and use one base pointer for u[i], u[i+1] (LLVM
# then sees the distance-1 dependence and vectorises without a run-time alias check).
# The kick is v = (v + c1 a) + c2 a with the running max of v taken on v + c1 a (the
# synchronous velocity) when ``track``; c2 = 0 for the closing step of a chunk and for
# the intermediate kicks of composition methods (adding 0·a is exact).  Only two loop
# variants per constant layout: the small-chain cost is the per-call overhead, and the
# functions are inlined (``inline="always"``) to keep it low.

@numba.njit(inline="always", **_JIT)
def _loop_const(uw, vw, vmw, m, un, phi_l, dc, c1, c2, im, kr, d0r, f0r, track):
    """Fused pass over m grains sharing the constants (1/m, k, δ0, f0) of their right contact."""
    if track:
        for i in range(m):
            unr = uw[i + 1] + dc * vw[i + 1]
            uw[i + 1] = unr
            r = max(d0r + (un - unr), 0.0)
            phi_r = kr * (r * np.sqrt(r)) - f0r
            ai = (phi_l - phi_r) * im
            vi = vw[i] + c1 * ai
            if vi > vmw[i]:
                vmw[i] = vi
            vw[i] = vi + c2 * ai
            phi_l = phi_r
            un = unr
    else:
        for i in range(m):
            unr = uw[i + 1] + dc * vw[i + 1]
            uw[i + 1] = unr
            r = max(d0r + (un - unr), 0.0)
            phi_r = kr * (r * np.sqrt(r)) - f0r
            ai = (phi_l - phi_r) * im
            vw[i] = (vw[i] + c1 * ai) + c2 * ai
            phi_l = phi_r
            un = unr
    return un, phi_l


@numba.njit(inline="always", **_JIT)
def _loop_arrays(uw, vw, vmw, imw, kw, d0w, f0w, m, un, phi_l, dc, c1, c2, track):
    """Fused pass over m grains with per-grain constants (kw etc. start at the right contact)."""
    if track:
        for i in range(m):
            unr = uw[i + 1] + dc * vw[i + 1]
            uw[i + 1] = unr
            r = max(d0w[i] + (un - unr), 0.0)
            phi_r = kw[i] * (r * np.sqrt(r)) - f0w[i]
            ai = (phi_l - phi_r) * imw[i]
            vi = vw[i] + c1 * ai
            if vi > vmw[i]:
                vmw[i] = vi
            vw[i] = vi + c2 * ai
            phi_l = phi_r
            un = unr
    else:
        for i in range(m):
            unr = uw[i + 1] + dc * vw[i + 1]
            uw[i + 1] = unr
            r = max(d0w[i] + (un - unr), 0.0)
            phi_r = kw[i] * (r * np.sqrt(r)) - f0w[i]
            ai = (phi_l - phi_r) * imw[i]
            vw[i] = (vw[i] + c1 * ai) + c2 * ai
            phi_l = phi_r
            un = unr
    return un, phi_l


@numba.njit(inline="always", **_JIT)
def _piece(u, v, vmax, inv_m, k, d0, f0, rs, rc, i0, i1, ul, ur, dc, c1, c2, track):
    """One substep of grains [i0, i1) given the drifted outer neighbours ``ul``, ``ur``.

    Returns the synchronous velocity (v + c1 a) of grain i1-1.
    """
    un = u[i0] + dc * v[i0]
    u[i0] = un
    r = max(d0[i0] + (ul - un), 0.0)
    phi_l = k[i0] * (r * np.sqrt(r)) - f0[i0]
    j = i0
    last = i1 - 1
    if last > j:
        if rs.size > 1:
            q = _first_at_least(rs, j + 1) - 1  # the run containing grain j
            while j < last:
                e = min(rs[q + 1], last)
                un, phi_l = _loop_const(u[j:e + 1], v[j:e + 1], vmax[j:e + 1], e - j, un,
                                        phi_l, dc, c1, c2, rc[q, 0], rc[q, 1], rc[q, 2],
                                        rc[q, 3], track)
                j = e
                q += 1
        else:
            un, phi_l = _loop_arrays(u[j:i1], v[j:i1], vmax[j:i1], inv_m[j:i1], k[j + 1:i1],
                                     d0[j + 1:i1], f0[j + 1:i1], last - j, un, phi_l, dc,
                                     c1, c2, track)
    # last grain: right neighbour given
    r = max(d0[i1] + (un - ur), 0.0)
    phi_r = k[i1] * (r * np.sqrt(r)) - f0[i1]
    ai = (phi_l - phi_r) * inv_m[last]
    vi = v[last] + c1 * ai
    if track and vi > vmax[last]:
        vmax[last] = vi
    v[last] = vi + c2 * ai
    return vi


@numba.njit(inline="always", **_JIT)
def _first_at_least(x, value):
    """Index of the first entry of the sorted int array ``x`` that is >= ``value``."""
    lo, hi = 0, x.size
    while lo < hi:
        mid = (lo + hi) // 2
        if x[mid] < value:
            lo = mid + 1
        else:
            hi = mid
    return lo


# ------------------------------------------------------------------ temporal blocking
# A block advances the (padded) window by ``nsub`` substeps with trapezoid tiles:
# phase A advances every tile [b_j, b_j+1) on the shrinking ranges [b_j + τ, b_j+1 - τ)
# for τ = 0 .. nsub-1 (the outer neighbours of a range at τ >= 1 are the tile's own
# grains, at level τ: drifted on the fly; at τ = 0 they belong to other tiles, so their
# drifted positions are computed before the phase); phase B then advances the growing
# ranges [b_j - τ, b_j + τ) around every tile boundary (and the window ends), whose
# outer neighbours phase A has left exactly at level τ + 1 (stored u).  Tiles of one
# phase touch disjoint grains, so they run concurrently; each grain's arithmetic is that
# of the per-step pass.  Two parallel regions per block instead of one per substep, and
# a tile (u, v, max v: 24 bytes per grain) stays in L2 during its nsub substeps.


@numba.njit(inline="always", **_JIT)
def _accel_at(u, inv_m, k, d0, f0, g, ul, ur):
    """Acceleration of grain g with neighbours at ``ul``, ``ur`` (the arithmetic of the pass)."""
    r = max(d0[g] + (ul - u[g]), 0.0)
    phi_l = k[g] * (r * np.sqrt(r)) - f0[g]
    r = max(d0[g + 1] + (u[g] - ur), 0.0)
    phi_r = k[g + 1] * (r * np.sqrt(r)) - f0[g + 1]
    return (phi_l - phi_r) * inv_m[g]


@numba.njit(inline="always", **_JIT)
def _advance(u, v, vmax, umax, inv_m, k, d0, f0, rs, rc, lo_t, hi_t, ul, ur, dc, c1, c2, trk,
             umx, sp, vsp):
    """One substep of grains [lo_t, hi_t) (:func:`_piece`) with the recording.

    The synchronous velocities v + c1 a of the special grains ``sp`` (sorted) in the
    range go to ``vsp`` (a recomputed with the pass's arithmetic from the drifted
    positions; ``ul``, ``ur`` at the range ends), and with ``umx`` the running maximum of
    u is updated on the range.
    """
    q0 = _first_at_least(sp, lo_t)
    q1 = _first_at_least(sp, hi_t)
    for q in range(q0, q1):
        vsp[q] = v[sp[q]]
    _piece(u, v, vmax, inv_m, k, d0, f0, rs, rc, lo_t, hi_t, ul, ur, dc, c1, c2, trk)
    for q in range(q0, q1):
        g = sp[q]
        left = ul if g == lo_t else u[g - 1]
        right = ur if g == hi_t - 1 else u[g + 1]
        vsp[q] = vsp[q] + c1 * _accel_at(u, inv_m, k, d0, f0, g, left, right)
    if umx:
        uw = u[lo_t:hi_t]
        umw = umax[lo_t:hi_t]
        for i in range(hi_t - lo_t):
            umw[i] = max(umw[i], uw[i])


@numba.njit(**_JIT)
def _trapezoid(u, v, vmax, umax, inv_m, k, d0, f0, rs, rc, bounds, j, phase, ulb, urb, wl,
               wr, dcs, c1s, c2s, trks, umxs, fins, sp, none, vsp2, nsub):
    """Phase A on tile j (shrinking ranges) or phase B around boundary j (growing)."""
    n = u.size
    nt = bounds.size - 1
    for tau in range(nsub):
        dc = dcs[tau]
        if phase == 0:
            lo_t = bounds[j] + tau
            hi_t = bounds[j + 1] - tau
            if lo_t >= hi_t:
                break
            ul = ulb[j] if tau == 0 else u[lo_t - 1] + dc * v[lo_t - 1]
            ur = urb[j] if tau == 0 else u[hi_t] + dc * v[hi_t]
        else:
            lo_t = max(bounds[j] - tau, bounds[0])
            hi_t = min(bounds[j] + tau, bounds[nt])
            if lo_t >= hi_t:
                continue
            ul = wl if lo_t == 0 else u[lo_t - 1]
            ur = wr if hi_t == n else u[hi_t]
        _advance(u, v, vmax, umax, inv_m, k, d0, f0, rs, rc, lo_t, hi_t, ul, ur, dc, c1s[tau],
                 c2s[tau], trks[tau], umxs[tau], sp if fins[tau] else none, vsp2[tau])


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _phase(u, v, vmax, umax, inv_m, k, d0, f0, rs, rc, bounds, phase, ulb, urb, wl, wr, dcs,
           c1s, c2s, trks, umxs, fins, sp, none, vsp2, nsub):
    """Phase ``phase`` (0: A, 1: B) of a block on the tiles ``bounds``, concurrently.

    (One prange loop called twice per block: numba compiles the loop body, and all it
    calls, once per prange loop.)
    """
    count = bounds.size - 1 + phase
    for j in numba.prange(count):
        _trapezoid(u, v, vmax, umax, inv_m, k, d0, f0, rs, rc, bounds, j, phase, ulb, urb, wl,
                   wr, dcs, c1s, c2s, trks, umxs, fins, sp, none, vsp2, nsub)


@numba.njit(**_JIT)
def run_chunk(u, v, a, inv_m, k, d0, f0, rs, rc, wl, wr, dt, drift, kick, nsteps, lo, hi,
              vmax, umax, track, watch, wmax, wthr, ts_idx, ts_every, step0, ts_out,
              nthreads, min_parallel, block_steps, tile, min_serial_block):
    """Advance ``nsteps`` steps on the window ``lo..hi`` in place.

    Parameters
    ----------
    u, v, a : (N,) float arrays
        Displacements (m), velocities (m/s), accelerations (m/s², consistent with u).
    inv_m, k, d0, f0 : arrays
        1/m (1/kg); contact constants (N/m^{3/2}), static overlaps (m), static forces (N).
    rs, rc : arrays
        Runs of equal grain constants (:func:`chain_runs`); empty: use the arrays.
    wl, wr : float
        Wall displacements, m.
    dt : float
        Time step h, s.
    drift, kick : (S,), (S+1,) float arrays
        Drift coefficients a_s h and kick coefficients b_s h of the method, s
        (velocity Verlet: (h,), (h/2, h/2); :mod:`discrete.integrators`).
    nsteps, lo, hi : int
        Steps to take and the window: every grain outside ``lo..hi`` must be inert
        (:func:`active_window`).  The window grows by one grain on a side before each
        substep at which its edge grain is not inert.
    vmax, umax : (N,) float arrays
        Running maxima of v (every step) and u (every ``UMAX_EVERY`` global steps and
        when an event fires), updated in place when ``track``.
    track : bool
        Update the running maxima.
    watch : (W,) int array
        Grains whose velocity peak stops the chunk: with ``wmax[q]`` the running max of
        ``v[watch[q]]`` (updated every step), the chunk returns one step after the first
        step at which ``wmax[q] >= wthr[q]`` and ``v[watch[q]] < wmax[q]`` (that step
        closes the step sequence: v = v^n, a = a^n).
    wmax, wthr : (W,) float arrays
        Running maxima (in/out) and thresholds (m/s) of the watched grains.
    ts_idx : (S,) int array
        Grains whose time series are recorded.
    ts_every : int
        A time-series row is written after every step whose global number is a
        multiple of ``ts_every``.
    step0 : int
        Global number of the step before the chunk (steps are numbered from 1 within it).
    ts_out : (R, S, 4) float array
        Rows of (u, v, left-contact overlap, right-contact overlap).
    nthreads, min_parallel : int
        Use threads when ``nthreads > 1`` and the window has at least ``min_parallel``
        grains (bitwise identical results either way).  The caller sets the number of
        numba threads (``numba.set_num_threads(nthreads)``): the parallel regions use
        them all (a block on one thread runs the same region with one thread).
    block_steps, tile, min_serial_block : int
        Temporal blocking (see above): blocks of up to ``block_steps`` steps on tiles of
        about ``tile`` grains, used with threads (window of at least ``min_parallel``
        grains) or, on one thread, for windows of at least ``min_serial_block`` grains;
        not while a sampled series grain is within reach of the window.  A block that
        overshoots a watched grain's event is rolled back and redone step by step.
        ``block_steps = 0``: never.

    Returns
    -------
    steps, rows, fired, lo, hi : int
        Steps taken (< nsteps if an event fired), time-series rows written, the index
        q of the watched grain whose event fired (-1: none), and the final window.
    """
    n = u.size
    ns = drift.size
    rows = 0
    fired = -1
    # special grains: watched (every step) and series (on sampling steps), sorted unique
    sp_w = np.unique(watch)
    sp_ws = np.unique(np.concatenate((watch, ts_idx)))
    pos_w = np.searchsorted(sp_w, watch)
    pos_ws_w = np.searchsorted(sp_ws, watch)
    pos_ws_s = np.searchsorted(sp_ws, ts_idx)
    vsp = np.empty(sp_ws.size)
    none = np.zeros(0, np.int64)
    nt_max = max(1, nthreads)
    # temporal blocking work arrays
    nsub_max = max(block_steps, 1) * ns
    dcs = np.empty(nsub_max)
    c1s = np.empty(nsub_max)
    c2s = np.empty(nsub_max)
    trks = np.zeros(nsub_max, np.bool_)
    umxs = np.zeros(nsub_max, np.bool_)
    fins = np.zeros(nsub_max, np.bool_)
    vsp2 = np.zeros((nsub_max, sp_w.size))
    keep = watch.size > 0  # a block may overshoot an event: keep the state to roll back
    su = np.empty(n if keep else 0)
    sv = np.empty(n if keep else 0)
    svm = np.empty(n if keep else 0)
    sum_ = np.empty(n if keep else 0)
    swm = np.empty(watch.size)
    no_block_before = 0
    ntile_max = (n // max(tile, 1)) + nt_max + 2
    bnd = np.empty(ntile_max + 1, np.int64)
    ulb_b = np.empty(ntile_max)
    urb_b = np.empty(ntile_max)
    # opening kick of the first step: v^{n+1/2} (or the first stage velocity)
    for i in range(lo, hi + 1):
        v[i] = v[i] + kick[0] * a[i]
    s = 0
    while s < nsteps:
        nb = min(block_steps, nsteps - s)
        if nb >= 4 and fired < 0 and s >= no_block_before:
            nsub = nb * ns
            lo_p = max(lo - nsub, 0)
            hi_p = min(hi + nsub, n - 1)
            width = hi_p - lo_p + 1
            par = nt_max > 1 and width >= max(min_parallel, 4 * nsub)
            ok = par or width >= max(min_serial_block, 2 * tile, 4 * nsub)
            nrow = 0
            if ts_idx.size > 0:
                nrow = (step0 + s + nb) // ts_every - (step0 + s) // ts_every
                if nrow > 0:  # sampled series grains must be out of reach (constant)
                    for q in range(ts_idx.size):
                        if lo_p - 1 <= ts_idx[q] <= hi_p + 1:
                            ok = False
            if ok:
                ntile = max(nt_max if par else 1, width // max(tile, 1))
                ntile = max(1, min(ntile, width // (2 * nsub)))
                for t in range(ntile + 1):
                    bnd[t] = lo_p + (width * t) // ntile
                for t in range(ntile):
                    b0 = bnd[t]
                    b1 = bnd[t + 1]
                    ulb_b[t] = wl if b0 == 0 else u[b0 - 1] + drift[0] * v[b0 - 1]
                    urb_b[t] = wr if b1 == n else u[b1] + drift[0] * v[b1]
                for tau in range(nsub):
                    st = tau % ns
                    sidx = s + 1 + tau // ns
                    final = st == ns - 1
                    dcs[tau] = drift[st]
                    c1s[tau] = kick[st + 1]
                    c2s[tau] = kick[0] if final and sidx != nsteps else 0.0
                    trks[tau] = final and track
                    umxs[tau] = final and track and (step0 + sidx) % UMAX_EVERY == 0
                    fins[tau] = final
                    for q in range(sp_w.size):
                        vsp2[tau, q] = 0.0  # watched grains outside the window: v = 0
                saved = False
                for q in range(watch.size):  # in reach, or armed (may fire with v = 0)
                    if lo_p - 1 <= watch[q] <= hi_p + 1 or wmax[q] >= wthr[q]:
                        saved = True
                if saved:
                    su[lo_p:hi_p + 1] = u[lo_p:hi_p + 1]
                    sv[lo_p:hi_p + 1] = v[lo_p:hi_p + 1]
                    svm[lo_p:hi_p + 1] = vmax[lo_p:hi_p + 1]
                    sum_[lo_p:hi_p + 1] = umax[lo_p:hi_p + 1]
                swm[:] = wmax
                for phase in range(2):
                    _phase(u, v, vmax, umax, inv_m, k, d0, f0, rs, rc, bnd[:ntile + 1], phase,
                           ulb_b[:ntile], urb_b[:ntile], wl, wr, dcs[:nsub], c1s[:nsub],
                           c2s[:nsub], trks[:nsub], umxs[:nsub], fins[:nsub], sp_w, none,
                           vsp2[:nsub], nsub)
                # events, step by step (the per-step test: the last firing grain wins)
                hit = -1
                hit_q = -1
                for tau in range(ns - 1, nsub, ns):
                    for q in range(watch.size):
                        vg = vsp2[tau, pos_w[q]]
                        if vg > wmax[q]:
                            wmax[q] = vg
                        elif wmax[q] >= wthr[q] and vg < wmax[q]:
                            hit = s + 1 + tau // ns
                            hit_q = q
                    if hit >= 0:
                        break
                if hit >= 0 and not (hit + 1 == nsteps and s + nb == nsteps):
                    # the block overshot the event's closing step: roll back and redo the
                    # block step by step (bitwise the same arithmetic), which stops there
                    u[lo_p:hi_p + 1] = su[lo_p:hi_p + 1]
                    v[lo_p:hi_p + 1] = sv[lo_p:hi_p + 1]
                    vmax[lo_p:hi_p + 1] = svm[lo_p:hi_p + 1]
                    umax[lo_p:hi_p + 1] = sum_[lo_p:hi_p + 1]
                    wmax[:] = swm
                    no_block_before = s + nb
                    continue
                fired = hit_q
                # series grains out of reach: constant u and overlaps, v = 0
                for _ in range(nrow):
                    for q in range(ts_idx.size):
                        g = ts_idx[q]
                        ts_out[rows, q, 0] = u[g]
                        ts_out[rows, q, 1] = 0.0
                        ts_out[rows, q, 2] = d0[g] + ((wl if g == 0 else u[g - 1]) - u[g])
                        ts_out[rows, q, 3] = d0[g + 1] + (u[g] - (wr if g == n - 1
                                                                  else u[g + 1]))
                    rows += 1
                s += nb
                lo, hi = active_window(u, v, k, wl, wr, lo_p, hi_p)
                if lo < 0:
                    lo, hi = lo_p, lo_p
                continue
        s += 1
        last = s == nsteps
        sample = ts_idx.size > 0 and (step0 + s) % ts_every == 0
        sp = sp_ws if sample else sp_w
        for st in range(ns):
            # grow the window by one grain on a side whose edge grain is not inert:
            # only its neighbour can start moving during this substep
            if lo > 0 and _active(u, v, k, wl, wr, lo):
                lo -= 1
            if hi < n - 1 and _active(u, v, k, wl, wr, hi):
                hi += 1
            dc = drift[st]
            c1 = kick[st + 1]
            final = st == ns - 1
            # closing kick + the next step's opening kick; only the closing kick at the
            # end of the chunk (a is then recomputed) and between the stages
            c2 = kick[0] if final and not last else 0.0
            trk = final and track
            spq = sp if final else none
            if final:
                for q in range(vsp.size):
                    vsp[q] = 0.0  # special grains outside the window are inert: v = 0
            do_umax = final and track and (step0 + s) % UMAX_EVERY == 0
            ul = wl if lo == 0 else u[lo - 1] + dc * v[lo - 1]
            ur = wr if hi == n - 1 else u[hi + 1] + dc * v[hi + 1]
            _advance(u, v, vmax, umax, inv_m, k, d0, f0, rs, rc, lo, hi + 1, ul, ur, dc, c1,
                     c2, trk, do_umax, spq, vsp)
        # time series and events use the synchronous velocities of the special grains
        if sample:
            for q in range(ts_idx.size):
                g = ts_idx[q]
                ts_out[rows, q, 0] = u[g]
                ts_out[rows, q, 1] = vsp[pos_ws_s[q]]
                ts_out[rows, q, 2] = d0[g] + ((wl if g == 0 else u[g - 1]) - u[g])
                ts_out[rows, q, 3] = d0[g + 1] + (u[g] - (wr if g == n - 1 else u[g + 1]))
            rows += 1
        if fired < 0:
            for q in range(watch.size):
                vg = vsp[pos_ws_w[q]] if sample else vsp[pos_w[q]]
                if vg > wmax[q]:
                    wmax[q] = vg
                elif wmax[q] >= wthr[q] and vg < wmax[q]:
                    fired = q
            if fired >= 0 and not last:
                nsteps = s + 1  # one closing step, then return
    # a^n of the final state (bitwise the values the closing pass used)
    accelerations(u, a, inv_m, k, d0, f0, wl, wr, lo, hi)
    return nsteps, rows, fired, lo, hi


@numba.njit(**_JIT)
def active_window(u, v, k, wl, wr, lo, hi):
    """Smallest [lo', hi'] ⊂ [lo, hi] outside which every grain is inert; (-1, -1) if none.

    A grain is inert if v_i = 0 and both its contacts are unstrained (u_{j-1} = u_j,
    walls included; an absent contact, k = 0, never strains).  Grains outside
    ``[lo, hi]`` must already be inert.
    """
    first = -1
    for i in range(lo, hi + 1):
        if _active(u, v, k, wl, wr, i):
            first = i
            break
    if first < 0:
        return -1, -1
    last = first
    for i in range(hi, first - 1, -1):
        if _active(u, v, k, wl, wr, i):
            last = i
            break
    return first, last


@numba.njit(**_JIT)
def _contact_potential(kj, d0j, r):
    """(2/5) k ([r]_+^{5/2} - δ0^{5/2}), J, without cancellation near r = δ0."""
    if r <= 0.0:
        return -0.4 * kj * d0j * d0j * np.sqrt(d0j)
    if d0j == 0.0:
        return 0.4 * kj * r * r * np.sqrt(r)
    x = (r - d0j) / d0j
    return 0.4 * kj * d0j * d0j * np.sqrt(d0j) * np.expm1(2.5 * np.log1p(x))


@numba.njit(**_JIT)
def contact_energies(u, k, d0, wl, wr, lo, hi, out):
    """out[j] = (2/5) k_j([r_j]_+^{5/2} - δ0_j^{5/2}), contacts lo..hi, J (docs/physics.md §6)."""
    n = u.size
    for j in range(lo, hi + 1):
        ul = wl if j == 0 else u[j - 1]
        ur = wr if j == n else u[j]
        out[j] = _contact_potential(k[j], d0[j], d0[j] + (ul - ur))


@numba.njit(**_JIT)
def grain_energies(u, v, mass, k, d0, wl, wr, lo, hi, ek, ep):
    """Per-grain kinetic ½mv² and potential (half of each contact's energy), J.

    A wall contact belongs wholly to its grain (the wall stores no energy).  Fills
    ek[lo:hi+1], ep[lo:hi+1]; returns (Σ ek, Σ contact energies of lo..hi+1).
    """
    n = u.size
    ul = wl if lo == 0 else u[lo - 1]
    e_l = _contact_potential(k[lo], d0[lo], d0[lo] + (ul - u[lo]))
    tk = 0.0
    tp = e_l
    for i in range(lo, hi + 1):
        ur = wr if i == n - 1 else u[i + 1]
        e_r = _contact_potential(k[i + 1], d0[i + 1], d0[i + 1] + (u[i] - ur))
        kin = 0.5 * mass[i] * v[i] * v[i]
        ek[i] = kin
        ep[i] = (e_l if i == 0 else 0.5 * e_l) + (e_r if i == n - 1 else 0.5 * e_r)
        tk += kin
        tp += e_r
        e_l = e_r
    return tk, tp


@numba.njit(**_JIT)
def shadow_correction(u, v, a, mass, k, d0, wl, wr, lo, hi):
    r"""O(h²) term of velocity Verlet's modified energy divided by h², J/s².

    :math:`\tilde H = H + h^2[\tfrac{1}{12} v^T V'' v - \tfrac{1}{24}\sum m_i a_i^2]`
    (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, 2006, §IX.3 with the
    Strang-splitting BCH formula), with :math:`V'' ` the Hertz stiffness
    :math:`\tfrac32 k_j [r_j]_+^{1/2}` on the contact differences.  Over contacts and
    grains lo..hi (+ contact hi+1).
    """
    n = u.size
    s = 0.0
    for j in range(lo, hi + 2):
        ul = wl if j == 0 else u[j - 1]
        ur = wr if j == n else u[j]
        vl = 0.0 if j == 0 else v[j - 1]
        vr = 0.0 if j == n else v[j]
        r = max(d0[j] + (ul - ur), 0.0)
        dv = vl - vr
        s += (1.0 / 12.0) * 1.5 * k[j] * np.sqrt(r) * dv * dv
    for i in range(lo, hi + 1):
        s -= (1.0 / 24.0) * mass[i] * a[i] * a[i]
    return s
