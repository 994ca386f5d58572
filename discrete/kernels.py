r"""Compiled velocity-Verlet kernels for the Hertz chain (pyro2 style: plain arrays).

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
and stays so until a neighbour moves.  In one step a disturbance moves at most one
grain (the force pass reads the drifted neighbours), so integrating only the window
``[lo, hi]`` outside which every grain is inert, grown by one grain on a side before
each step at which its edge grain is not inert, is bitwise identical to integrating
the whole chain.

Time stepping is velocity Verlet (kick–drift–kick; the paper's Section 2; Swope et al.,
J. Chem. Phys. 76 (1982) 637, Eq. 7):

.. math::
    v^{n+1/2} = v^n + \tfrac{h}{2} a^n,\quad u^{n+1} = u^n + h v^{n+1/2},\quad
    v^{n+1} = v^{n+1/2} + \tfrac{h}{2} a(u^{n+1}).

Each step is two vectorisable passes over the window: the drift u += h v^{n+1/2}, and
the force pass, which applies both half kicks v^n = v^{n-1/2} + (h/2) a^n and
v^{n+1/2} = v^n + (h/2) a^n (the same floating-point operations as kick–drift–kick,
without storing a^n; only the last step of a chunk stores a^n and stops at v^n).  The
recording (running maxima of u and v, the event test on watched grains, time series of
chosen grains) is fused into these passes.  No ``fastmath``: the tests rely on bitwise
determinism.  Measured on this machine (one core, N = 10^4 in cache): the drift-only
first pass makes the kernel ~25 % faster than a kick+drift / force+kick pair.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = [
    "accelerations",
    "run_chunk",
    "active_window",
    "grain_energies",
    "contact_energies",
    "shadow_correction",
]

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}

UMAX_EVERY = 8
"""Steps between updates of the running maximum of u (see :func:`run_chunk`)."""


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


@numba.njit(**_JIT)
def _active(u, v, k, wl, wr, i):
    """Grain i is not inert: it moves, or one of its (present) contacts is strained."""
    n = u.size
    ul = wl if i == 0 else u[i - 1]
    ur = wr if i == n - 1 else u[i + 1]
    return v[i] != 0.0 or (k[i] != 0.0 and ul != u[i]) or (k[i + 1] != 0.0 and ur != u[i])


@numba.njit(**_JIT)
def run_chunk(u, v, a, inv_m, k, d0, f0, wl, wr, dt, nsteps, lo, hi,
              vmax, umax, track, watch, wmax, wthr, ts_idx, ts_every, step0, ts_out):
    """Advance ``nsteps`` velocity-Verlet steps on grains ``lo..hi`` in place.

    Parameters
    ----------
    u, v, a : (N,) float arrays
        Displacements (m), velocities (m/s), accelerations (m/s², consistent with u).
    inv_m, k, d0, f0 : arrays
        1/m (1/kg); contact constants (N/m^{3/2}), static overlaps (m), static forces (N).
    wl, wr : float
        Wall displacements, m.
    dt : float
        Time step, s.
    nsteps, lo, hi : int
        Steps to take and the window: every grain outside ``lo..hi`` must be inert
        (:func:`active_window`).  The window grows by one grain on a side before each
        step at which its edge grain is not inert.
    vmax, umax : (N,) float arrays
        Running maxima of v (every step) and u (every ``UMAX_EVERY`` global steps and
        when an event fires), updated in place when ``track``.
    track : bool
        Update the running maxima.
    watch : (W,) int array
        Grains whose velocity peak stops the chunk: with ``wmax[q]`` the running max of
        ``v[watch[q]]`` (updated every step), the chunk returns one step after the first
        step at which ``wmax[q] >= wthr[q]`` and ``v[watch[q]] < wmax[q]`` (that step
        closes the velocity-Verlet step sequence: v = v^n, a = a^n).
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

    Returns
    -------
    steps, rows, fired, lo, hi : int
        Steps taken (< nsteps if an event fired), time-series rows written, the index
        q of the watched grain whose event fired (-1: none), and the final window.
    """
    n = u.size
    hdt = 0.5 * dt
    rows = 0
    fired = -1
    v_half = np.empty(watch.size + ts_idx.size)  # v^{n-1/2} of the watched/series grains
    s = 0
    while s < nsteps:
        s += 1
        last = s == nsteps  # the closing step ends with a half kick: v = v^n, a = a^n
        # Grow the window by one grain on a side whose edge grain is not inert: only
        # its neighbour can start moving during this step (see the module docstring).
        if lo > 0 and _active(u, v, k, wl, wr, lo):
            lo -= 1
        if hi < n - 1 and _active(u, v, k, wl, wr, hi):
            hi += 1
        # Views starting at the window so that loop indices start at 0 (numba then
        # proves them non-negative, drops the wrap-around test and vectorises).
        m = hi - lo + 1  # window grains
        mi = min(hi, n - 2) - lo + 1  # of which have a right neighbour (else: wall)
        uw, vw, aw, imw = u[lo:hi + 1], v[lo:hi + 1], a[lo:hi + 1], inv_m[lo:hi + 1]
        vmw, umw = vmax[lo:hi + 1], umax[lo:hi + 1]
        ur_w = u[lo + 1:]
        kw, d0w, f0w = k[lo + 1:], d0[lo + 1:], f0[lo + 1:]
        # pass 1: drift u += h v^{n+1/2}; the first step starts with the half kick
        # v^{n+1/2} = v^n + (h/2) a^n.  Every UMAX_EVERY (global) steps the pass also
        # updates the running max of u: u is smooth at its maximum (v = 0 there), so
        # the sampling error is <= |a| (UMAX_EVERY h)²/8.
        if s == 1:
            for i in range(m):
                vw[i] = vw[i] + hdt * aw[i]
        if track and (step0 + s) % UMAX_EVERY == 0:
            for i in range(m):
                ui = uw[i] + dt * vw[i]
                uw[i] = ui
                umw[i] = max(umw[i], ui)
        else:
            for i in range(m):
                uw[i] = uw[i] + dt * vw[i]
        sample = ts_idx.size > 0 and (step0 + s) % ts_every == 0
        for q in range(watch.size):
            v_half[q] = v[watch[q]]
        if sample:
            for q in range(ts_idx.size):
                v_half[watch.size + q] = v[ts_idx[q]]
        # pass 2: forces relative to static (Eq. 1, 2) and the two half kicks
        # v^n = v^{n-1/2} + (h/2) a^n (running max of v taken on it) and
        # v^{n+1/2} = v^n + (h/2) a^n, in one pass (velocity Verlet, same arithmetic);
        # the closing step stores a^n and stops at v^n.
        ul = wl if lo == 0 else u[lo - 1]
        r = max(d0[lo] + (ul - u[lo]), 0.0)
        phi_l = k[lo] * (r * np.sqrt(r)) - f0[lo]
        if last:
            for i in range(mi):
                r = max(d0w[i] + (uw[i] - ur_w[i]), 0.0)
                phi_r = kw[i] * (r * np.sqrt(r)) - f0w[i]
                ai = (phi_l - phi_r) * imw[i]
                aw[i] = ai
                vi = vw[i] + hdt * ai
                vw[i] = vi
                vmw[i] = max(vmw[i], vi) if track else vmw[i]
                phi_l = phi_r
        elif track:
            for i in range(mi):
                r = max(d0w[i] + (uw[i] - ur_w[i]), 0.0)
                phi_r = kw[i] * (r * np.sqrt(r)) - f0w[i]
                ai = (phi_l - phi_r) * imw[i]
                vi = vw[i] + hdt * ai
                vmw[i] = max(vmw[i], vi)
                vw[i] = vi + hdt * ai
                phi_l = phi_r
        else:
            for i in range(mi):
                r = max(d0w[i] + (uw[i] - ur_w[i]), 0.0)
                phi_r = kw[i] * (r * np.sqrt(r)) - f0w[i]
                ai = (phi_l - phi_r) * imw[i]
                vw[i] = (vw[i] + hdt * ai) + hdt * ai
                phi_l = phi_r
        if hi == n - 1:
            r = max(d0[n] + (u[n - 1] - wr), 0.0)
            phi_r = k[n] * (r * np.sqrt(r)) - f0[n]
            ai = (phi_l - phi_r) * inv_m[n - 1]
            vi = v[n - 1] + hdt * ai
            if track:
                vmax[n - 1] = max(vmax[n - 1], vi)
            if last:
                a[n - 1] = ai
                v[n - 1] = vi
            else:
                v[n - 1] = vi + hdt * ai
        # time series and events use v^n = v^{n-1/2} + (h/2) a^n, a^n recomputed with
        # the same arithmetic (bitwise the value of pass 2)
        if sample:
            for q in range(ts_idx.size):
                g = ts_idx[q]
                ts_out[rows, q, 0] = u[g]
                ts_out[rows, q, 1] = v[g] if last else (
                    v_half[watch.size + q] + hdt * _accel(u, inv_m, k, d0, f0, wl, wr, g))
                ts_out[rows, q, 2] = d0[g] + ((wl if g == 0 else u[g - 1]) - u[g])
                ts_out[rows, q, 3] = d0[g + 1] + (u[g] - (wr if g == n - 1 else u[g + 1]))
            rows += 1
        if fired < 0:
            for q in range(watch.size):
                g = watch[q]
                vg = v[g] if last else v_half[q] + hdt * _accel(u, inv_m, k, d0, f0, wl, wr, g)
                if vg > wmax[q]:
                    wmax[q] = vg
                elif wmax[q] >= wthr[q] and vg < wmax[q]:
                    fired = q
            if fired >= 0 and not last:
                nsteps = s + 1  # one closing step, then return
    return nsteps, rows, fired, lo, hi


@numba.njit(**_JIT)
def _accel(u, inv_m, k, d0, f0, wl, wr, g):
    """Acceleration of grain g, m/s², with the arithmetic of :func:`run_chunk`."""
    n = u.size
    ul = wl if g == 0 else u[g - 1]
    r = max(d0[g] + (ul - u[g]), 0.0)
    phi_l = k[g] * (r * np.sqrt(r)) - f0[g]
    ur = wr if g == n - 1 else u[g + 1]
    r = max(d0[g + 1] + (u[g] - ur), 0.0)
    phi_r = k[g + 1] * (r * np.sqrt(r)) - f0[g + 1]
    return (phi_l - phi_r) * inv_m[g]


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
    """out[j] = (2/5) k_j([r_j]_+^{5/2} - δ0_j^{5/2}) for contacts lo..hi (PHYSICS.md §6), J."""
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
