r"""Compiled time-stepping kernels for the chain, built per contact law (pyro2 style arrays).

Equation of motion (paper Eq. 2) with a contact law :math:`F(\delta, \dot\delta; k)`
(:mod:`theory.laws`; Hertz, paper Eq. 1, by default), written relative to the static
force :math:`f_{0,j} = F(\delta_{0,j}, 0; k_j)`:

.. math::
    m_i \ddot u_i = \varphi_i - \varphi_{i+1} - m_i\beta\dot u_i,\qquad
    \varphi_j = F(r_j, \dot r_j; k_j) - f_{0,j},\qquad
    r_j = \delta_{0,j} + (u_{j-1} - u_j)

(u in m, forces in N, :math:`u_{-1} = w_L`, :math:`u_N = w_R` the walls, β ≥ 0 an
optional on-site drag rate in 1/s).  Since every static force is the same F0 (force
equilibrium), subtracting f0 per contact changes Eq. 2 by at most one rounding error
of F0; it makes a grain at rest with unstrained contacts (:math:`u_{j-1} = u_j`,
evaluated as a difference first so that :math:`r_j = \delta_{0,j}` *exactly*) have
exactly zero acceleration: it is *inert* and stays so until a neighbour moves.  In one
(sub)step a disturbance moves at most one grain (the force pass reads the drifted
neighbours), so integrating only the window ``[lo, hi]`` outside which every grain is
inert, grown by one grain on a side before each substep at which its edge grain is not
inert, is bitwise identical to integrating the whole chain.

One law, one kernel
-------------------
:func:`make_kernels` builds the kernels of one contact law (and drag or not): it asks
the law for its compiled force (``law.make_force()``, an ``inline="always"`` scalar
function) and closes the passes below over it, the way py-pde compiles operators into
closures.  Kernels are built once per :meth:`ContactLaw.key <theory.laws.ContactLaw.key>`
and process, and compiled lazily: a run compiles (or loads from numba's disk cache)
only the entry points it calls.  Numba's own cache cannot key a closure (it pickles
the closed-over dispatchers, whose pickle changes every process), so each entry point
gets a cache keyed by the law's key and a digest of the kernel sources
(:func:`theory.jitcache.keyed_njit`).

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

Dissipation
-----------
*Velocity-dependent forces* — a dissipative law :math:`F = \max(0, F_{el}(r) + c(r)\dot
r)` (:mod:`theory.laws`, :math:`c \ge 0` in N·s/m) and the on-site drag
:math:`-m_i\beta v_i` — are split off the elastic force (Strang splitting):

.. math::
    \Phi_h = \mathcal D^*_{h/2}\circ \mathcal V_h \circ \mathcal D_{h/2},

with :math:`\mathcal V_h` velocity Verlet for the elastic forces only (the passes
below, unchanged: symplectic) and :math:`\mathcal D_\tau` the dissipative flow at
*fixed positions*, :math:`M\dot v = -C(u)\,v` (C a weighted graph Laplacian of the
contacts plus the diagonal drag), itself composed of exactly solved pieces: the drag
:math:`v_i \leftarrow v_i e^{-\beta\tau}`, then the even contacts, then the odd
contacts (each set a family of disjoint pairs, :math:`\mathcal D^*` in the reverse
order), and per contact j between grains L = j-1 and R = j (a wall: 1/m = 0, v = 0)
the exact relaxation of the relative velocity :math:`w = v_L - v_R = \dot r_j` at
constant momentum,

.. math::
    w' = w\,e^{-c_j s_j\tau},\quad s_j = \tfrac1{m_L} + \tfrac1{m_R},\quad
    P_j = \max\!\Big(\frac{w - w'}{s_j},\ -\tau F_{el}(r_j)\Big),\quad
    v_L \mathrel{-}= \frac{P_j}{m_L},\ v_R \mathrel{+}= \frac{P_j}{m_R}

(P the impulse, N·s, of the damping force over τ; the clip keeps the contact's mean
force over the sub-step :math:`F_{el} + P/\tau \ge 0`: no attraction).  Exactly,
:math:`\tfrac12 m_L(v_L'^2 - v_L^2) + \tfrac12 m_R(v_R'^2 - v_R^2) = -P_j\,\bar w`
with :math:`\bar w = \tfrac12(w + w')`, and :math:`P_j\bar w \ge 0` (P has the sign
of w and :math:`|sP| \le |w|`): the sub-step never creates energy, is stable for any
h, and the energy it removes, :math:`P_j\bar w` (and :math:`\tfrac12 m_i(v_i^2 -
v_i'^2)` for the drag), is what the kernels book in ``dis`` (J) — the integrator's own
discrete work, equal to the kinetic-energy change of the sub-step to round-off.  The
energy balance :math:`E + D - E(0)` then carries only velocity Verlet's own O(h²)
energy error.  All pieces are exact flows, so :math:`\Phi_h` is symmetric and
second order where the forces are smooth (measured in ``tests/discrete/test_laws.py``);
c = 0 (γ → 0) makes :math:`\mathcal D` the identity, bitwise.  The velocity passes
do not record on this path: the synchronous velocity is the one after
:math:`\mathcal D^*`, where ``step`` records it.  A dissipative sub-step moves at most
two grains beyond the window (one per contact set); the window grows to them.  This
path is velocity Verlet only, step by step (no temporal blocking, one thread).

Passes
------
One substep is **one fused pass** over the window: at grain i it drifts grain i+1
(``u += a_s h v``, stored), evaluates contact i+1 from the two drifted positions, and
kicks grain i with the contact forces on both sides (the left one carried from the
previous grain).  Per grain and substep the pass reads u, v and the running maximum of
v and writes u, v and the maximum (:func:`_raised`, one ``maxpd``).  The per-grain and
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

* **temporal blocking** (trapezoid tiles, see the section above ``trapezoid``):
  a block advances the window by up to 256 substeps in two phases of independent
  tiles, each tile staying in L2 while it takes its substeps;
* **threads**: the tiles of a phase run concurrently (numba ``prange``, two parallel
  regions per block) — results are bitwise identical with 1 or more threads and with
  or without blocking (``tests/discrete/test_parallel.py``);
* **events inside a block**: the synchronous velocities of watched grains are recorded
  per step; if a block overshoots an event it is rolled back (state kept at the block
  start while a watched grain is within reach) and redone step by step.

The recording (running maxima of v every step, of u every ``UMAX_EVERY`` steps, the
event test on watched grains, time series of chosen grains) is fused into these passes;
the refined maxima of v between the steps (section "Refined maxima" in ``_build``) run
after each step's final substep on the same range, per grain.
No ``fastmath``: the tests rely on bitwise determinism.

Compile time: numba inlines an ``inline="always"`` function by copying its IR into
every caller before typing (and runs its untyped passes again at every call site), so
the first compile grows with the inlined code.  The one-per-substep or rarer pieces
(``piece``, ``energy_row``, ``take_row``, ``block``, ``dissipate``, and the entry
point ``accelerations`` a chunk calls at its end and at an energy row, already
compiled for the simulation's start) are separate compiled functions without wrappers
for Python callers (LLVM may still inline them); the per-grain helpers stay inlined so
that the fused loops vectorise, and so does ``step`` (as a function of its own it
compiles faster but adds a call with its argument handling to every step of a small
window).  This about halves the first compile (docs/benchmarks.md, "Design
measurements", has the timings).  The
chunk's set-up uses no numba overloads of NumPy's sorting and searching
(:func:`_sorted_distinct`), and the kernel without temporal blocking compiles none of
the blocking code (``make_run_chunk``): a first run compiles about a third less
(docs/benchmarks.md, "First-run compilation").

Arguments are grouped in tuples (numba passes them at no cost): ``st = (u, v, a, dis)``
the state (displacements m, velocities m/s, accelerations m/s², dissipated energy
booked per contact J), ``con = (inv_m, k, d0, f0, rs, rc)`` the chain constants
(1/kg, N/m^n, m, N and the run table of :func:`chain_runs`), ``p`` the runtime law
parameters with the drag rate β (1/s) last.
"""

from __future__ import annotations

import hashlib
import os
import sys
from typing import NamedTuple

# Threads that wait at the end of a parallel region sleep instead of spinning: on a
# shared machine a spinning thread takes the core from the thread it waits for
# (docs/benchmarks.md, "Kernel threads on a shared machine").  libgomp reads this when
# numba first starts its threads (any numba.get_num_threads() call), so it is set before
# numba is imported; a setting of the user's is kept.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numba  # noqa: E402
import numba.extending  # noqa: E402
import numpy as np  # noqa: E402

from theory import jitcache  # noqa: E402
from theory.jitcache import keyed_njit, source_digest  # noqa: E402
from theory.laws import N_PARAMS, ContactLaw, as_law  # noqa: E402

from .interpolation import hermite_max_from  # noqa: E402

jitcache.configure()  # compiled kernels cached outside the package (theory/jitcache.py)

__all__ = ["Kernels", "make_kernels", "batch_kernel", "kernel_params", "chain_runs",
           "active_window",
           "UMAX_EVERY", "RUNS_MIN_LENGTH", "PEAK_ROWS"]

_JIT = {"cache": True, "nogil": True, "error_model": "numpy"}
_INNER = {"nogil": True, "error_model": "numpy"}
_INLINE = {"inline": "always", **_INNER}
_CALLEE = {"no_cpython_wrapper": True, "no_cfunc_wrapper": True, **_INNER}
"""A function only compiled code calls: no wrappers for Python or C callers (compile time)."""

UMAX_EVERY = 8
"""Steps between updates of the running maximum of u (see ``run_chunk``)."""

RUNS_MIN_LENGTH = 32
"""Mean run length from which :func:`chain_runs` returns a run table (else: arrays)."""


