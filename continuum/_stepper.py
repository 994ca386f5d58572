r"""Compiled time loops of the continuum solvers: one call advances a whole chunk of steps.

Each kernel takes plain arrays (the state, preallocated scratch, the medium's face and
node coefficients) and performs ``nsteps`` complete time steps without returning to
Python and without allocating: the stepping, the flux-form right-hand side, the
tridiagonal (Rosenau) solve and the bookkeeping of the active window are fused into
three sweeps over the window per force evaluation (flux divergence; elimination;
back substitution with the kick), the window's new edges found by scans from its ends.
The pieces that do not depend on the contact law are module-level ``@njit(cache=True)``
functions; the passes that evaluate forces are closures over the law's compiled pieces
(its elastic force, energy and damping coefficient, :mod:`theory.laws`), built once per
law by :func:`rosenau_kernels` and :func:`nesterenko_kernels` the way the discrete
solver builds its kernels, and cached on disk under the law's key
(:func:`theory.jitcache.keyed_njit`): compiled once per machine and law.
The NumPy reference of every kernel is the PDE's :meth:`evolution_rate` driven by
py-pde's generic stepping (``backend="numpy"``); the tests compare the two.

Splitting (symplectic) steps
----------------------------
For states (u, v) with u_t = v and v_t = a(u) a step is a sequence of P passes "drift,
kick" and a closing drift (:class:`continuum.solver.VerletSolver`; the letters of
:mod:`continuum.solver`, "Kernel passes": P passes, S force evaluations per step)

.. math:: u \mathrel{+}= \alpha_0 Δt\,v,\quad v \mathrel{+}= \beta_0 Δt\,a(u),\quad
          u \mathrel{+}= \alpha_1 Δt\,v,\quad \dots,\quad v \mathrel{+}= \beta_{P-1} Δt\,a(u),
          \quad u \mathrel{+}= \alpha_P Δt\,v

(position Verlet: P = 1, α = (1/2, 1/2), β = (1,); Yoshida-4: P = 3; a drift-first
method has S = P).  Inside a chunk the last drift of a step and the first of the next
are merged into one (α_P + α_0); a chunk starts with α_0 and ends with α_P, so the
state is synchronous between chunks.

A kick-first method (:mod:`theory.splitting`, S drifts and S + 1 kicks) arrives as
α = (0, a_1, …, a_S, 0), β = (b_1, …, b_{S+1}), P = S + 1
(:func:`continuum.solver.splitting_coefficients`).  With α_0 = α_P = 0 ("first same as
last", :func:`_pass_coefficients`) the kernels skip a step's first pass after the first
step and kick (β_{P-1} + β_0) Δt at the end of the step before it: one force
evaluation where the two kicks act on the same u, so a chunk of n steps costs
n (P - 1) + 1 = n S + 1 evaluations.

Active window (Rosenau form of Eq. 4)
-------------------------------------
Outside the window ``[lo, hi]`` every node is *at rest*: ``|v| <= tau_v`` and the strain
of both its faces ``|s| <= tau_s``.  The mass operator :math:`M = m - \partial_X m\ell^2
\partial_X` is not local: its inverse (the Green's function of the acceleration) decays
by the factor ρ < 1 per node (ρ = 0.51 at 5 nodes per grain, ≈ e^{-√12} per grain),
so the force pass covers ``[lo - margin, hi + margin]`` with ρ^margin < 2^{-60}:

* forward elimination from the window's left edge is exact (the right-hand side is
  zero, to within ``tau``, to its left, so the full sweep's eliminated values are too);
* back substitution starts ``margin`` nodes right of the last active node with x = 0,
  an error below 2^{-60} of the largest acceleration.

With ``tau`` = 2^{-52} of the state's largest strain and velocity (set by the caller)
the windowed step equals the full one to round-off; the window follows the wave (and
shrinks behind it where the medium comes back to rest).  Periodic chains are always
integrated whole (cyclic solve by Sherman–Morrison).

The tridiagonal solve (Rosenau form)
------------------------------------
Elimination a_i = r_i/d_i - g_i a_{i-1} and back substitution x_i = a_i - c_i x_{i+1}
are first-order recurrences: one multiply and one add per node on the dependency chain,
so their latency, not the arithmetic throughput, bounds the sweep; two chains (the
twisted factorisation's two directions) per sweep.  The factors d, g, c reach their
fixed point bit for bit some tens of nodes after each end and each change of the medium
(:func:`constant_runs`), and there the kernel advances four nodes per link, a_{i+3} =
T_3 + g⁴ a_{i-1} with the local sums T off the chain (:func:`_eliminate4`,
:func:`_substitute4`): the same arithmetic as the one-step form to a few ulp (not bit
for bit).  The four-node links shorten the dependency chain about fourfold and make a
drift-and-kick pass about a quarter cheaper; the flux sweep is bound by its loads, so a
vectorised form (each face's flux computed for both its nodes) is no faster (timings:
docs/benchmarks.md, "Design measurements").

Boundary codes (as :mod:`continuum._kernels`): 0 = free, 1 = wall, 2 = periodic.
Nonlinearity codes: 0 = linear K s, 1 = quadratic K s + B s², 2 = the full law
F_el(δ0 + s; k) - f0 (Hertz: k [δ0 + s]_+^{3/2} - f0).  No ``fastmath``: the tests rely on
IEEE arithmetic.

Dissipation
-----------
Velocity-dependent forces — the law's damping c(δ) δ̇ (Kuwabara & Kono; the viscous
long-wave term of Herbold & Nesterenko, Phys. Rev. E 75 (2007) 021304) and the on-site
drag -β m u_t — are split off the conservative forces (Strang): a step is
D(Δt/2) ∘ V(Δt) ∘ D*(Δt/2), V the symplectic splitting above, D the dissipative flow
at fixed positions, which books the energy it removes per node (the state's third
field).  Rosenau form: Crank–Nicolson on the tridiagonal mass operator; regularised
Eq. 7: exact face-by-face flows (diagonal mass).  Both never create energy, are stable
for any Δt, and their booked energy equals the kinetic-energy change to round-off; the
dissipative kernels step one step at a time (no merged passes).
"""

from __future__ import annotations

import sys
from typing import NamedTuple

from theory import jitcache

jitcache.configure()  # compiled kernels cached outside the package (theory/jitcache.py)

import numba as nb  # noqa: E402
import numpy as np  # noqa: E402
from rocket_fft import c2r, r2c  # noqa: E402

from theory.laws import ContactLaw, compile_piece  # noqa: E402

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}
_INNER = {"nogil": True, "error_model": "numpy"}
_CALLEE = {"no_cpython_wrapper": True, "no_cfunc_wrapper": True}
"""A function only compiled code calls: no wrappers for Python or C callers (compile time)."""

FREE, WALL, PERIODIC = 0, 1, 2

_AXES = np.zeros(1, np.int64)  # the one axis of the rocket-fft transforms

WINDOW_LOG2_TOLERANCE = 60
"""The windowed tridiagonal solve neglects terms below 2^-60 of the largest value."""



@nb.njit(inline="always", **_JIT)
def _pass_coefficients(alpha, beta, dt, step, j, nsteps, fsal):
    """Drift and kick (s) of pass j of ``step`` in a chunk, and whether to skip it.

    Drift α_j Δt, merged with the previous step's closing drift (α_P + α_0) Δt for
    ``step`` > 0 and j = 0; kick β_j Δt (P = ``beta.size`` passes).  ``fsal``
    (α_0 = α_P = 0): the first pass of a step after the first is skipped and its kick
    β_0 added to the last pass of the step before (module docstring, "Splitting
    (symplectic) steps").
    """
    nsub = beta.size
    if j == 0 and step > 0:
        if fsal:
            return 0.0, 0.0, True
        return (alpha[nsub] + alpha[0]) * dt, beta[0] * dt, False
    b = beta[j] * dt
    if fsal and j == nsub - 1 and step < nsteps - 1:
        b = (beta[j] + beta[0]) * dt
    return alpha[j] * dt, b, False


@nb.njit(inline="always", **_JIT)
def _eliminate4(y, i0, i1, i2, i3, c1, c2, q2, q3, q4, a):
    """Four elimination steps a_i = y_i c1 - c2 a_{i-1} with constant c1, c2 (in place).

    Written as a_{i+j} = T_j + (-c2)^{j+1} a with the local sums T (a = 0) off the
    dependency chain: one multiply-add per four nodes on it instead of four.  ``q2``,
    ``q3``, ``q4``: c2², -c2³, c2⁴.  The first node is rounded as the one-step form;
    the others differ from it by round-off (a few ulp, damped by |c2| < 1).
    """
    t0 = y[i0] * c1
    t1 = y[i1] * c1 - c2 * t0
    t2 = y[i2] * c1 - c2 * t1
    t3 = y[i3] * c1 - c2 * t2
    y[i0] = t0 - c2 * a
    y[i1] = t1 + q2 * a
    y[i2] = t2 + q3 * a
    a = t3 + q4 * a
    y[i3] = a
    return a