def chain_runs(inv_m, k, d0, f0, min_length: int = RUNS_MIN_LENGTH):
    """Runs of grains with equal constants, for ``run_chunk``.

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


def kernel_params(law: ContactLaw, drag: float = 0.0) -> np.ndarray:
    """The runtime parameter vector ``p`` of the kernels: the law's, then the drag rate (1/s)."""
    return np.r_[law.params(), float(drag)].astype(float)


# ---------------------------------------------------------- law-independent parts
@numba.njit(inline="always", **_INNER)
def _active(u, v, a, k, wl, wr, i, use_a):
    """Grain i is not inert: it moves, or one of its (present) contacts is strained.

    With ``use_a`` (velocity-dependent forces) also if its acceleration is not zero: a
    grain at rest beside a moving one feels the damping of their contact, and its
    predicted velocity v + c a moves its other neighbour (:func:`make_kernels`).
    """
    n = u.size
    ul = wl if i == 0 else u[i - 1]
    ur = wr if i == n - 1 else u[i + 1]
    return (v[i] != 0.0 or (use_a and a[i] != 0.0) or (k[i] != 0.0 and ul != u[i])
            or (k[i + 1] != 0.0 and ur != u[i]))


@jitcache.compile_locked  # (called by every worker process of a run: compiled once)
@numba.njit(**_JIT)
def active_window(u, v, a, k, wl, wr, lo, hi, use_a):
    """Smallest [lo', hi'] ⊂ [lo, hi] outside which every grain is inert; (-1, -1) if none.

    A grain is inert if v_i = 0 and both its contacts are unstrained (u_{j-1} = u_j,
    walls included; an absent contact, k = 0, never strains), and with ``use_a``
    (velocity-dependent forces) a_i = 0.  Grains outside ``[lo, hi]`` must already be
    inert.
    """
    first = -1
    for i in range(lo, hi + 1):
        if _active(u, v, a, k, wl, wr, i, use_a):
            first = i
            break
    if first < 0:
        return -1, -1
    last = first
    for i in range(hi, first - 1, -1):
        if _active(u, v, a, k, wl, wr, i, use_a):
            last = i
            break
    return first, last


@numba.extending.intrinsic
def _opaque(typingctx, x):
    """``x`` itself, through LLVM's ``freeze`` (the identity on any value that is not poison).

    Hides from LLVM that ``x`` is the value just loaded from an address (see
    :func:`_raised`); costs no instruction.
    """
    from llvmlite import ir

    if not isinstance(x, numba.types.Float):
        return None

    def codegen(context, builder, signature, args):
        (val,) = args
        instr = ir.instructions.Instruction(builder.block, val.type, "freeze", [val])
        builder._insert(instr)  # (llvmlite's IRBuilder has no ``freeze``)
        return instr

    return x(x), codegen


@numba.njit(inline="always", **_INNER)
def _raised(g, x):
    """The running maximum g raised to x: ``x if x > g else g``, bit for bit.

    The same bits as the conditional store ``if x > g: g = x`` for every g and x
    (signed zeros, infinities; a NaN x never raises g: a NaN velocity is not recorded
    as a maximum, and the run stops on it, ``Simulation``'s non-finite check after
    each chunk).  Stored at every grain by the passes, it is one ``maxpd`` (x > g ? x
    : g is that instruction's definition, operands in this order) plus the load and
    the store.  g goes through :func:`_opaque`: otherwise LLVM sees a store of either
    x or the value just loaded from the same address and turns it back into a
    conditional (masked) store of x, which is microcoded on some processors and made
    the recording kernel markedly slower (docs/benchmarks.md, "Design measurements").
    """
    g = _opaque(g)
    return x if x > g else g


@numba.njit(inline="always", **_INNER)
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


@numba.njit(**_INNER)
def _sorted_distinct(a, b):
    """The distinct entries of the int arrays ``a`` and ``b``, sorted (a new array).

    ``np.unique`` by insertion into a sorted array: the special grains of a chunk are a
    few, and numba's sort and search overloads took about a tenth of the first compile
    of the stepping kernel.
    """
    m = a.size + b.size
    out = np.empty(m, np.int64)
    n = 0
    for q in range(m):
        x = a[q] if q < a.size else b[q - a.size]
        i = n
        while i > 0 and out[i - 1] > x:
            i -= 1
        if i > 0 and out[i - 1] == x:
            continue
        for j in range(n, i, -1):
            out[j] = out[j - 1]
        out[i] = x
        n += 1
    return out[:n]


@numba.njit(**_INNER)
def _positions(sorted_, x):
    """Index in the sorted int array ``sorted_`` of each entry of ``x`` (all present)."""
    out = np.empty(x.size, np.int64)
    for q in range(x.size):
        out[q] = _first_at_least(sorted_, x[q])
    return out


@numba.njit(inline="always", **_INNER)
def _test_events(vals, pos, watch, wmax, wthr):
    """The per-step event test on the watched grains' synchronous velocities ``vals[pos[q]]``.

    Updates the running maxima ``wmax``; returns the last q whose velocity has reached
    its maximum above ``wthr[q]`` and started to decrease (-1: none).
    """
    fired = -1
    for q in range(watch.size):
        vg = vals[pos[q]]
        if vg > wmax[q]:
            wmax[q] = vg
        elif wmax[q] >= wthr[q] and vg < wmax[q]:
            fired = q
    return fired


@numba.njit(inline="always", **_INNER)
def _series_row(ts_out, row, ts_idx, vals, pos, moving, u, d0, wl, wr):
    """Write one time-series row: u, v, left and right overlap of each grain.

    v is ``vals[pos[q]]`` when ``moving``, else 0.
    """
    n = u.size
    for q in range(ts_idx.size):
        g = ts_idx[q]
        ts_out[row, q, 0] = u[g]
        ts_out[row, q, 1] = vals[pos[q]] if moving else 0.0
        ts_out[row, q, 2] = d0[g] + ((wl if g == 0 else u[g - 1]) - u[g])
        ts_out[row, q, 3] = d0[g + 1] + (u[g] - (wr if g == n - 1 else u[g + 1]))


# ----------------------------------------------------------------- keyed disk cache
def _entry(py_func, key: str, **options):
    """Compile ``py_func`` (a closure) as a kernel entry point with the keyed disk cache.

    :func:`theory.jitcache.keyed_njit`: numba would key a closure's cache entry by a
    pickle of the law's compiled pieces it closes over, which differs in every process;
    the entry is keyed by the bytecode and ``key`` instead.
    """
    return keyed_njit(py_func, key, **_INNER, **options)


_DIGESTS: dict[type, str] = {}


def _source_digest(law: ContactLaw) -> str:
    """SHA-256 of the sources the compiled kernels of ``law`` are made of.

    This module and the source file of the law's class and of each of its bases that
    is a :class:`~theory.laws.ContactLaw` (:func:`theory.jitcache.source_digest`: the
    law's own file and ``theory/laws/base.py``; a class defined by ``exec`` contributes
    its bytecode).  Part of every kernel's cache key, so that editing a law or the
    kernels recompiles.  Computed once per law class.
    """
    cls = type(law)
    if cls not in _DIGESTS:
        bases = [b for b in cls.__mro__ if isinstance(b, type) and issubclass(b, ContactLaw)]
        _DIGESTS[cls] = source_digest(sys.modules[__name__], *bases)
    return _DIGESTS[cls]


def _interp_digest() -> str:
    """SHA-256 of :mod:`discrete.interpolation` (compiled into the kernels' refined maxima)."""
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "interpolation.py"), "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


PEAK_ROWS = 5
"""Rows of the per-grain peak state of the refined maxima (``run_chunk``'s ``peak``)."""


# ------------------------------------------------------------------------ kernels
class Kernels(NamedTuple):
    """The compiled kernels of one contact law (:func:`make_kernels`)."""

    law: ContactLaw
    drag: bool
    overlap_maxima: bool
    refined_maxima: bool
    """Compiled with the refined maxima between the steps (``refine_range``)."""
    velocity_dependent: bool
    """The law or the drag depends on velocities: dissipative sub-steps, no blocking."""
    run_steps: object
    """``run_chunk`` without temporal blocking (compiles faster; for windows too small
    to block, and for velocity-dependent forces)."""
    run_blocked: object
    """``run_chunk`` with temporal blocking and threads (None for velocity-dependent
    forces); bitwise the same results as :attr:`run_steps`."""
    accelerations: object
    contact_energies: object
    grain_energies: object
    shadow_correction: object
    static_forces: object
    dissipation_rate: object
    grid_row: object
    """A row of the energy grid (blocks of grains), the arithmetic of ``run_chunk``'s rows."""


_BUILT: dict[tuple, Kernels] = {}


def make_kernels(law: ContactLaw | None = None, drag: bool = False,
                 overlap_maxima: bool = False, refined_maxima: bool = False) -> Kernels:
    """The kernels of ``law`` (default Hertz), with on-site drag if ``drag``; built once.

    Parameters
    ----------
    law : ContactLaw, optional
        The contact law (:mod:`theory.laws`); None: :data:`theory.laws.HERTZ`.
    drag : bool
        Include the on-site drag term -m β v (its rate β is a runtime parameter,
        :func:`kernel_params`).
    overlap_maxima : bool
        Keep running maxima of the contact overlaps (``Recording.strain_maxima``): a
        variant of its own, so that the passes without it carry no extra test per grain
        (measured: a run-time switch cost the recording kernel ~40 %).
    refined_maxima : bool
        Search the refined maxima between the steps (``Recording.refined_maxima``,
        section "Refined maxima"): a variant of its own, because the search, inlined
        into every pass, nearly doubled the compile time of every kernel (measured: a
        100-grain impact's first run 23 -> 37 s CPU with it compiled in but unused).

    Returns
    -------
    Kernels
        Entry points compiled on first call (or loaded from the disk cache).
    """
    law = as_law(law)
    key = (law.key(), bool(drag), bool(overlap_maxima), bool(refined_maxima))
    if key not in _BUILT:
        _BUILT[key] = _build(law, bool(drag), bool(overlap_maxima), bool(refined_maxima))
    return _BUILT[key]