@nb.njit(inline="always", **_JIT)
def _substitute4(y, v, i0, i1, i2, i3, c, q2, q3, q4, beta, a):
    """Four back-substitution steps x_i = y_i - c x_{i±1} with constant c, and the kick.

    As :func:`_eliminate4`: x_{i+j} = S_j + (-c)^{j+1} x with the local sums S off the
    dependency chain; v_i += β x_i.  ``q2``, ``q3``, ``q4``: c², -c³, c⁴.
    """
    s0 = y[i0]
    s1 = y[i1] - c * s0
    s2 = y[i2] - c * s1
    s3 = y[i3] - c * s2
    v[i0] += beta * (s0 - c * a)
    v[i1] += beta * (s1 + q2 * a)
    v[i2] += beta * (s2 + q3 * a)
    a = s3 + q4 * a
    v[i3] += beta * a
    return a


@nb.njit(inline="always", **_JIT)
def _node_active(u, v, i, n, ih, tau_s, tau_v):
    """Node i moves (|v| > tau_v) or one of its interior faces is strained (> tau_s)."""
    if abs(v[i]) > tau_v:
        return True
    if i > 0 and abs((u[i - 1] - u[i]) * ih) > tau_s:
        return True
    if i < n - 1 and abs((u[i] - u[i + 1]) * ih) > tau_s:
        return True
    return False


def rosenau_factors(diag, off, corner):
    """Factors of the symmetric (cyclic) tridiagonal matrix (diag, off, corner).

    Returns ``(fac, z, vfac)``.  ``fac`` (8 × N) holds the elimination from the top
    (inv_t = 1/den_t, g_t_i = off_{i-1}/den_t_i, cp_t_i = off_i/den_t_i), from the
    bottom (inv_b, g_b_i = off_i/den_b_i, cp_b_i = off_{i-1}/den_b_i), the inverse
    twisted pivots d_k - off_{k-1} cp_t_{k-1} - off_k cp_b_{k+1} (Meurant, SIAM J.
    Matrix Anal. Appl. 13 (1992) 707: the "twisted" factorisation) and off itself.  A cyclic matrix
    (``corner`` ≠ 0) uses the top elimination of the Sherman–Morrison-modified matrix
    with the vector z and scalars ``vfac`` (Press et al., *Numerical Recipes*, 3rd ed.,
    §2.7.2; zeros otherwise).
    """
    from ._kernels import tridiag_factor

    d = np.asarray(diag, float)
    e = np.asarray(off, float)
    n = d.size
    den, cp, offp, z, vfac = tridiag_factor(d, e, float(corner))
    fac = np.zeros((8, n))
    fac[0] = 1.0 / den
    fac[1, 1:] = offp[:-1] * fac[0, 1:]
    fac[2] = cp
    if corner == 0.0:
        den_b = np.empty(n)
        den_b[-1] = d[-1]
        for i in range(n - 2, -1, -1):
            den_b[i] = d[i] - e[i] * e[i] / den_b[i + 1]
        fac[3] = 1.0 / den_b
        fac[4, :-1] = e * fac[3, :-1]
        fac[5, 1:] = e * fac[3, 1:]
        piv = d.copy()
        piv[1:] -= e * cp[:-1]
        piv[:-1] -= e * e * fac[3, 1:]
        fac[6] = 1.0 / piv
        fac[7, :-1] = e
    return fac, z, vfac


def constant_runs(fac) -> np.ndarray:
    """Lengths of the runs of bitwise-constant factors that the Rosenau pass meets.

    Row r, node i: how many consecutive nodes, starting at i in the direction sweep
    r walks, carry exactly the factors of node i — 0: elimination from the top,
    ascending (``fac`` rows 0, 1: inv_t, g_t); 1: from the bottom, descending (rows 3,
    4); 2: back substitution towards the top, descending (row 2, cp_t); 3: towards the
    bottom, ascending (row 5, cp_b).  The factor recurrences of :func:`rosenau_factors`
    reach their fixed point (bit for bit) some tens of nodes after each end and each
    change of the medium, so the runs cover all but those nodes.
    """
    fac = np.asarray(fac, float)
    n = fac.shape[1]
    out = np.empty((4, n), np.int32)  # (a run is at most n < 2^31 nodes long)
    idx = np.arange(n)
    for r, (rows, up) in enumerate((((0, 1), True), ((3, 4), False), ((2,), False),
                                    ((5,), True))):
        x = fac[list(rows)]
        same = np.all(x[:, 1:] == x[:, :-1], axis=0)  # node i + 1 equals node i
        if up:  # run from i upwards ends before the first change above i
            starts = np.r_[np.flatnonzero(~same) + 1, n]
            out[r] = starts[np.searchsorted(starts, idx, side="right")] - idx
        else:  # run from i downwards ends after the last change below i
            ends = np.r_[-1, np.flatnonzero(~same)]
            out[r] = idx - ends[np.searchsorted(ends, idx, side="left") - 1]
    return out


def window_margin(fac) -> int:
    """Nodes over which the mass operator's Green's function falls below 2^-60.

    The smallest m such that every product of m consecutive back-substitution factors
    |cp_t| and |cp_b| (rows 2 and 5 of :func:`rosenau_factors`) is below 2^-60: the
    truncation error of the Rosenau chunk's windowed solve relative to the largest
    value (at least 2).
    """
    target = -WINDOW_LOG2_TOLERANCE * np.log(2.0)
    worst = 0
    for f in (np.asarray(fac[2], float)[:-1], np.asarray(fac[5], float)[1:]):
        if f.size == 0:
            continue
        lf = np.log(np.maximum(np.abs(f), 1e-300))
        c = np.r_[0.0, np.cumsum(lf)]
        m = f.size
        for m in range(1, f.size + 1):
            if np.max(c[m:] - c[:-m]) < target:
                break
        worst = max(worst, m)
    return max(2, worst + 1)


# ------------------------------------------------------------------------------ Nesterenko
@nb.njit(**_JIT)
def fft_size(need):
    """Smallest length m >= ``need`` that is a multiple of 8 with no prime factor above 5.

    The real FFT pair of :func:`_saturated_apply` (DUCC through rocket-fft) is about a
    third cheaper per m log2 m at such lengths than at odd ones or ones divisible only by
    2 or 4 (timings: docs/benchmarks.md, "Design measurements"); rocket-fft's
    ``good_size`` returns the smallest 5-smooth length, often odd (3375 = 3³5³ for a need
    of 3,350, where 3456 = 2⁷3³ is faster).
    """
    m = max(8, need + (-need) % 8)
    while True:
        r = m // 8
        for p in (2, 3, 5):
            while r % p == 0:
                r //= p
        if r == 1:
            return m
        m += 8


@nb.njit(**_JIT, **_CALLEE)
def _rfft(x, out):
    """Real FFT of x into out (unscaled; DUCC through rocket-fft), out.size = x.size//2 + 1.

    One compiled copy shared by every call site of the Nesterenko kernels: rocket-fft's
    overloads are expanded at each call, so calling them in one place halves the
    first compilation of :func:`_saturated_apply` (docs/physics.md §4).
    """
    r2c(x, out, _AXES, True, 1.0, 1)


@nb.njit(**_JIT, **_CALLEE)
def _irfft(x, out):
    """Inverse real FFT of x into out, scaled by 1/out.size (the inverse of :func:`_rfft`)."""
    c2r(x, out, _AXES, False, 1.0 / out.size, 1)


@nb.njit(inline="always", **_JIT)
def _direct_sum(ncomp, w):
    """Apply H by a direct sum over the ``ncomp`` compressed faces (else an FFT over w)."""
    return ncomp * ncomp <= 40 * w + 2000