def _tag(law: ContactLaw, drag: bool, rmax: bool, refined: bool) -> str:
    """A name suffix per law for every compiled function of its kernels.

    The closures of different laws share their Python names; compiled by different
    processes and loaded from the disk cache into one, they could then share symbol
    names too (numba names a function by name, a per-process counter and argument
    types), and one law's code would run for another's.  The suffix keeps them apart.
    """
    text = f"{law.key()!r}|drag={drag}|rmax={rmax}" + ("|refined" if refined else "")
    return "L" + hashlib.sha256(text.encode()).hexdigest()[:12]


def _build(law: ContactLaw, drag: bool, rmax: bool,  # noqa: C901
           refined: bool = False) -> Kernels:
    """Close the passes over the law's compiled pieces (module docstring)."""
    force = law.make_force()
    elastic = law.make_elastic()
    damping = law.make_damping()
    LAWDIS = bool(law.dissipative)  # contact damping in the dissipative sub-step
    energy = law.make_energy()
    stiffness = law.make_stiffness()
    VD = bool(law.dissipative or drag)  # velocity-dependent: dissipative sub-steps
    DRAG = bool(drag)
    NP = N_PARAMS  # index of the drag rate in p
    RMAX = bool(rmax)  # running maxima of the overlaps
    ckey = f"{law.key()!r}|drag={DRAG}|rmax={RMAX}|{_source_digest(law)}|{_interp_digest()}"
    tag = _tag(law, DRAG, RMAX, refined)

    def jit(**options):
        """numba.njit with the law's tag in the function's name (see :func:`_tag`)."""
        def decorate(func):
            func.__qualname__ = f"{func.__qualname__}_{tag}"
            return numba.njit(**options)(func)
        return decorate

    # ------------------------------------------------------------------ contacts
    @jit(**_INLINE)
    def contact(r, kj, f0j, p):
        """φ = F(r) - f0 of one contact (r the overlap, not yet clipped), N.

        The elastic force only: a conservative law's force does not read the overlap
        rate (ṙ = 0 passed), and with velocity-dependent forces the damping is the
        dissipative sub-step's ("Dissipation" above).
        """
        if VD:
            return elastic(r, kj) - f0j
        return force(r, 0.0, kj, p) - f0j

    # --------------------------------------------------- dissipative sub-step
    @jit(**_INLINE)
    def damp_contacts(u, v, dis, con, p, wl, wr, j0, j1, parity, tau):
        """Exact damping of the contacts j0 <= j <= j1 with j % 2 == parity over τ (s).

        Module docstring, "Dissipation": relative velocity w ← w e^{-c s τ} at fixed
        momentum, impulse P clipped at -τ F_el, energy P w̄ booked in ``dis[j]`` (J).
        """
        inv_m, k, d0 = con[0], con[1], con[2]
        n = u.size
        j = j0 + (j0 + parity) % 2
        while j <= j1:
            ul = wl if j == 0 else u[j - 1]
            ur = wr if j == n else u[j]
            r = d0[j] + (ul - ur)
            c = damping(r, k[j], p)
            if c > 0.0:
                iml = 0.0 if j == 0 else inv_m[j - 1]
                imr = 0.0 if j == n else inv_m[j]
                vl = 0.0 if j == 0 else v[j - 1]
                vr = 0.0 if j == n else v[j]
                s = iml + imr
                w = vl - vr
                pj = max(-w * np.expm1(-c * s * tau) / s, -tau * elastic(r, k[j]))
                vl2 = vl - pj * iml
                vr2 = vr + pj * imr
                if j > 0:
                    v[j - 1] = vl2
                if j < n:
                    v[j] = vr2
                dis[j] += pj * (0.5 * ((vl + vl2) - (vr + vr2)))
            j += 2

    @jit(**_INLINE)
    def damp_grains(v, dis, inv_m, p, g0, g1, tau):
        """Exact drag v ← v e^{-βτ} of grains g0..g1, booking ½ m (v² - v'²) (J) in dis[i+1]."""
        f = np.exp(-p[NP] * tau)
        for i in range(g0, g1 + 1):
            vi = v[i]
            vn = vi * f
            v[i] = vn
            dis[i + 1] += 0.5 * ((vi - vn) * (vi + vn)) / inv_m[i]

    @jit(**_CALLEE)
    def dissipate(st, con, p, wl, wr, lo, hi, tau, adjoint):
        """The dissipative sub-step D_τ (``adjoint``: D*_τ) on the window; new (lo, hi).

        D: drag, even contacts, odd contacts; D*: the reverse order.  Works on the window
        padded by two grains (grains beyond move only through a contact with a moving
        grain) and grows the window to the grains it set moving.
        """
        u, v, dis = st[0], st[1], st[3]
        n = u.size
        g0 = max(lo - 2, 0)
        g1 = min(hi + 2, n - 1)
        j0 = max(lo - 1, 0)
        j1 = min(hi + 2, n)
        if DRAG and not adjoint:
            damp_grains(v, dis, con[0], p, g0, g1, tau)
        if LAWDIS:
            first = 1 if adjoint else 0
            damp_contacts(u, v, dis, con, p, wl, wr, j0, j1, first, tau)
            damp_contacts(u, v, dis, con, p, wl, wr, j0, j1, 1 - first, tau)
        if DRAG and adjoint:
            damp_grains(v, dis, con[0], p, g0, g1, tau)
        for g in range(g0, lo):
            if v[g] != 0.0:
                lo = g
                break
        for g in range(g1, hi, -1):
            if v[g] != 0.0:
                hi = g
                break
        return lo, hi

    # -------------------------------------------------------------------- passes
    # The fused loops advance grains 0..m-1 of the views (uw, vw, ... start at the first
    # grain), drifting grain i+1 at grain i; ``un``/``phi_l`` are the drifted
    # position of grain 0 and the force of its left contact.
    # They return the carried pair for grain m.  Views starting at the loop's first
    # grain let numba prove the indices non-negative (no wrap-around test) and use one
    # base pointer for u[i], u[i+1] (LLVM then sees the distance-1 dependence and
    # vectorises without a run-time alias check).  The kick is v = (v + c1 a) + c2 a
    # with the running max of v taken on v + c1 a (the synchronous velocity) when
    # ``track``; c2 = 0 for the closing step of a chunk and for the intermediate kicks
    # of composition methods (adding 0·a is exact).  Two loop variants per constant
    # layout (track or not: the untracked one vectorises); both inline.  The running
    # maximum is :func:`_raised` stored at every grain, one vector max instruction (the
    # conditional store ``if v > vmax: vmax = v``, the same bits, vectorises to a masked
    # store that is slower on some processors; ``benchmarks/kernel.py --roofline``
    # compares the recording kernel with the bare one).
    @jit(**_INLINE)
    def loop_const(uw, vw, vmw, rmw, aw, m, un, phi_l, dc, c1, c2, im, kr, d0r, f0r, p,
                   track, trk_r):
        """Fused pass over m grains sharing the constants (1/m, k, δ0, f0) of the right contact."""
        if track:
            for i in range(m):
                unr = uw[i + 1] + dc * vw[i + 1]
                uw[i + 1] = unr
                r = d0r + (un - unr)
                if RMAX:  # (as v's; stored unconditionally: -inf never raises it)
                    rmw[i] = _raised(rmw[i], r if trk_r else -np.inf)
                phi_r = contact(r, kr, f0r, p)
                ai = (phi_l - phi_r) * im
                if VD:
                    aw[i] = ai
                vi = vw[i] + c1 * ai
                vmw[i] = _raised(vmw[i], vi)  # the running max (see above)
                vw[i] = vi + c2 * ai
                phi_l = phi_r
                un = unr
        else:
            for i in range(m):
                unr = uw[i + 1] + dc * vw[i + 1]
                uw[i + 1] = unr
                r = d0r + (un - unr)
                phi_r = contact(r, kr, f0r, p)
                ai = (phi_l - phi_r) * im
                if VD:
                    aw[i] = ai
                vw[i] = (vw[i] + c1 * ai) + c2 * ai
                phi_l = phi_r
                un = unr
        return un, phi_l

    @jit(**_INLINE)
    def loop_arrays(uw, vw, vmw, rmw, aw, imw, kw, d0w, f0w, m, un, phi_l, dc, c1, c2, p,
                    track, trk_r):
        """Fused pass over m grains with per-grain constants (kw etc. from the right contact)."""
        if track:
            for i in range(m):
                unr = uw[i + 1] + dc * vw[i + 1]
                uw[i + 1] = unr
                r = d0w[i] + (un - unr)
                if RMAX:  # (as v's; stored unconditionally: -inf never raises it)
                    rmw[i] = _raised(rmw[i], r if trk_r else -np.inf)
                phi_r = contact(r, kw[i], f0w[i], p)
                ai = (phi_l - phi_r) * imw[i]
                if VD:
                    aw[i] = ai
                vi = vw[i] + c1 * ai
                vmw[i] = _raised(vmw[i], vi)  # the running max (see above)
                vw[i] = vi + c2 * ai
                phi_l = phi_r
                un = unr
        else:
            for i in range(m):
                unr = uw[i + 1] + dc * vw[i + 1]
                uw[i + 1] = unr
                r = d0w[i] + (un - unr)
                phi_r = contact(r, kw[i], f0w[i], p)
                ai = (phi_l - phi_r) * imw[i]
                if VD:
                    aw[i] = ai
                vw[i] = (vw[i] + c1 * ai) + c2 * ai
                phi_l = phi_r
                un = unr
        return un, phi_l

    @jit(**_CALLEE)
    def piece(st, con, p, mx, i0, i1, ul, ur, dc, c1, c2, track):
        """One substep of grains [i0, i1) given the drifted outer neighbours ``ul``, ``ur``.

        Returns the synchronous velocity (v + c1 a) of grain i1-1.
        """
        u, v, a, dis = st
        inv_m, k, d0, f0, rs, rc = con
        vmax, rmax, trk_r = mx
        trk_r = track and trk_r
        un = u[i0] + dc * v[i0]
        u[i0] = un
        r = d0[i0] + (ul - un)
        if RMAX and trk_r and r > rmax[i0]:
            rmax[i0] = r
        phi_l = contact(r, k[i0], f0[i0], p)
        j = i0
        last = i1 - 1
        if last > j:
            if rs.size > 1:
                q = _first_at_least(rs, j + 1) - 1  # the run containing grain j
                while j < last:
                    e = min(rs[q + 1], last)
                    un, phi_l = loop_const(u[j:e + 1], v[j:e + 1], vmax[j:e + 1],
                                           rmax[j + 1:e + 1], a[j:e + 1], e - j, un, phi_l,
                                           dc, c1, c2, rc[q, 0], rc[q, 1], rc[q, 2],
                                           rc[q, 3], p, track, trk_r)
                    j = e
                    q += 1
            else:
                un, phi_l = loop_arrays(u[j:i1], v[j:i1], vmax[j:i1], rmax[j + 1:i1],
                                        a[j:i1], inv_m[j:i1], k[j + 1:i1], d0[j + 1:i1],
                                        f0[j + 1:i1], last - j, un, phi_l, dc, c1, c2, p,
                                        track, trk_r)
        # last grain: right neighbour given
        r = d0[i1] + (un - ur)
        if RMAX and trk_r and r > rmax[i1]:
            rmax[i1] = r
        phi_r = contact(r, k[i1], f0[i1], p)
        ai = (phi_l - phi_r) * inv_m[last]
        if VD:
            a[last] = ai
        vi = v[last] + c1 * ai
        if track and vi > vmax[last]:
            vmax[last] = vi
        v[last] = vi + c2 * ai
        return vi

    @jit(**_INLINE)
    def accel_at(st, con, p, g, ul, ur):
        """Acceleration of grain g in the pass that just ran, m/s².

        Recomputed with the pass's arithmetic from its drifted neighbours ``ul``, ``ur``;
        for velocity-dependent laws the one the pass stored.
        """
        u, v, a, dis = st
        inv_m, k, d0, f0, rs, rc = con
        if VD:
            return a[g]
        phi_l = contact(d0[g] + (ul - u[g]), k[g], f0[g], p)
        phi_r = contact(d0[g + 1] + (u[g] - ur), k[g + 1], f0[g + 1], p)
        return (phi_l - phi_r) * inv_m[g]

    # ------------------------------------------------------------ refined maxima
    # The running maximum ``vmax`` stays the largest *sampled* synchronous velocity (the
    # gate, the figures' quantity; its test in the fused loops is unchanged: a call in
    # that branch stops LLVM vectorising the loop, measured 6x slower).  After a step's
    # final substep, ``refine_range`` compares the gate with its copy (row 0 of the peak
    # state): a grain whose gate rose at this step, or that is *pending* (its gate rose at
    # the step before; copy NaN), gets its acceleration a1 recomputed (``accel_at``) and
    # its synchronous v1 (= the new gate, or v - c2 a1), and the maximum of the cubic
    # Hermite interpolant of (v, a) on the step (:mod:`discrete.interpolation`) raises
    # its refined maximum ``vref`` — O(h^p) for an integrator of order p, where the
    # largest sample is O(h^2) off.  A grain stays pending one step after its gate last
    # rose, so the steps on both sides of its largest sample are searched.  If the gate
    # is first exceeded with a1 < 0 (a new peak already behind within that step; v at
    # the step before is not kept) the next step's interpolant is searched one step
    # back as well (``hermite_max_from(..., -1)``, still O(h^4)).  Cheap paths: where
    # the gate rose, a1 = (v - v1)/c2 from the velocity the pass left (no force); where
    # v rises at both ends of the step (a0, a1 >= 0) its maximum there is the end, v1.
    # Grains are independent: bitwise the same with blocks and threads.
    if refined:
        @jit(**_INLINE)
        def refine_one(pk, vref, tref, t0, i, g, v1, a1, h, gstep):
            """The refined maximum of a flagged grain i after a step (section above).

            ``g`` its gate, ``v1``, ``a1`` its synchronous velocity and acceleration at the
            step's end, ``gstep`` the step's global number, ``t0`` the time of step 0 (s):
            ``tref`` is t0 + (fractional step) h.
            """
            pending = pk[0, i] != pk[0, i]
            changed = (not pending) or g != pk[1, i]
            if not pending or pk[4, i] != gstep - 1.0 or (
                    changed and pk[3, i] == 0.0 and pk[2, i] >= 0.0 and a1 >= 0.0):
                # first exceeded; or (not reached: a pending grain stays in the window) a
                # stale state; or rising at both ends: the step's maximum is its end
                if v1 > vref[i]:
                    vref[i] = v1
                    tref[i] = t0 + gstep * h
            else:
                s_, y = hermite_max_from(h, pk[1, i], v1, pk[2, i], a1, pk[3, i])
                if y > vref[i]:
                    vref[i] = y
                    tref[i] = t0 + (gstep - 1.0 + s_) * h
            if changed:
                pk[0, i] = np.nan
                pk[1, i] = v1
                pk[2, i] = a1
                # first exceeded after the peak (a1 < 0): search the next step's cubic one
                # step back as well
                pk[3, i] = -1.0 if not pending and a1 < 0.0 else 0.0
                pk[4, i] = gstep
            else:
                pk[0, i] = g  # the peak is behind: no longer pending

        @jit(**_INLINE)
        def refine_range(st, con, p, vmax, peak, lo_t, hi_t, ul, ur, c2, h, gstep):
            """``refine_one`` on every grain of [lo_t, hi_t) whose gate changed or is pending.

            The test ``vmax != pk[0]`` (NaN while pending) is a vectorised count over blocks
            of 64 grains (a constant trip count: LLVM vectorises it; a variable one of 16
            measured 10x slower); only blocks with a flagged grain are walked.  Where the
            gate rose, a1 = (v - g)/c2 from the velocity the pass left; only a pending grain
            whose gate did not rise (once per peak) or the closing step of a chunk (c2 = 0)
            recomputes a1 from its contacts (``accel_at``), in a walk of its own (inside the
            first it doubled a 2,000-grain impact's CPU time).  At c2 = 0 the velocity a
            mid-chunk pass would have left, v + k0 a1 (k0 = ``peak[5]``, the opening kick),
            is rebuilt first, so that every grain's arithmetic is the same bits wherever a
            chunk ends.
            """
            u, v = st[0], st[1]
            pk, vref, tref, t0, k0 = peak[1], peak[2], peak[3], peak[4], peak[5]
            gate = pk[0]
            b0 = lo_t
            while b0 < hi_t:
                m = min(64, hi_t - b0)
                flagged = 1
                if m == 64:
                    x = vmax[b0:b0 + 64]
                    y = gate[b0:b0 + 64]
                    flagged = 0
                    for j in range(64):
                        flagged += x[j] != y[j]
                if flagged:
                    # where the gate rose (first time, or again while pending): a1 from v;
                    # the others (a pending grain whose gate did not rise, once per peak;
                    # every grain at c2 = 0) in a walk of their own, ``accel_at``
                    slow = 0
                    for i in range(b0, b0 + m):
                        g = vmax[i]
                        if g != gate[i]:
                            if c2 != 0.0 and (gate[i] == gate[i] or g != pk[1, i]):
                                refine_one(pk, vref, tref, t0, i, g, g, (v[i] - g) / c2, h,
                                           gstep)
                            else:
                                slow += 1
                    if slow:
                        for i in range(b0, b0 + m):
                            g = vmax[i]
                            if g != gate[i] and pk[4, i] != gstep:  # (not done above)
                                left = ul if i == lo_t else u[i - 1]
                                right = ur if i == hi_t - 1 else u[i + 1]
                                acc = accel_at(st, con, p, i, left, right)
                                # v as a mid-chunk pass leaves it (c2 = k0): the same bits
                                # wherever the chunks end (resume, threads' chunk lengths)
                                vaft = v[i] if c2 != 0.0 else v[i] + k0 * acc
                                if gate[i] == gate[i] or g != pk[1, i]:  # (c2 = 0)
                                    refine_one(pk, vref, tref, t0, i, g, g, (vaft - g) / k0,
                                               h, gstep)
                                else:
                                    refine_one(pk, vref, tref, t0, i, g, vaft - k0 * acc, acc,
                                               h, gstep)
                b0 += m
    else:
        @jit(**_INLINE)
        def refine_range(st, con, p, vmax, peak, lo_t, hi_t, ul, ur, c2, h, gstep):
            """No refined maxima in this variant (``make_kernels(refined_maxima=False)``)."""
            return

    @jit(**_INLINE)
    def advance(st, con, p, mx, umax, lo_t, hi_t, ul, ur, dc, c1, c2, trk, umx, sp, vsp, peak,
                h, gstep):
        """One substep of grains [lo_t, hi_t) (``piece``) with the recording.

        The synchronous velocities v + c1 a of the special grains ``sp`` (sorted) in the
        range go to ``vsp`` (``ul``, ``ur`` at the range ends), with ``umx`` the
        running maximum of u is updated on the range, and with ``trk`` and ``peak[0]``
        the refined maxima (``refine_range``; ``h`` the step, ``gstep`` its global
        number).
        """
        u = st[0]
        v = st[1]
        q0 = _first_at_least(sp, lo_t)
        q1 = _first_at_least(sp, hi_t)
        for q in range(q0, q1):
            vsp[q] = v[sp[q]]
        piece(st, con, p, mx, lo_t, hi_t, ul, ur, dc, c1, c2, trk)
        for q in range(q0, q1):
            g = sp[q]
            left = ul if g == lo_t else u[g - 1]
            right = ur if g == hi_t - 1 else u[g + 1]
            vsp[q] = vsp[q] + c1 * accel_at(st, con, p, g, left, right)
        if umx:
            uw = u[lo_t:hi_t]
            umw = umax[lo_t:hi_t]
            for i in range(hi_t - lo_t):
                umw[i] = _raised(umw[i], uw[i])  # (see the passes)
        if trk and peak[0]:
            refine_range(st, con, p, mx[0], peak, lo_t, hi_t, ul, ur, c2, h, gstep)

    # ---------------------------------------------------------- temporal blocking
    # A block advances the (padded) window by ``nsub`` substeps with trapezoid tiles:
    # phase A advances every tile [b_j, b_j+1) on the shrinking ranges [b_j + τ,
    # b_j+1 - τ) for τ = 0 .. nsub-1 (the outer neighbours of a range at τ >= 1 are the
    # tile's own grains, at level τ: drifted on the fly; at τ = 0 they belong to other
    # tiles, so their drifted positions are computed before the phase); phase B then
    # advances the growing ranges [b_j - τ, b_j + τ) around every tile boundary (and
    # the window ends), whose outer neighbours phase A has left exactly at level τ + 1
    # (stored u).  Tiles of one phase touch disjoint grains, so they run concurrently;
    # each grain's arithmetic is that of the per-step pass.  Two parallel regions per
    # block instead of one per substep, and a tile (u, v, max v: 24 bytes per grain)
    # stays in L2 during its nsub substeps.  Position-dependent laws only.

    @jit(**_CALLEE)
    def trapezoid(st, con, p, mx, umax, bounds, j, phase, ulb, urb, wl, wr, sub, sp, none,
                  vsp2, nsub, peak, h):
        """Phase A on tile j (shrinking ranges) or phase B around boundary j (growing)."""
        u, v = st[0], st[1]
        dcs, c1s, c2s, trks, umxs, fins, gss = sub
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
            advance(st, con, p, mx, umax, lo_t, hi_t, ul, ur, dc, c1s[tau], c2s[tau],
                    trks[tau], umxs[tau], sp if fins[tau] else none, vsp2[tau], peak, h,
                    gss[tau])

    @jit(parallel=True, **_INNER)
    def phase_tiles(st, con, p, mx, umax, bounds, phase, ulb, urb, wl, wr, sub, sp, none,
                    vsp2, nsub, peak, h):
        """Phase ``phase`` (0: A, 1: B) of a block on the tiles ``bounds``, concurrently.

        (One prange loop called twice per block: numba compiles the loop body, and all it
        calls, once per prange loop.)
        """
        count = bounds.size - 1 + phase
        for j in numba.prange(count):
            trapezoid(st, con, p, mx, umax, bounds, j, phase, ulb, urb, wl, wr, sub, sp,
                      none, vsp2, nsub, peak, h)

    @jit(**_CALLEE)
    def block(st, con, p, wl, wr, drift, kick, nsteps, s, nb, close, lo, hi, mx, umax, track,
              events, series, rows, cfg, work, peak, h):
        """Try one temporal block of ``nb`` steps from step ``s`` (section above).

        Returns ``(status, rows, fired, lo, hi)``: status 0 = not blocked (too small, a
        sampled series grain in reach: take a step), 1 = done (``nb`` steps taken),
        2 = rolled back (it overshot an event: redo these steps one by one).
        """
        u, v = st[0], st[1]
        inv_m, k, d0, f0, rs, rc = con
        watch, wmax, wthr, sp_w, pos_w = events
        ts_idx, ts_every, step0, ts_out = series
        nt_max, min_parallel, tile, min_serial_block = cfg
        sub, vsp2, saved_state, swm, bnd, ulb_b, urb_b = work
        su, sv, svm, sum_, srm, spk, svr, str_ = saved_state
        vmax, rmax = mx[0], mx[1]
        dcs, c1s, c2s, trks, umxs, fins, gss = sub
        n = u.size
        ns = drift.size
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
        if not ok:
            return 0, rows, -1, lo, hi
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
            st_ = tau % ns
            sidx = s + 1 + tau // ns
            final = st_ == ns - 1
            dcs[tau] = drift[st_]
            c1s[tau] = kick[st_ + 1]
            c2s[tau] = kick[0] if final and sidx != nsteps and not (
                close and sidx == s + nb) else 0.0  # ``close``: synchronous v at the end
            trks[tau] = final and track
            umxs[tau] = final and track and (step0 + sidx) % UMAX_EVERY == 0
            fins[tau] = final
            gss[tau] = float(step0 + sidx)
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
            if mx[2]:
                srm[lo_p:hi_p + 2] = rmax[lo_p:hi_p + 2]
            if peak[0]:
                spk[:, lo_p:hi_p + 1] = peak[1][:, lo_p:hi_p + 1]
                svr[lo_p:hi_p + 1] = peak[2][lo_p:hi_p + 1]
                str_[lo_p:hi_p + 1] = peak[3][lo_p:hi_p + 1]
        swm[:] = wmax
        subv = (dcs[:nsub], c1s[:nsub], c2s[:nsub], trks[:nsub], umxs[:nsub], fins[:nsub],
                gss[:nsub])
        none = np.zeros(0, np.int64)
        for phase in range(2):
            phase_tiles(st, con, p, mx, umax, bnd[:ntile + 1], phase, ulb_b[:ntile],
                        urb_b[:ntile], wl, wr, subv, sp_w, none, vsp2[:nsub], nsub, peak, h)
        # events, step by step (the per-step test: the last firing grain wins)
        hit = -1
        hit_q = -1
        for tau in range(ns - 1, nsub, ns):
            q = _test_events(vsp2[tau], pos_w, watch, wmax, wthr)
            if q >= 0:
                hit = s + 1 + tau // ns
                hit_q = q
                break
        if hit >= 0 and not (hit + 1 == nsteps and s + nb == nsteps):
            # the block overshot the event's closing step: roll back and redo the block
            # step by step (bitwise the same arithmetic), which stops there
            u[lo_p:hi_p + 1] = su[lo_p:hi_p + 1]
            v[lo_p:hi_p + 1] = sv[lo_p:hi_p + 1]
            vmax[lo_p:hi_p + 1] = svm[lo_p:hi_p + 1]
            umax[lo_p:hi_p + 1] = sum_[lo_p:hi_p + 1]
            if mx[2]:
                rmax[lo_p:hi_p + 2] = srm[lo_p:hi_p + 2]
            if peak[0]:
                peak[1][:, lo_p:hi_p + 1] = spk[:, lo_p:hi_p + 1]
                peak[2][lo_p:hi_p + 1] = svr[lo_p:hi_p + 1]
                peak[3][lo_p:hi_p + 1] = str_[lo_p:hi_p + 1]
            wmax[:] = swm
            return 2, rows, -1, lo, hi
        # series grains out of reach: constant u and overlaps, v = 0
        for _ in range(nrow):
            _series_row(ts_out, rows, ts_idx, swm, pos_w, False, u, d0, wl, wr)
            rows += 1
        lo, hi = active_window(u, v, st[2], k, wl, wr, lo_p, hi_p, False)
        if lo < 0:
            lo, hi = lo_p, lo_p
        return 1, rows, hit_q, lo, hi

    # ------------------------------------------------------------ energy rows
    @jit(**_CALLEE)
    def energy_row(u, v, mass, k, d0, wl, wr, lo, hi, c, ek_out, ep_out):
        """One row of the per-grain energy grid, summed over blocks of ``c`` grains, J.

        Kinetic ½ m v² and potential (half of each contact's U(r) - U(δ0); a wall
        contact wholly its grain's) of grains lo..hi, added into the zeroed rows
        ``ek_out``, ``ep_out`` (block i // c); grains outside the window are inert and
        hold no wave energy.  Needs the synchronous v (a chunk-end state).
        """
        n = u.size
        ul = wl if lo == 0 else u[lo - 1]
        e_l = energy(d0[lo] + (ul - u[lo]), k[lo], d0[lo])
        if c == 1:
            for i in range(lo, hi + 1):
                ur = wr if i == n - 1 else u[i + 1]
                e_r = energy(d0[i + 1] + (u[i] - ur), k[i + 1], d0[i + 1])
                ek_out[i] += 0.5 * mass[i] * v[i] * v[i]
                ep_out[i] += ((e_l if i == 0 else 0.5 * e_l)
                              + (e_r if i == n - 1 else 0.5 * e_r))
                e_l = e_r
            return
        i = lo
        while i <= hi:  # block by block: the sums in registers, no division per grain
            b = i // c
            end = min(hi, (b + 1) * c - 1)
            sk, sp = ek_out[b], ep_out[b]  # (the same additions in the same order)
            for j in range(i, end + 1):
                ur = wr if j == n - 1 else u[j + 1]
                e_r = energy(d0[j + 1] + (u[j] - ur), k[j + 1], d0[j + 1])
                sk += 0.5 * mass[j] * v[j] * v[j]
                sp += (e_l if j == 0 else 0.5 * e_l) + (e_r if j == n - 1 else 0.5 * e_r)
                e_l = e_r
            ek_out[b], ep_out[b] = sk, sp
            i = end + 1

    # ------------------------------------------------------------------ one step
    @jit(**_INLINE)
    def step(st, con, p, wl, wr, drift, kick, dt, last, lo, hi, mx, umax, track, do_umax,
             sp, vsp, vwork, peak, gstep):
        """All substeps of one step on the window, grown as needed; returns (lo, hi).

        ``vsp`` receives the synchronous velocities of the special grains ``sp``.  With
        velocity-dependent forces the step is D*_{h/2} V_h (after the D_{h/2} that
        opened it, module docstring "Dissipation"): the velocity pass then records its
        maxima into the scratch ``vwork`` and the synchronous velocities are recorded
        after D*; unless ``last``, the next step's D_{h/2} and opening kick follow.
        """
        u, v, a = st[0], st[1], st[2]
        k = con[1]
        n = u.size
        ns = drift.size
        none = sp[:0]
        for st_ in range(ns):
            # grow the window by one grain on a side whose edge grain is not inert:
            # only its neighbour can start moving during this substep
            if lo > 0 and _active(u, v, a, k, wl, wr, lo, VD):
                lo -= 1
            if hi < n - 1 and _active(u, v, a, k, wl, wr, hi, VD):
                hi += 1
            dc = drift[st_]
            c1 = kick[st_ + 1]
            final = st_ == ns - 1
            # closing kick + the next step's opening kick; only the closing kick at the
            # end of the chunk (a is then recomputed) and between the stages
            c2 = kick[0] if final and not last and not VD else 0.0
            if final:
                for q in range(vsp.size):
                    vsp[q] = 0.0  # special grains outside the window are inert: v = 0
            ul = wl if lo == 0 else u[lo - 1] + dc * v[lo - 1]
            ur = wr if hi == n - 1 else u[hi + 1] + dc * v[hi + 1]
            advance(st, con, p, (vwork, mx[1], mx[2]) if VD else mx, umax, lo, hi + 1, ul,
                    ur, dc, c1, c2, final and track,
                    final and track and do_umax, sp if final else none, vsp,
                    peak, dt, gstep)
        if VD:  # close with D*_{h/2}; record the synchronous velocities
            lo, hi = dissipate(st, con, p, wl, wr, lo, hi, 0.5 * dt, True)
            v = st[1]
            if track:
                vmax = mx[0]
                for i in range(lo, hi + 1):
                    if v[i] > vmax[i]:
                        vmax[i] = v[i]
            for q in range(sp.size):
                vsp[q] = v[sp[q]]  # 0 outside the window (inert)
            if not last:
                lo, hi = open_step(st, con, p, wl, wr, kick[0], dt, lo, hi)
        return lo, hi

    @jit(**_INLINE)
    def open_step(st, con, p, wl, wr, b1h, dt, lo, hi):
        """A step's opening on the window: (D_{h/2}, then) the kick v += b_1 h a.

        D_{h/2} with velocity-dependent forces only.  Returns (lo, hi).
        """
        v, a = st[1], st[2]
        if VD:
            lo, hi = dissipate(st, con, p, wl, wr, lo, hi, 0.5 * dt, False)
        for i in range(lo, hi + 1):
            v[i] = v[i] + b1h * a[i]
        return lo, hi

    # -------------------------------------------------------- chunk (entry points)
    def make_run_chunk(BLOCKS):
        """``run_chunk`` with temporal blocking (``block``) or without.

        Without, the blocking code and its work arrays are not compiled in: ``BLOCKS``
        is a constant of the closure, and numba drops the branches on it before typing.
        """

        def run_chunk(st, con, p, wl, wr, dt, drift, kick, nsteps, lo, hi, vmax, umax, rmax,
                      track, track_r, watch, wmax, wthr, ts_idx, ts_every, step0, ts_out, cfg,
                      erow, peak):
            """Advance ``nsteps`` steps on the window ``lo..hi`` in place.

            Parameters
            ----------
            st, con, p : tuples, array
                State ``(u, v, a, dis)``, chain constants ``(inv_m, k, d0, f0, rs, rc)`` and
                runtime parameters (module docstring).  a must be consistent with u (and v).
            wl, wr : float
                Wall displacements, m.
            dt : float
                Time step h, s.
            drift, kick : (S,), (S+1,) float arrays
                Drift coefficients a_s h and kick coefficients b_s h of the method, s
                (velocity Verlet: (h,), (h/2, h/2); :mod:`discrete.integrators`).
            nsteps, lo, hi : int
                Steps to take and the window: every grain outside ``lo..hi`` must be inert
                (:func:`active_window`).
            vmax, umax, rmax : (N,), (N,), (N+1,) float arrays
                Running maxima of v (every step), u (every ``UMAX_EVERY`` global steps and
                when an event fires) and the contact overlaps (every step, with
                ``track_r``), updated in place when ``track``.
            track, track_r : bool
                Update the running maxima; also those of the overlaps.
            watch, wmax, wthr : (W,) arrays
                Grains whose velocity peak stops the chunk, their running maxima (in/out) and
                thresholds (m/s): the chunk returns one step after the first step at which
                ``wmax[q] >= wthr[q]`` and ``v[watch[q]] < wmax[q]`` (that step closes the
                step sequence: v = v^n, a = a^n).
            ts_idx, ts_every, step0, ts_out : arrays and ints
                Time series: grains, steps between rows (a row after every step whose global
                number is a multiple of ``ts_every``), global number of the step before the
                chunk, and the rows (R, S, 4) of (u, v, left overlap, right overlap).
            cfg : tuple of int
                ``(nthreads, min_parallel, block_steps, tile, min_serial_block)``: threads
                when ``nthreads > 1`` and the window has at least ``min_parallel`` grains;
                blocks of up to ``block_steps`` steps on tiles of about ``tile`` grains (with
                threads, or on one thread for windows of at least ``min_serial_block``
                grains; ``block_steps = 0``: never).  Bitwise identical results either way.
            erow : tuple
                ``(e_every, coarsen, e_kin, e_pot, mass)``: after every step whose global
                number is a multiple of ``e_every`` (> 0; 0: none) a row of the per-grain
                energy grid (``energy_row``, blocks of ``coarsen`` grains) goes to
                ``e_kin[row]`` (kinetic) and ``e_pot[row]`` (potential), J (two (rows, Nc)
                arrays, ``discrete.recording.EnergyGrid``'s blocks); ``mass`` in kg.  Such a step
                closes like the last step of a chunk (synchronous v, a recomputed) and the
                next one opens with its kick: bitwise the arithmetic of ending the chunk
                there, so the grid costs no kernel call per row.
            peak : tuple
                ``(refine, state, vref, tref, t0, k0)``: with ``refine`` and ``track`` the
                refined maxima of v (section "Refined maxima"): ``vref`` (N,) m/s, ``tref``
                (N,) the time each was reached, ``t0 + (fractional global step) dt`` (s),
                ``k0`` the opening kick coefficient ``kick[0]`` (s), ``state``
                (``PEAK_ROWS``, N) the peak state carried between steps and chunks (row 0
                the gate copy, NaN while pending; 1, 2 v and a at the last step; 3 the
                start of the searched interval, -1 or 0; 4 that step's global number).

            Returns
            -------
            steps, rows, fired, lo, hi, erows : int
                Steps taken (< nsteps if an event fired), time-series rows written, the index
                q of the watched grain whose event fired (-1: none), the final window, and
                the energy rows written.
            """
            u, v, a = st[0], st[1], st[2]
            nthreads, min_parallel, block_steps, tile, min_serial_block = cfg
            n = u.size
            ns = drift.size
            rows = 0
            fired = -1
            # special grains: watched (every step) and series (on sampling steps), sorted unique
            sp_w = _sorted_distinct(watch, watch)
            sp_ws = _sorted_distinct(watch, ts_idx)
            pos_w = _positions(sp_w, watch)
            pos_ws_w = _positions(sp_ws, watch)
            pos_ws_s = _positions(sp_ws, ts_idx)
            vsp = np.empty(sp_ws.size)
            vwork = np.empty(n if VD else 0)  # the velocity pass's maxima, discarded (step)
            if BLOCKS:
                # temporal blocking work arrays (a state copy to roll back to if events
                # can fire)
                nt_max = max(1, nthreads)
                nsub_max = max(block_steps, 1) * ns
                keep = n if watch.size > 0 else 0
                keep_r = keep + 1 if keep and track_r else 0
                keep_p = keep if keep and peak[0] else 0
                ntile_max = (n // max(tile, 1)) + nt_max + 2
                work = ((np.empty(nsub_max), np.empty(nsub_max), np.empty(nsub_max),
                         np.zeros(nsub_max, np.bool_), np.zeros(nsub_max, np.bool_),
                         np.zeros(nsub_max, np.bool_), np.zeros(nsub_max)),
                        np.zeros((nsub_max, sp_w.size)),
                        (np.empty(keep), np.empty(keep), np.empty(keep), np.empty(keep),
                         np.empty(keep_r), np.empty((PEAK_ROWS, keep_p)), np.empty(keep_p),
                         np.empty(keep_p)),
                        np.empty(watch.size), np.empty(ntile_max + 1, np.int64),
                        np.empty(ntile_max), np.empty(ntile_max))
                events = (watch, wmax, wthr, sp_w, pos_w)
                bcfg = (nt_max, min_parallel, tile, min_serial_block)
            mx = (vmax, rmax, track_r)
            no_block_before = 0
            e_every, e_coarsen, e_kin, e_pot, mass = erow
            erows = np.int64(0)  # (not a literal 0: one take_row signature for both calls)
            # opening kick of the first step: v^{n+1/2} (or the first stage velocity)
            lo, hi = open_step(st, con, p, wl, wr, kick[0], dt, lo, hi)
            s = 0
            while s < nsteps:
                nb = min(block_steps, nsteps - s)
                if e_every > 0:  # a block never spans an energy row
                    nb = min(nb, e_every - (step0 + s) % e_every)
                if BLOCKS and nb >= 4 and fired < 0 and s >= no_block_before:
                    close = e_every > 0 and (step0 + s + nb) % e_every == 0
                    status, rows, hit, lo_b, hi_b = block(
                        st, con, p, wl, wr, drift, kick, nsteps, s, nb, close, lo, hi, mx, umax,
                        track, events, (ts_idx, ts_every, step0, ts_out), rows, bcfg, work,
                        peak, dt)
                    if status == 1:
                        s += nb
                        fired = hit
                        lo, hi = lo_b, hi_b
                        if e_every > 0 and (step0 + s) % e_every == 0 and s < nsteps:
                            erows, lo, hi = take_row(st, con, p, wl, wr, kick, dt, lo, hi,
                                                     e_coarsen, e_kin, e_pot, erows, mass)
                        continue
                    if status == 2:
                        no_block_before = s + nb
                        continue
                s += 1
                last = s == nsteps
                erow_now = e_every > 0 and (step0 + s) % e_every == 0 and not last
                sample = ts_idx.size > 0 and (step0 + s) % ts_every == 0
                lo, hi = step(st, con, p, wl, wr, drift, kick, dt, last or erow_now, lo, hi,
                              mx, umax, track, (step0 + s) % UMAX_EVERY == 0,
                              sp_ws if sample else sp_w, vsp, vwork, peak,
                              float(step0 + s))
                if erow_now:
                    erows, lo, hi = take_row(st, con, p, wl, wr, kick, dt, lo, hi, e_coarsen,
                                             e_kin, e_pot, erows, mass)
                # time series and events use the synchronous velocities of the special grains
                if sample:
                    _series_row(ts_out, rows, ts_idx, vsp, pos_ws_s, True, u, con[2], wl, wr)
                    rows += 1
                if fired < 0:
                    fired = _test_events(vsp, pos_ws_w if sample else pos_w, watch, wmax, wthr)
                    if fired >= 0 and not last:
                        nsteps = s + 1  # one closing step, then return
            if not VD:  # a^n of the final state (bitwise the values the closing pass used)
                accelerations(u, v, a, con, p, wl, wr, lo, hi)
            return nsteps, rows, fired, lo, hi, erows

        return run_chunk

    @jit(**_CALLEE)
    def take_row(st, con, p, wl, wr, kick, dt, lo, hi, c, e_kin, e_pot, erows, mass):
        """An energy row inside a chunk (``run_chunk``'s ``erow``); returns (rows, lo, hi).

        The step just taken closed like a chunk's last (synchronous v): a is recomputed
        as at a chunk end, the row taken, and the next step's opening applied.
        """
        u, v, a = st[0], st[1], st[2]
        if not VD:
            accelerations(u, v, a, con, p, wl, wr, lo, hi)
        for b in range(e_kin.shape[1]):
            e_kin[erows, b] = 0.0
            e_pot[erows, b] = 0.0
        energy_row(u, v, mass, con[1], con[2], wl, wr, lo, hi, c, e_kin[erows],
                   e_pot[erows])
        lo, hi = open_step(st, con, p, wl, wr, kick[0], dt, lo, hi)
        return erows + 1, lo, hi

    # ----------------------------------------------------- other entry points
    def accelerations(u, v, a, con, p, wl, wr, lo, hi):
        """Set a[lo:hi+1] = (φ_i - φ_{i+1})/m_i (Eq. 2), m/s²; others untouched.

        With velocity-dependent forces the elastic part only: the damping and the drag
        are the dissipative sub-step's (module docstring, "Dissipation"); ``v`` is not
        read (kept in the entry point's signature).
        """
        inv_m, k, d0, f0, rs, rc = con
        n = u.size
        ul = wl if lo == 0 else u[lo - 1]
        phi_l = contact(d0[lo] + (ul - u[lo]), k[lo], f0[lo], p)
        for i in range(lo, hi + 1):
            ur = wr if i == n - 1 else u[i + 1]
            phi_r = contact(d0[i + 1] + (u[i] - ur), k[i + 1], f0[i + 1], p)
            a[i] = (phi_l - phi_r) * inv_m[i]
            phi_l = phi_r

    def contact_energies(u, k, d0, wl, wr, lo, hi, out):
        """out[j] = U(r_j) - U(δ0_j), the wave potential energy of contacts lo..hi, J."""
        n = u.size
        for j in range(lo, hi + 1):
            ul = wl if j == 0 else u[j - 1]
            ur = wr if j == n else u[j]
            out[j] = energy(d0[j] + (ul - ur), k[j], d0[j])

    def grain_energies(u, v, mass, k, d0, wl, wr, lo, hi, ek, ep):
        """Per-grain kinetic ½mv² and potential (half of each contact's energy), J.

        A wall contact belongs wholly to its grain (the wall stores no energy).  Fills
        ek[lo:hi+1], ep[lo:hi+1]; returns (Σ ek, Σ contact energies of lo..hi+1).
        """
        n = u.size
        ul = wl if lo == 0 else u[lo - 1]
        e_l = energy(d0[lo] + (ul - u[lo]), k[lo], d0[lo])
        tk = 0.0
        tp = e_l
        for i in range(lo, hi + 1):
            ur = wr if i == n - 1 else u[i + 1]
            e_r = energy(d0[i + 1] + (u[i] - ur), k[i + 1], d0[i + 1])
            kin = 0.5 * mass[i] * v[i] * v[i]
            ek[i] = kin
            ep[i] = (e_l if i == 0 else 0.5 * e_l) + (e_r if i == n - 1 else 0.5 * e_r)
            tk += kin
            tp += e_r
            e_l = e_r
        return tk, tp

    def shadow_correction(u, v, a, mass, k, d0, wl, wr, lo, hi):
        r"""O(h²) term of velocity Verlet's modified energy divided by h², J/s².

        :math:`\tilde H = H + h^2[\tfrac{1}{12} v^T V'' v - \tfrac{1}{24}\sum m_i a_i^2]`
        (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, 2006, §IX.3 with
        the Strang-splitting BCH formula), with :math:`V''` the contact stiffness
        ∂F/∂δ (:meth:`ContactLaw.make_stiffness`) on the contact differences.  Over
        contacts and grains lo..hi (+ contact hi+1).
        """
        n = u.size
        s = 0.0
        for j in range(lo, hi + 2):
            ul = wl if j == 0 else u[j - 1]
            ur = wr if j == n else u[j]
            vl = 0.0 if j == 0 else v[j - 1]
            vr = 0.0 if j == n else v[j]
            dv = vl - vr
            s += (1.0 / 12.0) * stiffness(d0[j] + (ul - ur), k[j]) * dv * dv
        for i in range(lo, hi + 1):
            s -= (1.0 / 24.0) * mass[i] * a[i] * a[i]
        return s

    def static_forces(k, d0, p):
        """F(δ0_j, 0; k_j) of every contact with the kernels' arithmetic, N."""
        out = np.empty(k.size)
        for j in range(k.size):
            out[j] = force(d0[j], 0.0, k[j], p)
        return out

    def dissipation_rate(u, v, mass, k, d0, p, wl, wr):
        """Power P = Σ_j (F_j - F_el,j) ṙ_j + Σ_i m_i β v_i² (W) at the synchronous state."""
        n = u.size
        s = 0.0
        for j in range(n + 1):
            ul = wl if j == 0 else u[j - 1]
            ur = wr if j == n else u[j]
            vl = 0.0 if j == 0 else v[j - 1]
            vr = 0.0 if j == n else v[j]
            r = d0[j] + (ul - ur)
            rd = vl - vr
            s += (force(r, rd, k[j], p) - elastic(r, k[j])) * rd
        if DRAG:
            for i in range(n):
                s += mass[i] * p[NP] * v[i] * v[i]
        return s

    def grid_row(u, v, mass, k, d0, wl, wr, lo, hi, c, ek_out, ep_out):
        """``energy_row`` as an entry point: a chunk-end row of the energy grid, J."""
        ek_out[:] = 0.0
        ep_out[:] = 0.0
        if lo >= 0:
            energy_row(u, v, mass, k, d0, wl, wr, lo, hi, c, ek_out, ep_out)

    def entry(func, suffix="", **options):
        func.__qualname__ = f"{func.__qualname__}{suffix}_{tag}"
        return _entry(func, ckey + suffix, **options)

    accelerations = entry(accelerations)
    run_steps = entry(make_run_chunk(False), "_steps")
    run_blocked = None if VD else entry(make_run_chunk(True), "_blocked")
    return Kernels(law, DRAG, RMAX, refined, VD, run_steps, run_blocked, accelerations,
                   entry(contact_energies), entry(grain_energies), entry(shadow_correction),
                   entry(static_forces), entry(dissipation_rate), entry(grid_row))



# ------------------------------------------------------------------ ensembles
_BATCH: dict[tuple, object] = {}

BATCH_PAD = 8
"""The ensemble pass integrates grains up to a multiple of this many (doubles in the
widest SIMD register): the resting grains it adds cost less than a scalar remainder."""


def batch_kernel(law: ContactLaw | None = None):
    r"""The ensemble kernel of a conservative ``law``: R chains of N grains in one call.

    Many realisations of a small chain (a disorder ensemble) are integrated in one
    compiled loop over the realisations, each on its own rows of (R, N) arrays
    (realisation first): a realisation's state and constants (u, v, the maxima and
    their times, 1/m, k, δ0, f0: 64 bytes a grain) stay in the L1/L2 cache through
    all its steps, and none of the per-step bookkeeping of :attr:`Kernels.run_steps`
    (the event tests, the special grains, the chunk calls) that dominates a
    200-grain chain's step is done.

    Each realisation's arithmetic is the per-step pass of the single-chain kernels
    (module docstring, "Passes"): the drift ``u + a_s h v`` of grain i+1, the overlap
    ``δ0 + (u_i - u_{i+1})`` (walls not drifted), φ = F(r) - f0, the kick
    ``v = (v + c1 a) + c2 a`` with the closing and the next opening kick fused, the
    running maximum on the synchronous velocity ``v + c1 a``; a run's last step closes
    with c2 = 0 and its acceleration is recomputed as ``accelerations`` does.

    Each pass integrates grains 0 … w of its realisation, w its *front*: grains right
    of the front are inert (at rest in equilibrium, u = v = 0, so F(δ0) - f0 = 0
    exactly and they stay so; module docstring).  Before every pass the front moves
    right while its grain is not at rest — a disturbance crosses at most one contact
    per pass — so the last grain integrated feels its resting right neighbour through
    the same arithmetic as in a whole-chain pass, and every realisation ends bit for
    bit where :meth:`discrete.Simulation.run` ends it
    (``tests/discrete/test_ensemble.py``).  A wave started at one end thus costs the
    grains it has reached, as in the single-chain kernels' active window.  Each
    realisation has its own time step and step count.

    Besides the running maximum ``vmax`` of the synchronous velocity (the transmitted
    amplitude at every grain, paper Fig. 2) the kernel keeps, if ``tmax`` has a column
    per grain, the time at which that maximum was reached, ``t0 + s h`` at the end of
    the step s that raised it (the arrival time of the wave's peak, resolved to one
    step): a second select per grain in the pass of the method's last substep, chosen
    at run time (one compiled kernel; the pass without it is a loop of its own).

    The passes are written out in the step loop (no helper taking the rows: its
    arguments' reference counts are calls into numba's runtime at every step, on a
    short chain as costly as the pass itself).

    Parameters
    ----------
    law : ContactLaw, optional
        A conservative contact law (default Hertz).

    Returns
    -------
    callable
        ``run_batch(st, con, p, walls, coef, steps)``, compiled on its first call (or
        loaded from the disk cache), apart from the single-chain kernels: a sweep of
        small chains compiles only it.  Its arguments:

        st : tuple of arrays
            ``(u, v, a, vmax, tmax)``: (R, N) displacements (m), velocities (m/s),
            accelerations (m/s², overwritten: computed from u at the start and at the
            end), running maxima of v (m/s) and their times (s; start them at t0; an
            (R, 0) array: no times); updated in place.
        con : tuple of arrays
            ``(inv_m, k, d0, f0)``: 1/m (R, N) in 1/kg, and per contact (R, N+1) the
            constants k (N/m^n), the static overlaps δ0 (m) and the static forces
            F(δ0) (N, computed with the kernels' arithmetic: ``Kernels.static_forces``).
        p : (P,) float array
            The law's runtime parameters (:func:`kernel_params`).
        walls : tuple of (R,) float arrays
            ``(w_L, w_R)`` wall displacements, m.
        coef : tuple
            ``(drift, kick, t0, dt)``: the method's coefficients per realisation, drift
            (R, S) = a_s h and kick (R, S+1) = b_s h (s), the start time t0 (R,) and
            the step h (R,) in s.
        steps : (R,) int64 array
            Steps of each realisation.
    """
    law = as_law(law)
    if law.dissipative:
        raise ValueError(f"law must be conservative for the ensemble kernel (got the "
                         f"{law.describe()}): velocity-dependent forces need the split "
                         "dissipative step of the single-chain kernels")
    key = law.key()
    if key not in _BATCH:
        _BATCH[key] = _build_batch(law)
    return _BATCH[key]


def _build_batch(law: ContactLaw):  # noqa: C901
    """Close the ensemble pass over the law's compiled force (:func:`batch_kernel`)."""
    force = law.make_force()
    ckey = f"batch|{law.key()!r}|{_source_digest(law)}"
    tag = "B" + hashlib.sha256(f"{law.key()!r}".encode()).hexdigest()[:12]

    @numba.njit(**_INLINE)
    def contact(r, kj, f0j, p):
        """φ = F(r) - f0 of one contact (conservative: the overlap rate is not read), N."""
        return force(r, 0.0, kj, p) - f0j

    @numba.njit(**_INLINE)
    def accelerations(u, a, inv_m, k, d0, f0, p, wl, wr):
        """Set a = (φ_i - φ_{i+1})/m_i of one chain (``accelerations``' arithmetic)."""
        n = u.size
        phl = contact(d0[0] + (wl - u[0]), k[0], f0[0], p)
        for i in range(n):
            ur = wr if i == n - 1 else u[i + 1]
            phr = contact(d0[i + 1] + (u[i] - ur), k[i + 1], f0[i + 1], p)
            a[i] = (phl - phr) * inv_m[i]
            phl = phr

    @numba.njit(**_INLINE)
    def pass_end(n, w):
        """Last grain m of a pass with front w (w up to a multiple of :data:`BATCH_PAD`, <= N-1)."""
        return min(n - 1, -(-w // BATCH_PAD) * BATCH_PAD)

    def run_batch(st, con, p, walls, coef, steps):
        """Advance every realisation by its ``steps`` (see :func:`batch_kernel`).

        A substep is one fused pass (drift, force, kick) over grains 0 … m of one
        chain ("Passes"), written out in the step loop (:func:`batch_kernel`).  The
        loops are those of the single-chain kernels' ``loop_arrays``: one base
        pointer for u[i] and u[i+1] (LLVM sees the distance-1 dependence and
        vectorises), the running maximum stored at every grain (:func:`_raised`) in
        a method's last substep.  The pass ends at grain m = ``pass_end(n, w)`` >= w:
        the grains w+1 … m are at rest in equilibrium and stay so bit for bit (u = 0 +
        h·0, φ = F(δ0) - f0 = 0, v = 0 + c·0), and the vectorised loop then needs no
        scalar remainder.  Grain m+1 (at rest when m < N-1) is drifted in the
        arithmetic but not stored.
        """
        u, v, a, vmax, tmax = st
        inv_m, k, d0, f0 = con
        wl, wr = walls
        drift, kick, t0, dt = coef
        nr = u.shape[0]
        ns = drift.shape[1]
        times = tmax.shape[1] > 0
        for r in range(nr):
            ur, vr, ar, vm, tr = u[r], v[r], a[r], vmax[r], tmax[r]
            im, kr, dr, fr = inv_m[r], k[r], d0[r], f0[r]
            k1, d1, f1 = kr[1:], dr[1:], fr[1:]
            wlr, wrr = wl[r], wr[r]
            accelerations(ur, ar, im, kr, dr, fr, p, wlr, wrr)
            nsteps = steps[r]
            if nsteps <= 0:
                continue
            n = ur.size
            # the front: the last grain that moves, is accelerated, or feels a wall
            # out of its place (the right wall's contact is then not in equilibrium)
            w = n - 1 if wrr != 0.0 else 0
            for i in range(n - 1, w - 1, -1):
                if ur[i] != 0.0 or vr[i] != 0.0 or ar[i] != 0.0:
                    w = i
                    break
            for i in range(n):  # the opening kick of the first step
                vr[i] = vr[i] + kick[r, 0] * ar[i]
            for s in range(nsteps):
                # the closing kick and the next step's opening one; the last step stops
                # at the synchronous velocity
                c2s = kick[r, 0] if s + 1 < nsteps else 0.0
                for q in range(ns):
                    while w < n - 1 and (ur[w] != 0.0 or vr[w] != 0.0):
                        w += 1
                    track = q == ns - 1
                    dc, c1 = drift[r, q], kick[r, q + 1]
                    c2 = c2s if track else 0.0
                    un = ur[0] + dc * vr[0]
                    ur[0] = un
                    phl = contact(dr[0] + (wlr - un), kr[0], fr[0], p)
                    m = pass_end(n, w)
                    tn = t0[r] + (s + 1) * dt[r]
                    if track and times:
                        for i in range(m):
                            unr = ur[i + 1] + dc * vr[i + 1]
                            ur[i + 1] = unr
                            phr = contact(d1[i] + (un - unr), k1[i], f1[i], p)
                            ai = (phl - phr) * im[i]
                            x = vr[i] + c1 * ai
                            g = _opaque(vm[i])
                            tt = _opaque(tr[i])
                            up = x > g
                            vm[i] = x if up else g
                            tr[i] = tn if up else tt
                            vr[i] = x + c2 * ai
                            phl = phr
                            un = unr
                    elif track:
                        for i in range(m):
                            unr = ur[i + 1] + dc * vr[i + 1]
                            ur[i + 1] = unr
                            phr = contact(d1[i] + (un - unr), k1[i], f1[i], p)
                            ai = (phl - phr) * im[i]
                            x = vr[i] + c1 * ai
                            vm[i] = _raised(vm[i], x)
                            vr[i] = x + c2 * ai
                            phl = phr
                            un = unr
                    else:
                        for i in range(m):
                            unr = ur[i + 1] + dc * vr[i + 1]
                            ur[i + 1] = unr
                            phr = contact(d1[i] + (un - unr), k1[i], f1[i], p)
                            ai = (phl - phr) * im[i]
                            vr[i] = (vr[i] + c1 * ai) + c2 * ai
                            phl = phr
                            un = unr
                    unr = wrr if m == n - 1 else ur[m + 1] + dc * vr[m + 1]
                    phr = contact(dr[m + 1] + (un - unr), kr[m + 1], fr[m + 1], p)
                    ai = (phl - phr) * im[m]
                    x = vr[m] + c1 * ai
                    if track and x > vm[m]:
                        vm[m] = x
                        if times:
                            tr[m] = tn
                    vr[m] = x + c2 * ai
            accelerations(ur, ar, im, kr, dr, fr, p, wlr, wrr)

    run_batch.__qualname__ = f"run_batch_{tag}"
    return _entry(run_batch, ckey)