@nb.njit(**_JIT, **_CALLEE)
def _saturated_apply(y, hy, qa, qb, comp, ncomp, c, spec, fft_re, fft_c, fstate, periodic):
    """hy[q] = (H y)[q] for the faces that need it, y zero outside ``comp``/[qa, qb].

    Periodic: the circulant with the real multiplier ``spec`` (DUCC real FFTs of the
    chain's length, through rocket-fft).  Otherwise the restriction of the
    infinite-lattice Toeplitz operator (kernel ``c``): a direct sum over the
    ``ncomp`` faces listed in ``comp`` when that is cheaper, else a zero-padded real
    FFT over the faces [qa, qb] of a length m ≥ 2 (qb - qa) + 1 (``fstate[0]``, chosen
    by :func:`fft_size`; the spectrum of the embedded kernel for that length is kept in
    ``spec`` and recomputed when m changes).  No allocation.
    """
    nf = y.size
    if periodic:
        m = nf
        nh = m // 2 + 1
        _rfft(y, fft_c[:nh])
        for i in range(nh):
            fft_c[i] *= spec[i]
        _irfft(fft_c[:nh], hy)
        return
    w = qb - qa + 1
    need = 2 * w - 1
    m = fstate[0]
    if _direct_sum(ncomp, w):
        for q in range(qa, qb + 1):
            hy[q] = 0.0
        for a in range(ncomp):
            q = comp[a]
            acc = 0.0
            for b in range(ncomp):
                p = comp[b]
                d = q - p if q >= p else p - q
                acc += c[d] * y[p]
            hy[q] = acc
        return
    if need > m or 5 * need < 4 * m:
        m = fft_size(need)
        fstate[0] = m
        # spectrum of the circulant of length m holding the Toeplitz matrix
        for i in range(m):
            fft_re[i] = 0.0
        nc = min(m // 2, c.size)
        fft_re[0] = c[0]
        for j in range(1, nc):
            fft_re[j] = c[j]
            fft_re[m - j] = c[j]
        nh = m // 2 + 1
        _rfft(fft_re[:m], fft_c[:nh])
        for i in range(nh):
            spec[i] = fft_c[i].real
    nh = m // 2 + 1
    yw = y[qa:qb + 1]
    for i in range(w):
        fft_re[i] = yw[i]
    pad = fft_re[w:m]
    for i in range(m - w):
        pad[i] = 0.0
    _rfft(fft_re[:m], fft_c[:nh])
    for i in range(nh):
        fft_c[i] *= spec[i]
    _irfft(fft_c[:nh], fft_re[:m])
    hw = hy[qa:qb + 1]
    for i in range(w):
        hw[i] = fft_re[i]


@nb.njit(**_JIT, **_CALLEE)
def _table_overlap(u, q, gidx, gcoef, d0, dl):
    """dl[q] = [d0_q + Σ_j gcoef[q, j] u[gidx[q, j]]]_+ (the stencil table's row q)."""
    sq_ = 0.0
    for j in range(gidx.shape[1]):
        sq_ += gcoef[q, j] * u[gidx[q, j]]
    x = d0[q] + sq_
    dl[q] = 0.0 if x < 0.0 else x  # (NaN kept)


@nb.njit(inline="always", **_JIT)
def _nesterenko_kick(v, L, R, beta, bc, h, gidx, gcoef, fh, inv_m):
    """Kick v_i += β Δt (-Gᵀ F)_i / m_i of nodes [L, R] by the face forces ``fh``.

    The node force density -Gᵀ F is the transpose of the strain stencil: the plain
    weights where faces i-1 .. i+2 are interior faces inside [qa, qb] (nodes [ja, jb]),
    else the scatter of the table; one loop for both orders (second order: weights 1
    and 0 over h, i.e. (F_i - F_{i+1})/h).
    """
    n = v.size
    width = gidx.shape[1]
    qa = L
    qb = R if bc == PERIODIC else R + 1
    ja = max(L, max(qa, 2) + 1)
    jb = min(R, min(qb, n - 2) - 2)
    for i in range(L, min(ja, R + 1)):
        _table_kick(v, i, beta, bc, qa, qb, gidx, gcoef, fh, inv_m)
    for i in range(max(jb + 1, ja, L), R + 1):
        _table_kick(v, i, beta, bc, qa, qb, gidx, gcoef, fh, inv_m)
    if jb < ja:
        return
    if width == 4:
        w1, w3, den = 27.0, 1.0, 24.0 * h
    else:
        w1, w3, den = 1.0, 0.0, h
    mj = jb + 1 - ja
    vj = v[ja:jb + 1]
    im = inv_m[ja:jb + 1]
    ff = fh[ja - 1:jb + 3]  # ff[j] = fh[i - 1] for i = ja + j
    for j in range(mj):
        f = (w1 * (ff[j + 1] - ff[j + 2]) - w3 * (ff[j] - ff[j + 3])) / den
        vj[j] += beta * f * im[j]


@nb.njit(inline="always", **_JIT)
def _shrink_window(v, dl, lo, hi, tau_v, tau_d, win):
    """Shrink the active window [lo, hi] of Eq. 7's stepper to the nodes still moving.

    A node is active if its speed exceeds ``tau_v`` or an adjacent face's overlap change
    exceeds ``tau_d``; ``win`` gets the first and last active node, (-1, -1) if none.
    """
    new_lo = -1
    for i in range(lo, hi + 1):
        if abs(v[i]) > tau_v or dl[i] > tau_d or dl[i + 1] > tau_d:
            new_lo = i
            break
    if new_lo < 0:
        win[0] = -1
        win[1] = -1
        return
    new_hi = new_lo
    for i in range(hi, new_lo, -1):
        if abs(v[i]) > tau_v or dl[i] > tau_d or dl[i + 1] > tau_d:
            new_hi = i
            break
    win[0] = new_lo
    win[1] = new_hi


@nb.njit(**_JIT, **_CALLEE)
def _table_kick(v, i, beta, bc, qa, qb, gidx, gcoef, fh, inv_m):
    """Kick of node i by the scatter -Gᵀ F of the stencil table (faces in [qa, qb])."""
    width = gidx.shape[1]
    half = width // 2
    nf = fh.size
    f = 0.0
    for d in range(1 - half, half + 1):
        q = i + d
        if bc == PERIODIC:
            q = q % nf
        elif q < qa or q > qb:
            continue
        for j in range(width):
            if gidx[q, j] == i:
                f -= gcoef[q, j] * fh[q]
    v[i] += beta * f * inv_m[i]


# ------------------------------------------------------------------------------ kernels of a law
def _kernel_key(law: ContactLaw, kind: str) -> str:
    """Disk-cache key of the kernels of ``law``: its key and the sources they compile.

    This module and the file of every :class:`~theory.laws.ContactLaw` class in the
    law's MRO (:func:`theory.jitcache.source_digest`, once per law class and process):
    editing a law or a kernel recompiles.
    """
    cls = type(law)
    if cls not in _DIGESTS:
        classes = [c for c in cls.__mro__ if isinstance(c, type) and issubclass(c, ContactLaw)]
        _DIGESTS[cls] = jitcache.source_digest(sys.modules[__name__], *classes)
    return f"{kind}|{law.key()!r}|{_DIGESTS[cls]}"


_DIGESTS: dict[type, str] = {}

_STATIC: dict[str, object] = {}


def _static_forces(law: ContactLaw):
    """``static_forces(d0, k, out)``: F_el(δ0; k) into ``out`` (N), with the kernels' arithmetic.

    The law's compiled elastic force (:meth:`~theory.laws.ContactLaw.make_elastic`), as
    the passes evaluate it, so that the dynamic force F_el(δ0 + s) - f0 is exactly 0 at
    s = 0.  One compiled kernel per law, shared by the Rosenau and Eq. 7 kernels.
    """
    key = _kernel_key(law, "static")
    if key not in _STATIC:
        elastic = law.make_elastic()

        def static_forces(d0, k, out):
            for i in range(d0.size):
                out[i] = elastic(d0[i], k[i])

        _STATIC[key] = jitcache.keyed_njit(static_forces, key, **_INNER)
    return _STATIC[key]


def power_piece(q: float):
    """Compiled x ↦ x^q for x >= 0: √√x, √x, √x·√√x, x, x√x for q = 1/4 … 3/2, else x**q.

    The powers of the dispersive term of the strongly nonlinear equation
    (φ = δ^{(n-1)/2}: δ^{1/4} for Hertz, formed as √√δ as the kernels always have).
    """
    q = float(q)
    if q == 0.0:
        def power(x):
            return 1.0
    elif q == 0.25:
        def power(x):
            return np.sqrt(np.sqrt(x))
    elif q == 0.5:
        def power(x):
            return np.sqrt(x)
    elif q == 0.75:
        def power(x):
            return np.sqrt(x) * np.sqrt(np.sqrt(x))
    elif q == 1.0:
        def power(x):
            return x
    elif q == 1.5:
        def power(x):
            return x * np.sqrt(x)
    else:
        def power(x):
            return x**q
    return compile_piece(power)


class RosenauKernels(NamedTuple):
    """The compiled kernels of the Rosenau form for one law and flux (:func:`rosenau_kernels`)."""

    chunk: object
    """``chunk(u, v, y, nsteps, dt, alpha, beta, h, bc, kk, bb, kh, d0, f0, fac, runs,
    win, margin, tau_s, tau_v)``: free or wall ends, active window."""
    chunk_periodic: object
    """``chunk_periodic(u, v, y, nsteps, dt, alpha, beta, h, kk, bb, kh, d0, f0, fac,
    z, vfac)``: a periodic chain, swept whole."""
    chunk_dissipative: object
    """``chunk_dissipative(u, v, wd, y, nsteps, dt, alpha, beta, h, bc, kk, bb, kh, d0,
    f0, fac, runs, win, mdiag, moff, wface, mass, drag, p, ad, ao, x, cp)``: Strang
    splitting with the dissipative Crank–Nicolson sub-steps, swept whole."""
    monitor: object
    """``monitor(u, v, h, bc, kk, bb, kh, d0, f0, mass, wgrad, w) -> (E, P)``."""
    static_forces: object
    """``static_forces(d0, k, out)``: F_el(δ0; k) with the kernels' arithmetic."""
    window_pass: object
    """``window_pass(u, v, y, L, R, alpha, beta, h, bc, kk, bb, kh, d0, f0, fac, runs,
    tau_s, tau_v, win)``: one drift and kick over nodes [L, R] (for tests)."""


_ROSENAU: dict[str, RosenauKernels] = {}


def rosenau_kernels(law: ContactLaw, nl: int) -> RosenauKernels:
    """The kernels of the Rosenau form closed over ``law``'s compiled pieces; built once.

    Like the discrete solver's kernels (``discrete.kernels.make_kernels``): the law's
    elastic force, energy and damping coefficient (``make_elastic``, ``make_energy``,
    ``make_damping``, inlined) are fused into the passes below, which are compiled per
    law key with a keyed disk cache (:func:`theory.jitcache.keyed_njit`).

    The flux's nonlinearity code ``nl`` (0 linear, 1 quadratic, 2 the full law: module
    docstring) is a constant of the kernels, not an argument: numba drops the flux
    branches of the other codes before typing them, so that a kernel compiles only the
    flux it evaluates (the full law's force and energy only for ``nl`` = 2).
    """
    if nl not in (0, 1, 2):
        raise ValueError(f"nl must be 0 (linear), 1 (quadratic) or 2 (full law), got {nl!r}")
    key = _kernel_key(law, f"rosenau{nl}")
    if key not in _ROSENAU:
        _ROSENAU[key] = _build_rosenau(law, key, int(nl))
    return _ROSENAU[key]


def _build_rosenau(law: ContactLaw, key: str, nl: int) -> RosenauKernels:  # noqa: C901
    elastic = law.make_elastic()
    energy = law.make_energy()
    damping = law.make_damping()

    def inner(func, **options):
        options = options or _CALLEE
        return jitcache.keyed_njit(func, key, cache=False, **_INNER, **options)

    def entry(func):
        return jitcache.keyed_njit(func, key, **_INNER)

    def flux(s, kq, bq, khq, d0q, f0q):
        """Dynamic contact force P(s) at one face, N (see the nonlinearity codes)."""
        if nl == 0:
            return kq * s
        if nl == 1:
            return (kq + bq * s) * s
        return elastic(d0q + s, khq) - f0q

    flux = inner(flux, inline="always")

    def rosenau_pass(u, v, y, L, R, alpha, beta, h, bc, kk, bb, kh, d0, f0, fac, runs,
                     tau_s, tau_v, win):
        """One drift (α Δt) and one kick (β Δt) over nodes [L, R], non-periodic ends.

        Sweep A (the drift vectorised; the flux of each face carried to the next node):
        drift, face strains and fluxes, flux divergence r_i.  Sweep B: the "burn at both
        ends" (twisted) factorisation of the tridiagonal mass operator, eliminating from L
        upwards and from R downwards at the same time (two independent dependency chains)
        to the twist node k; sweep C: back substitution outwards from k with the kick.
        Where the factors are constant (``runs``, :func:`constant_runs`: everywhere but a
        few tens of nodes at the chain's ends and its interfaces) B and C advance four
        nodes per link of their dependency chains (:func:`_eliminate4`,
        :func:`_substitute4`).  ``win`` receives the new active window.
        """
        n = u.size
        ih = 1.0 / h
        inv_t, g_t, cp_t, inv_b, g_b, cp_b = fac[0], fac[1], fac[2], fac[3], fac[4], fac[5]
        twist, off = fac[6], fac[7]
        # ---- sweep A (on views of the window: no negative-index checks, vectorisable)
        m_ = R + 1 - L
        uu = u[L:R + 1]
        vv = v[L:R + 1]
        yy = y[L:R + 1]
        for i in range(m_):
            uu[i] += alpha * vv[i]
        if L == 0:
            s = -2.0 * u[0] * ih if bc == WALL else 0.0
        else:
            s = (u[L - 1] - u[L]) * ih
        p_prev = flux(s, kk[L], bb[L], kh[L], d0[L], f0[L])
        k1 = kk[L + 1:R + 2]
        b1 = bb[L + 1:R + 2]
        if nl == 1:
            for i in range(m_ - 1):
                s = (uu[i] - uu[i + 1]) * ih
                p = (k1[i] + b1[i] * s) * s
                yy[i] = (p_prev - p) * ih
                p_prev = p
        else:
            h1 = kh[L + 1:R + 2]
            z1 = d0[L + 1:R + 2]
            f1 = f0[L + 1:R + 2]
            for i in range(m_ - 1):
                s = (uu[i] - uu[i + 1]) * ih
                p = flux(s, k1[i], b1[i], h1[i], z1[i], f1[i])
                yy[i] = (p_prev - p) * ih
                p_prev = p
        if R == n - 1:
            s = 2.0 * u[n - 1] * ih if bc == WALL else 0.0
        else:
            s = (u[R] - u[R + 1]) * ih
        q = R + 1
        y[R] = (p_prev - flux(s, kk[q], bb[q], kh[q], d0[q], f0[q])) * ih
        # ---- sweep B: eliminate L -> k-1 (a) and R -> k+1 (b)
        k = (L + R) // 2
        nt = k - L
        nb_ = R - k
        a = 0.0
        b = 0.0
        i = L
        j = R
        while i < k and j > k:
            r = min(runs[0, i], runs[1, j], k - i, j - k)
            if r >= 4:
                c1, c2, d1, d2 = inv_t[i], g_t[i], inv_b[j], g_b[j]
                p2 = c2 * c2
                e2 = d2 * d2
                p3, p4, e3, e4 = -(p2 * c2), p2 * p2, -(e2 * d2), e2 * e2
                for _ in range(r // 4):
                    a = _eliminate4(y, i, i + 1, i + 2, i + 3, c1, c2, p2, p3, p4, a)
                    b = _eliminate4(y, j, j - 1, j - 2, j - 3, d1, d2, e2, e3, e4, b)
                    i += 4
                    j -= 4
            else:
                a = y[i] * inv_t[i] - g_t[i] * a
                y[i] = a
                i += 1
                b = y[j] * inv_b[j] - g_b[j] * b
                y[j] = b
                j -= 1
        # the chains advance together and nb_ - nt is 0 or 1: the top chain is done, at
        # most one node of the bottom one is left
        if j > k:
            b = y[j] * inv_b[j] - g_b[j] * b
            y[j] = b
        # twist node: (d_k - e_{k-1} cp_t[k-1] - e_k cp_b[k+1]) x_k = r_k - e_{k-1} a - e_k b
        rk = y[k]
        if nt > 0:
            rk -= off[k - 1] * a
        if nb_ > 0:
            rk -= off[k] * b
        xk = rk * twist[k]
        v[k] += beta * xk
        # ---- sweep C: back substitution k-1 -> L (a) and k+1 -> R (b), kick
        a = xk
        b = xk
        i = k - 1
        j = k + 1
        while i >= L and j <= R:
            r = min(runs[2, i], runs[3, j], i - L + 1, R - j + 1)
            if r >= 4:
                c, d = cp_t[i], cp_b[j]
                p2 = c * c
                e2 = d * d
                p3, p4, e3, e4 = -(p2 * c), p2 * p2, -(e2 * d), e2 * e2
                for _ in range(r // 4):
                    a = _substitute4(y, v, i, i - 1, i - 2, i - 3, c, p2, p3, p4, beta, a)
                    b = _substitute4(y, v, j, j + 1, j + 2, j + 3, d, e2, e3, e4, beta, b)
                    i -= 4
                    j += 4
            else:
                a = y[i] - cp_t[i] * a
                v[i] += beta * a
                i -= 1
                b = y[j] - cp_b[j] * b
                v[j] += beta * b
                j += 1
        if j <= R:  # (at most one node left, of the bottom chain, as in sweep B)
            b = y[j] - cp_b[j] * b
            v[j] += beta * b
        # ---- new active window: scan inwards from both edges
        lo = -1
        for i in range(L, R + 1):
            if _node_active(u, v, i, n, ih, tau_s, tau_v):
                lo = i
                break
        if lo < 0:
            win[0] = -1
            win[1] = -1
            return
        hi = lo
        for i in range(R, lo, -1):
            if _node_active(u, v, i, n, ih, tau_s, tau_v):
                hi = i
                break
        win[0] = lo
        win[1] = hi

    window_pass = nb.njit(**_INNER)(rosenau_pass)  # (for tests; compiled when called)
    rosenau_pass = inner(rosenau_pass)

    def rosenau_pass_periodic(u, v, y, alpha, beta, h, kk, bb, kh, d0, f0,
                              inv_den, g, cp, z, vfac):
        """One drift and one kick over a periodic chain (cyclic Thomas, Sherman–Morrison)."""
        n = u.size
        ih = 1.0 / h
        for i in range(n):
            u[i] += alpha * v[i]
        s = (u[n - 1] - u[0]) * ih
        p0 = flux(s, kk[0], bb[0], kh[0], d0[0], f0[0])
        p_prev = p0
        yp = 0.0
        for i in range(1, n):
            s = (u[i - 1] - u[i]) * ih
            p = flux(s, kk[i], bb[i], kh[i], d0[i], f0[i])
            yp = (p_prev - p) * ih * inv_den[i - 1] - g[i - 1] * yp
            y[i - 1] = yp
            p_prev = p
        y[n - 1] = (p_prev - p0) * ih * inv_den[n - 1] - g[n - 1] * yp
        x = 0.0
        for i in range(n - 1, -1, -1):
            x = y[i] - cp[i] * x
            y[i] = x
        f = (y[0] + vfac[0] * y[n - 1]) / vfac[1]
        for i in range(n):
            v[i] += beta * (y[i] - f * z[i])

    rosenau_pass_periodic = inner(rosenau_pass_periodic)

    def rosenau_chunk(u, v, y, nsteps, dt, alpha, beta, h, bc, kk, bb, kh, d0, f0,
                      fac, runs, win, margin, tau_s, tau_v):
        """Advance the Rosenau form of Eq. 4 by ``nsteps`` steps of ``dt`` (s), in place.

        Free or wall ends (periodic chains: :func:`rosenau_chunk_periodic`, a kernel of its
        own so that neither compiles the other's pass).

        Parameters
        ----------
        u, v : float64[N]
            Node displacements (m) and velocities (m/s).
        y : float64[N]
            Scratch.
        alpha, beta : float64[P+1], float64[P]
            Drift and kick coefficients of the splitting (module docstring).
        h, bc :
            Node spacing (grains), boundary code.
        kk, bb, kh, d0, f0 : float64[faces]
            Linear stiffness K = F'(δ0) (N/m), quadratic coefficient b = F''(δ0)/2 (N/m²;
            K/(4δ0) for Hertz), contact constant (N/m^n), static overlap (m) and static
            force F_el(δ0) (N) per face.
        fac :
            Factors of the mass operator (:func:`rosenau_factors`).
        runs : int32[4, N]
            Lengths of their constant runs (:func:`constant_runs`).
        win : int64[2]
            Active window [lo, hi] (in/out; lo = -1: the chain is at rest).
        margin : int
            Nodes solved beyond the active window on either side.
        tau_s, tau_v : float
            At-rest thresholds for strain (m) and velocity (m/s).

        Returns
        -------
        int
            Node-updates performed (nodes swept times force evaluations).
        """
        n = u.size
        nsub = beta.size
        fsal = alpha[0] == 0.0 and alpha[nsub] == 0.0
        work = 0
        for step in range(nsteps):
            for j in range(nsub):
                a, b, skip = _pass_coefficients(alpha, beta, dt, step, j, nsteps, fsal)
                if skip:
                    continue
                if win[0] < 0:
                    # at rest: drifts are no-ops (v = 0 to within tau), kicks vanish
                    continue
                lo = max(win[0] - margin, 0)
                hi = min(win[1] + margin, n - 1)
                rosenau_pass(u, v, y, lo, hi, a, b, h, bc, kk, bb, kh, d0, f0, fac, runs,
                              tau_s, tau_v, win)
                work += hi - lo + 1
        # closing drift α_P
        a = alpha[nsub] * dt
        if nsteps > 0 and win[0] >= 0:
            lo = max(win[0] - margin, 0)
            hi = min(win[1] + margin, n - 1)
            for i in range(lo, hi + 1):
                u[i] += a * v[i]
        return work


    def rosenau_chunk_periodic(u, v, y, nsteps, dt, alpha, beta, h, kk, bb, kh, d0, f0,
                               fac, z, vfac):
        """``rosenau_chunk`` for a periodic chain, swept whole (cyclic solve).

        ``fac``, ``z``, ``vfac``: the Sherman–Morrison factors of :func:`rosenau_factors`.
        Returns the node-updates performed.
        """
        n = u.size
        nsub = beta.size
        fsal = alpha[0] == 0.0 and alpha[nsub] == 0.0
        passes = 0
        for step in range(nsteps):
            for j in range(nsub):
                a, b, skip = _pass_coefficients(alpha, beta, dt, step, j, nsteps, fsal)
                if skip:
                    continue
                rosenau_pass_periodic(u, v, y, a, b, h, kk, bb, kh, d0, f0,
                                       fac[0], fac[1], fac[2], z, vfac)
                passes += 1
        if nsteps > 0:
            a = alpha[nsub] * dt
            for i in range(n):
                u[i] += a * v[i]
        return passes * n


    def rosenau_monitor(u, v, h, bc, kk, bb, kh, d0, f0, mass, wgrad, w):
        """Energy functional (J) and momentum (kg m/s) of the Rosenau form of Eq. 4.

        E = h Σ_p ½ m_p v_p² + h Σ_q w_q [½ m_q ℓ² (v_X)_q² + W(s_q)] with ``wgrad`` =
        w_q m_q ℓ² and W the dynamic potential of the flux (``BoussinesqPDE.potential``);
        P = h Σ m_p v_p.  Non-finite values propagate (NaN/inf state → NaN/inf energy).
        """
        n = u.size
        ih = 1.0 / h
        ek = 0.0
        mom = 0.0
        for i in range(n):
            ek += mass[i] * v[i] * v[i]
            mom += mass[i] * v[i]
        ek *= 0.5
        nf = kk.size
        ep = 0.0
        for q in range(nf):
            if bc == PERIODIC:
                im = q - 1 if q > 0 else n - 1
                s = (u[im] - u[q]) * ih
                dv = (v[q] - v[im]) * ih
            elif q == 0 or q == n:
                if bc == WALL:
                    s = -2.0 * u[0] * ih if q == 0 else 2.0 * u[n - 1] * ih
                    dv = 2.0 * v[0] * ih if q == 0 else -2.0 * v[n - 1] * ih
                else:
                    s = 0.0
                    dv = 0.0
            else:
                s = (u[q - 1] - u[q]) * ih
                dv = (v[q] - v[q - 1]) * ih
            if nl == 0:
                pot = 0.5 * kk[q] * s * s
            elif nl == 1:
                pot = 0.5 * kk[q] * s * s + bb[q] * s * s * s / 3.0
            else:
                pot = energy(d0[q] + s, kh[q], d0[q]) - f0[q] * s
            ep += w[q] * pot + 0.5 * wgrad[q] * dv * dv
        return h * (ek + ep), h * mom



    def rosenau_dissipate(u, v, wd, tau, h, bc, kh, d0, mdiag, moff, wface, mass, drag, p,
                          ad, ao, x, cp):
        """Dissipative sub-step: (M + τ/2 A) v' = (M - τ/2 A) v, booked into ``wd`` (J).

        A = Gᵀ diag(w c) G + β m (symmetric, >= 0): the viscous flux c(δ) ṡ of every
        face (the law's damping coefficient at the overlap δ0 + s, positions fixed) and
        the drag; M the Rosenau mass operator (bands ``mdiag``, ``moff``).  Crank–
        Nicolson: unconditionally stable and dissipative, the kinetic energy falls by
        exactly h τ v̄ᵀ A v̄ (v̄ = (v + v')/2), booked per node as h τ v̄_i (A v̄)_i.
        Free or wall ends (module docstring of :mod:`continuum.boussinesq`).
        """
        n = u.size
        ih = 1.0 / h
        for i in range(n):
            ad[i] = drag * mass[i]
        for i in range(n - 1):
            ao[i] = 0.0
        if bc == WALL:
            e0 = damping(d0[0] - 2.0 * u[0] * ih, kh[0], p) * wface[0] * ih * ih
            en = damping(d0[n] + 2.0 * u[n - 1] * ih, kh[n], p) * wface[n] * ih * ih
            ad[0] += 4.0 * e0
            ad[n - 1] += 4.0 * en
        for q in range(1, n):
            e = damping(d0[q] + (u[q - 1] - u[q]) * ih, kh[q], p) * wface[q] * ih * ih
            ad[q - 1] += e
            ad[q] += e
            ao[q - 1] -= e
        ht = 0.5 * tau
        # right-hand side (M - τ/2 A) v into x; forward elimination of M + τ/2 A
        for i in range(n):
            r = (mdiag[i] - ht * ad[i]) * v[i]
            if i > 0:
                r += (moff[i - 1] - ht * ao[i - 1]) * v[i - 1]
            if i < n - 1:
                r += (moff[i] - ht * ao[i]) * v[i + 1]
            x[i] = r
        den = mdiag[0] + ht * ad[0]
        x[0] = x[0] / den
        for i in range(1, n):
            o = moff[i - 1] + ht * ao[i - 1]
            cp[i - 1] = o / den
            den = mdiag[i] + ht * ad[i] - o * cp[i - 1]
            x[i] = (x[i] - o * x[i - 1]) / den
        for i in range(n - 2, -1, -1):
            x[i] -= cp[i] * x[i + 1]
        # v̄ into x, booking, v' = 2 v̄ - v
        for i in range(n):
            x[i] = 0.5 * (v[i] + x[i])
        for i in range(n):
            av = ad[i] * x[i]
            if i > 0:
                av += ao[i - 1] * x[i - 1]
            if i < n - 1:
                av += ao[i] * x[i + 1]
            wd[i] += h * tau * x[i] * av
        for i in range(n):
            v[i] = 2.0 * x[i] - v[i]

    rosenau_dissipate = inner(rosenau_dissipate)

    def rosenau_chunk_dissipative(u, v, wd, y, nsteps, dt, alpha, beta, h, bc, kk, bb,
                                  kh, d0, f0, fac, runs, win, mdiag, moff, wface, mass,
                                  drag, p, ad, ao, x, cp):
        """Advance the dissipative Rosenau form by ``nsteps`` steps of ``dt`` (s), in place.

        Strang splitting D(Δt/2) ∘ V(Δt) ∘ D(Δt/2): V the symplectic splitting of the
        elastic forces (the passes of ``rosenau_chunk``, whole chain, each step's
        passes unmerged), D the Crank–Nicolson dissipative sub-step of
        ``rosenau_dissipate`` (which books the dissipated energy in ``wd``, J per node).
        Free or wall ends.  Returns the node-updates performed.
        """
        n = u.size
        nsub = beta.size
        work = 0
        for _ in range(nsteps):
            rosenau_dissipate(u, v, wd, 0.5 * dt, h, bc, kh, d0, mdiag, moff, wface, mass,
                              drag, p, ad, ao, x, cp)
            for j in range(nsub):
                rosenau_pass(u, v, y, 0, n - 1, alpha[j] * dt, beta[j] * dt, h, bc, kk,
                             bb, kh, d0, f0, fac, runs, 0.0, 0.0, win)
                work += n
            a = alpha[nsub] * dt
            for i in range(n):
                u[i] += a * v[i]
            rosenau_dissipate(u, v, wd, 0.5 * dt, h, bc, kh, d0, mdiag, moff, wface, mass,
                              drag, p, ad, ao, x, cp)
        win[0] = 0
        win[1] = n - 1
        return work

    return RosenauKernels(entry(rosenau_chunk), entry(rosenau_chunk_periodic),
                          entry(rosenau_chunk_dissipative), entry(rosenau_monitor),
                          _static_forces(law), window_pass)



class NesterenkoKernels(NamedTuple):
    """The compiled kernels of the regularised Eq. 7 for one law (:func:`nesterenko_kernels`)."""

    chunk: object
    """``chunk(u, v, nsteps, dt, alpha, beta, bc, h, gidx, gcoef, w, k, d0, f0, sk, z0,
    mask, eps, disp, inv_m, c, spec, <9 scratch arrays>, win, windowed, margin, tau_v,
    tau_d, mass, mon)`` (``nesterenko_chunk`` of the law)."""
    chunk_dissipative: object
    """The same with the dissipated energy ``wd`` after ``v`` and the drag rate, law
    parameters after ``mon``: Strang splitting with the exact dissipative face flows."""
    static_forces: object
    """``static_forces(d0, k, out)``: F_el(δ0; k) with the kernels' arithmetic."""
    zeta: object
    """``zeta(x, eps, out)``: ζ(x) = x φ(x) continued below ``eps``, the kernels' arithmetic."""


_NESTERENKO: dict[tuple, NesterenkoKernels] = {}


def nesterenko_kernels(law: ContactLaw) -> NesterenkoKernels:
    r"""The kernels of the regularised Eq. 7 closed over ``law``'s compiled pieces; built once.

    The elastic force, its energy and damping coefficient come from the law; the
    dispersive term's powers from its exponent n: φ = δ^{(n-1)/2}, ζ = δ φ =
    δ^{(n+1)/2} (:class:`continuum.nesterenko.NesterenkoPDE`), continued below the floor
    ε as ζ = ε φ(ε) (a r² + 1 - a), φ = φ(ε) r (r = δ/ε, a = (n+1)/4: C¹ at r = 1).
    """
    key = _kernel_key(law, "nesterenko")
    if key not in _NESTERENKO:
        _NESTERENKO[key] = _build_nesterenko(law, key)
    return _NESTERENKO[key]


def _build_nesterenko(law: ContactLaw, key: str) -> NesterenkoKernels:  # noqa: C901
    elastic = law.make_elastic()
    energy = law.make_energy()
    damping = law.make_damping()
    n_exp = float(law.exponent)
    phi = power_piece(0.5 * (n_exp - 1.0))
    ca = 0.25 * (n_exp + 1.0)  # ζ's continuation below the floor: ε φ(ε) (ca r² + cb)
    cb = 1.0 - ca
    n1 = n_exp + 1.0

    def inner(func, **options):
        options = options or _CALLEE
        return jitcache.keyed_njit(func, key, cache=False, **_INNER, **options)

    def entry(func):
        return jitcache.keyed_njit(func, key, **_INNER)


    def nesterenko_faces(u, qa, qb, h, gidx, gcoef, k, d0, f0, sk, z0, mask, eps, dl, fh, ph, y,
                         comp):
        """Overlap δ, elastic flux F_el(δ) - f0, φ and y = mask √k (ζ(δ) - ζ0) per face.

        Faces [qa, qb]; the strain is s_q = Σ_j gcoef[q, j] u[gidx[q, j]]
        (:func:`continuum._kernels.staggered_gradient`), with the plain weights (1/h and 0,
        or 27/24h and 1/24h) written out for the faces 2 <= q <= n - 2 (interior for either
        order, whose stencil rows are the plain ones: checked by the caller,
        :meth:`NesterenkoPDE.make_chunk_stepper`) in a loop without branches.  Returns
        how many faces carry a nonzero y or φ; when H is then applied by a direct sum
        (:func:`_direct_sum`) they are listed in ``comp``.
        """
        width = gidx.shape[1]
        n = u.size
        e4 = phi(eps)
        e54 = eps * e4
        # one loop for both orders (one compiled copy): the four-point formula, whose outer
        # weight is 0 at second order (then x = δ0 + (u_{q-1} - u_q)/h exactly)
        if width == 4:
            c1, c3 = 27.0 / (24.0 * h), 1.0 / (24.0 * h)
        else:
            c1, c3 = 1.0 / h, 0.0
        ia = max(qa, 2)
        ib = min(qb, n - 2)
        # overlaps δ of the interior faces.  Every hot loop runs over zero-based views with
        # a zero-based index, so that numba emits no negative-index wrap-around check and
        # LLVM vectorises it (with an index starting at a runtime value it does neither)
        if ib >= ia:
            mi = ib + 1 - ia
            dd = dl[ia:ib + 1]
            zz = d0[ia:ib + 1]
            uu = u[ia - 2:ib + 2]  # uu[i] = u[q - 2] for q = ia + i
            for i in range(mi):
                x = zz[i] + (c1 * (uu[i + 1] - uu[i + 2]) - c3 * (uu[i] - uu[i + 3]))
                dd[i] = 0.0 if x < 0.0 else x  # (NaN kept)
        # end faces [qa, ia) and (ib, qb]: the stencil table
        for q in range(qa, min(ia, qb + 1)):
            _table_overlap(u, q, gidx, gcoef, d0, dl)
        for q in range(max(ib + 1, ia), qb + 1):
            _table_overlap(u, q, gidx, gcoef, d0, dl)
        mf = qb + 1 - qa
        dd = dl[qa:qb + 1]
        kq, f0q, mq = k[qa:qb + 1], f0[qa:qb + 1], mask[qa:qb + 1]
        skq, z0q = sk[qa:qb + 1], z0[qa:qb + 1]
        fq, pq, yq = fh[qa:qb + 1], ph[qa:qb + 1], y[qa:qb + 1]
        for i in range(mf):
            x = dd[i]
            fq[i] = elastic(x, kq[i]) - f0q[i]
            r4 = phi(x)
            r = x / eps
            # ζ = x φ, φ above the floor, else their C¹ continuation (NesterenkoPDE):
            # both computed, one selected (no branch)
            zq = x * r4 if x >= eps else e54 * (ca * r * r + cb)
            pq[i] = (r4 if x >= eps else e4 * r) * mq[i]
            yq[i] = mq[i] * skq[i] * (zq - z0q[i])
        ncomp = 0
        for i in range(mf):
            ncomp += (yq[i] != 0.0) | (pq[i] != 0.0)
        if _direct_sum(ncomp, mf):
            m = 0
            for q in range(qa, qb + 1):
                if y[q] != 0.0 or ph[q] != 0.0:
                    comp[m] = q
                    m += 1
        return ncomp

    nesterenko_faces = inner(nesterenko_faces)

    def nesterenko_forces(u, L, R, bc, h, gidx, gcoef, w, k, d0, f0, sk, z0, mask, eps, disp,
                          c, spec, fft_re, fft_c, fstate, dl, fh, ph, y, hy, comp):
        """Face forces of the regularised Eq. 7 for nodes [L, R], into ``fh`` (N).

        Sweeps: faces (δ, elastic flux, φ, y: ``nesterenko_faces``); the saturated
        operator H y (:func:`_saturated_apply`); F = w (F_el(δ) - f0) + disp √k φ H y.
        Leaves δ, y and H y in ``dl``, ``y``, ``hy`` (the monitor's energy reads them).
        """
        qa = L
        qb = R if bc == PERIODIC else R + 1
        ncomp = nesterenko_faces(u, qa, qb, h, gidx, gcoef, k, d0, f0, sk, z0, mask, eps, dl,
                                  fh, ph, y, comp)
        _saturated_apply(y, hy, qa, qb, comp, ncomp, c, spec, fft_re, fft_c, fstate,
                         bc == PERIODIC)
        # face forces F (zero outside [qa, qb]: there δ = 0, see nesterenko_chunk) into fh
        fq, wq, skq, pq, hq = (fh[qa:qb + 1], w[qa:qb + 1], sk[qa:qb + 1], ph[qa:qb + 1],
                               hy[qa:qb + 1])
        for i in range(qb + 1 - qa):
            fq[i] = wq[i] * fq[i] + disp * skq[i] * pq[i] * hq[i]

    nesterenko_forces = inner(nesterenko_forces, inline="always")

    def nesterenko_energy(u, v, bc, h, gidx, gcoef, w, k, d0, f0, disp, mass, dl, y, hy):
        """Energy functional (J) and momentum (kg m/s) of the regularised Eq. 7.

        E = h Σ ½ m v² + h Σ_q [w_q (U(δ) - U(δ0) - f0_q s_q) + (disp/(n+1)) y_q (Hy)_q]
        (U the law's elastic energy; NesterenkoPDE.energy_density), P = h Σ m v, from δ, y and
        H y of every face (``nesterenko_forces`` over the whole chain).
        """
        n = u.size
        ek = 0.0
        mom = 0.0
        for i in range(n):
            ek += mass[i] * v[i] * v[i]
            mom += mass[i] * v[i]
        qb = n - 1 if bc == PERIODIC else n
        ep = 0.0
        width = gidx.shape[1]
        for q in range(qb + 1):
            x = dl[q]
            s = 0.0
            for j in range(width):
                s += gcoef[q, j] * u[gidx[q, j]]
            pot = energy(x, k[q], d0[q]) - f0[q] * s
            ep += w[q] * pot + (disp / n1) * y[q] * hy[q]
        return h * (0.5 * ek + ep), h * mom

    nesterenko_energy = inner(nesterenko_energy)

    def nesterenko_chunk(u, v, nsteps, dt, alpha, beta, bc, h, gidx, gcoef, w, k, d0, f0, sk, z0,
                         mask, eps, disp, inv_m, c, spec, fft_re, fft_c, fstate, dl, fh, ph, y, hy,
                         comp, win, windowed, margin, tau_v, tau_d, mass, mon):
        """Advance the regularised Eq. 7 by ``nsteps`` steps of ``dt`` (s), in place.

        With ``windowed`` (sonic vacuum, non-periodic) only nodes [lo - margin, hi + margin]
        are swept, ``win`` = [lo, hi] being the nodes that move (|v| > tau_v) or touch a
        compressed face (δ > tau_d): outside, δ = 0 and v = 0 (to 2^-52 of the wave's
        values), so the flux (elastic and dispersive, the latter ∝ φ(δ) = 0) vanishes, and a
        disturbance reaches at most ``margin`` nodes per force evaluation (1 for the
        second-order stencil, 3 for the fourth-order one).  Otherwise the whole chain is
        swept.  Returns the node-updates performed.

        With ``mon.size == 2`` it then writes the energy functional (J) and momentum
        (kg m/s) of the state into ``mon`` (``nesterenko_energy``; ``mass`` in kg per
        grain).  The monitor is this kernel with ``nsteps`` = 0 and scratch arrays of its
        own: one compiled kernel, in which the face pass and H are called from one place
        (the loop's last evaluation is the monitor's), so that they are compiled once —
        this kernel's first compilation is the continuum's largest.
        """
        n = u.size
        nsub = beta.size
        fsal = alpha[0] == 0.0 and alpha[nsub] == 0.0
        nev = nsteps * nsub
        work = 0
        for e in range(nev + 1):
            if e < nev:
                step = e // nsub
                j = e - step * nsub
                a, b, skip = _pass_coefficients(alpha, beta, dt, step, j, nsteps, fsal)
                if skip:
                    continue
                if windowed:
                    if win[0] < 0:
                        continue
                    lo = max(win[0] - margin, 0)
                    hi = min(win[1] + margin, n - 1)
                else:
                    lo = 0
                    hi = n - 1
                uu = u[lo:hi + 1]
                vv = v[lo:hi + 1]
                for i in range(hi + 1 - lo):
                    uu[i] += a * vv[i]
            else:
                # closing drift α_P, then (monitor) the whole chain's forces and energy
                if nsteps > 0:
                    a = alpha[nsub] * dt
                    if windowed:
                        if win[0] >= 0:
                            for i in range(max(win[0] - margin, 0),
                                           min(win[1] + margin, n - 1) + 1):
                                u[i] += a * v[i]
                    else:
                        for i in range(n):
                            u[i] += a * v[i]
                if mon.size != 2:
                    break
                lo = 0
                hi = n - 1
            nesterenko_forces(u, lo, hi, bc, h, gidx, gcoef, w, k, d0, f0, sk, z0, mask, eps,
                               disp, c, spec, fft_re, fft_c, fstate, dl, fh, ph, y, hy, comp)
            if e == nev:
                en, mo = nesterenko_energy(u, v, bc, h, gidx, gcoef, w, k, d0, f0, disp, mass, dl,
                                            y, hy)
                mon[0] = en
                mon[1] = mo
                break
            _nesterenko_kick(v, lo, hi, b, bc, h, gidx, gcoef, fh, inv_m)
            work += hi - lo + 1
            if windowed:
                _shrink_window(v, dl, lo, hi, tau_v, tau_d, win)
        return work



    def nesterenko_dissipate(u, v, wd, tau, lo, hi, bc, h, gidx, gcoef, w, k, d0, p, inv_m,
                             mass, drag, forward):
        """Dissipative sub-step of nodes [lo, hi] at fixed positions, booked into ``wd`` (J).

        The face flows m v̇ = -w_q c_q g_q (g_qᵀ v), g_q the face's strain stencil and c_q
        the law's damping coefficient at its overlap, solved exactly one face at a time:
        z = g_qᵀ v relaxes as z e^{-λτ}, λ = w_q c_q g_qᵀ M⁻¹ g_q, at constant momentum,
        and the kinetic energy falls by exactly h (z² - z'²)/(2 g_qᵀ M⁻¹ g_q).  Faces in
        the residue classes q mod (stencil width) in turn (the faces of one class have
        disjoint stencils), ascending (``forward``) or in the reverse order, so that the
        forward and backward sub-steps compose symmetrically; the drag
        v ← v e^{-βτ} first (forward) or last.  Free or wall ends.
        """
        width = gidx.shape[1]
        qa = lo
        qb = hi + 1
        if forward and drag > 0.0:
            f = np.exp(-drag * tau)
            for i in range(lo, hi + 1):
                v1 = v[i] * f
                wd[i] += 0.5 * h * mass[i] * (v[i] * v[i] - v1 * v1)
                v[i] = v1
        for rr in range(width):
            r = rr if forward else width - 1 - rr
            first = qa + (r - qa) % width
            count = 0 if first > qb else (qb - first) // width + 1
            for t in range(count):
                q = first + t * width if forward else first + (count - 1 - t) * width
                x = d0[q]
                for j in range(width):
                    x += gcoef[q, j] * u[gidx[q, j]]
                if not x > 0.0:
                    continue
                c = damping(x, k[q], p) * w[q]
                if c == 0.0:
                    continue
                z = 0.0
                gam = 0.0
                for j in range(width):
                    z += gcoef[q, j] * v[gidx[q, j]]
                    for jj in range(width):
                        if gidx[q, jj] == gidx[q, j]:
                            gam += gcoef[q, j] * gcoef[q, jj] * inv_m[gidx[q, j]]
                if not gam > 0.0:
                    continue
                z1 = z * np.exp(-c * gam * tau)
                a = (z - z1) / gam
                for j in range(width):
                    v[gidx[q, j]] -= inv_m[gidx[q, j]] * gcoef[q, j] * a
                wd[gidx[q, width // 2 - 1]] += 0.5 * h * (z * z - z1 * z1) / gam
        if not forward and drag > 0.0:
            f = np.exp(-drag * tau)
            for i in range(lo, hi + 1):
                v1 = v[i] * f
                wd[i] += 0.5 * h * mass[i] * (v[i] * v[i] - v1 * v1)
                v[i] = v1

    nesterenko_dissipate = inner(nesterenko_dissipate)

    def nesterenko_chunk_dissipative(u, v, wd, nsteps, dt, alpha, beta, bc, h, gidx, gcoef,
                                     w, k, d0, f0, sk, z0, mask, eps, disp, inv_m, c, spec,
                                     fft_re, fft_c, fstate, dl, fh, ph, y, hy, comp, win,
                                     windowed, margin, tau_v, tau_d, mass, drag, p):
        """Advance the dissipative regularised Eq. 7 by ``nsteps`` steps of ``dt`` (s).

        Strang splitting D(Δt/2) ∘ V(Δt) ∘ D*(Δt/2): V the symplectic splitting of the
        conservative forces (the passes of ``nesterenko_chunk``, each step's unmerged),
        D the exact dissipative face flows of ``nesterenko_dissipate`` (forward, D* in
        reverse), over the active window in the sonic vacuum (outside it every face is
        open: no damping), else the whole chain.  Free or wall ends.  Returns the
        node-updates performed.
        """
        n = u.size
        nsub = beta.size
        work = 0
        for _ in range(nsteps):
            if windowed and win[0] < 0:
                break  # at rest
            lo = max(win[0] - margin, 0) if windowed else 0
            hi = min(win[1] + margin, n - 1) if windowed else n - 1
            nesterenko_dissipate(u, v, wd, 0.5 * dt, lo, hi, bc, h, gidx, gcoef, w, k, d0,
                                 p, inv_m, mass, drag, True)
            for j in range(nsub):
                if windowed:
                    if win[0] < 0:
                        break
                    lo = max(win[0] - margin, 0)
                    hi = min(win[1] + margin, n - 1)
                a = alpha[j] * dt
                for i in range(lo, hi + 1):
                    u[i] += a * v[i]
                nesterenko_forces(u, lo, hi, bc, h, gidx, gcoef, w, k, d0, f0, sk, z0, mask,
                                  eps, disp, c, spec, fft_re, fft_c, fstate, dl, fh, ph, y,
                                  hy, comp)
                _nesterenko_kick(v, lo, hi, beta[j] * dt, bc, h, gidx, gcoef, fh, inv_m)
                work += hi - lo + 1
                if windowed:
                    _shrink_window(v, dl, lo, hi, tau_v, tau_d, win)
            if windowed:
                if win[0] < 0:
                    break
                lo = max(win[0] - margin, 0)
                hi = min(win[1] + margin, n - 1)
            a = alpha[nsub] * dt
            for i in range(lo, hi + 1):
                u[i] += a * v[i]
            nesterenko_dissipate(u, v, wd, 0.5 * dt, lo, hi, bc, h, gidx, gcoef, w, k, d0,
                                 p, inv_m, mass, drag, False)
        return work

    def zeta(x, eps, out):
        """ζ(x) into ``out`` with the kernels' arithmetic (``nesterenko_faces``)."""
        e4 = phi(eps)
        e54 = eps * e4
        for i in range(x.size):
            xi = x[i]
            r = xi / eps
            out[i] = xi * phi(xi) if xi >= eps else e54 * (ca * r * r + cb)

    return NesterenkoKernels(entry(nesterenko_chunk), entry(nesterenko_chunk_dissipative),
                             _static_forces(law), entry(zeta))



# ------------------------------------------------------------------------------ KdV
@nb.njit(**_JIT)
def _kdv_stage(src, base, acc, dst, wa, wd, mode, a1, a3, nl, h):
    """One RK4 stage of the KdV rate (periodic), fused with the stage updates.

    k_i = -a1 s_X - a3 s_XXX - nl (s s_X + (s²)_X) of ``src`` (central differences:
    s_X = (s_{i+1} - s_{i-1})/2h, s_XXX = (s_{i+2} - 2 s_{i+1} + 2 s_{i-1} - s_{i-2})/2h³,
    as py-pde's ``d_dx(d2_dx2 s)``).  mode 0: acc = base + wa k, dst = base + wd k;
    mode 1: acc += wa k, dst = base + wd k; mode 2: base = acc + wa k.
    """
    n = src.size
    i2h = 0.5 / h
    i2h3 = 0.5 / (h * h * h)
    for i in range(n):
        im2 = i - 2 if i >= 2 else i - 2 + n
        im1 = i - 1 if i >= 1 else n - 1
        ip1 = i + 1 if i + 1 < n else i + 1 - n
        ip2 = i + 2 if i + 2 < n else i + 2 - n
        sm2, sm1, s0, sp1, sp2 = src[im2], src[im1], src[i], src[ip1], src[ip2]
        sx = (sp1 - sm1) * i2h
        sxxx = ((sp2 - sp1) - (sp1 - s0) - (s0 - sm1) + (sm1 - sm2)) * i2h3
        s2x = (sp1 * sp1 - sm1 * sm1) * i2h
        k = -a1 * sx - a3 * sxxx - nl * (s0 * sx + s2x)
        if mode == 0:
            acc[i] = base[i] + wa * k
            dst[i] = base[i] + wd * k
        elif mode == 1:
            acc[i] += wa * k
            dst[i] = base[i] + wd * k
        else:
            base[i] = acc[i] + wa * k


@nb.njit(**_JIT)
def kdv_chunk(s, acc, sa, sb, nsteps, dt, a1, a3, nl, h):
    """Advance the KdV reduction of Eq. 4 by ``nsteps`` classical RK4 steps, in place.

    ``acc``, ``sa``, ``sb`` are scratch arrays of the size of ``s``.  Returns the node
    updates (points times stages).
    """
    for _ in range(nsteps):
        _kdv_stage(s, s, acc, sa, dt / 6.0, 0.5 * dt, 0, a1, a3, nl, h)
        _kdv_stage(sa, s, acc, sb, dt / 3.0, 0.5 * dt, 1, a1, a3, nl, h)
        _kdv_stage(sb, s, acc, sa, dt / 3.0, dt, 1, a1, a3, nl, h)
        _kdv_stage(sa, s, acc, sa, dt / 6.0, 0.0, 2, a1, a3, nl, h)
    return 4 * nsteps * s.size


@nb.njit(**_JIT)
def kdv_monitor(s, h):
    """The KdV invariants ∫s² dX (m² grains) and ∫s dX (m grains) of a periodic state."""
    m1 = 0.0
    m2 = 0.0
    for i in range(s.size):
        m1 += s[i]
        m2 += s[i] * s[i]
    return h * m2, h * m1
