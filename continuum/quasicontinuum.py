r"""The grain-averaged quasi-continuum: the chain's grain averages, Padé-regularised.

The lattice in one formula
--------------------------
For the displacement u(X) of a continuous grain coordinate X (X = grain index), paper
Eq. 2 reads exactly

.. math:: m\,u_{tt} = -\partial_X\,S\,\big[F(\delta) - F_0\big],\qquad
          \delta = \delta_0 + S\,s,\qquad s = -\partial_X u,

where S is the average over one grain, :math:`(Sf)(X) = \int_{X-1/2}^{X+1/2} f`, with
Fourier multiplier :math:`\mathrm{sinc}(k/2) = \sin(k/2)/(k/2)` (k per grain): the
overlap of a contact is the strain averaged over the grain between two centres,
u(X − ½) − u(X + ½), and the net force on a grain is the face force averaged the same
way, F(X − ½) − F(X + ½) (docs/physics.md §24).
Sampled at the grains this *is* the chain; on a continuous X it is a family of
uncoupled copies of the chain (S couples only points one grain apart), so it is no
continuum.  Its travelling waves are the exact discrete solitary waves (§7):
:math:`m V^2\delta = S^2F(\delta)` is the lattice's advance–delay equation.

The quasi-continuum
-------------------
Replace S by the Padé-type approximant

.. math:: \tilde S_M = P_M(-\partial_{XX})^{-1},\qquad
          P_M(K) = \sum_{j=0}^{M} a_j K^j = 1 + \frac{K}{24} + \frac{7K^2}{5760}
          + \frac{31K^3}{967680} + \dots,

P_M the Taylor polynomial of order M of :math:`1/\mathrm{sinc}(\sqrt K/2) =
(\sqrt K/2)/\sin(\sqrt K/2)` (:func:`averaging_coefficients`; its coefficients are
positive, :math:`a_j = 2(2^{2j-1}-1)|B_{2j}|/((2j)!\,4^j)`, B the Bernoulli numbers, and
the series converges for |k| < 2π).  Then

* :math:`\tilde S_M` (the [0/M] Padé approximant of sinc(k/2)) equals S to O(k^{2M+2}):
  the chain's dispersion
  :math:`\omega^2 = (K_0/m)\,k^2\tilde S_M^2 = (4K_0/m)\sin^2(k/2)\,(1 + O(k^{2M+2}))`;
* :math:`\tilde S_M` couples every X (a smooth kernel decaying like
  :math:`e^{-\kappa|X|}`, κ ≈ 2.4 and 3.8 per grain for M = 2 and 3): a continuum,
  whose limit as the grid is refined is a PDE, not the chain;
* it is bounded, 0 < \tilde S_M ≤ 1: ω² ≤ (K_0/m) max_K K/P_M(K)², so the time step is
  the lattice's whatever the grid, and the problem is well-posed in every regime, with
  or without precompression;
* the system stays Hamiltonian with the energy
  :math:`\int \tfrac12 m u_t^2 + [W(\delta) - W(\delta_0) - F_0(\delta - \delta_0)]\,dX`
  (W the law's elastic energy), which is bounded below for any contact law (W convex):
  no dispersion cap and no floor near δ = 0 is needed, unlike Eq. 7
  (:mod:`continuum.nesterenko`);
* the kinetic energy is the plain ½ m v², so the grain-sampled energies and the
  functional agree to the model's accuracy.

Its sonic-vacuum solitary wave (Hertz, grain-sampled overlap amplitude A) against the
exact discrete wave of the same A: speed −0.09 %, −0.03 %, −0.01 % and energy −1.6 %,
−0.42 %, −0.13 % for M = 2, 3, 4 (the compacton of Eq. 7: speed −1.2 %; travelling
waves by Petviashvili's iteration, docs/physics.md §24).  The default M = 3.

Discretisation
--------------
The staggered grid of :mod:`continuum.medium` (u, v on nodes, δ and F on faces), h = 1/n
grains.  The strain s = Gu is the two-point staggered difference, -L = -DᵀD/h² the
three-point second difference on the faces with even (Neumann) ends, so that B = P(L)
is a symmetric positive definite band matrix of half-bandwidth M with B·1 = 1 (a
uniform strain is averaged to itself; sums are kept).  It is factored once (B = ŨᵀDŨ);
each force evaluation is two banded solves:

.. math:: \delta = \delta_0 + B^{-1}Gu,\qquad m\,\ddot u = -G^{\mathsf T}B^{-1}
          \big[w\,(F(\delta) - F_0)\big],

the exact gradient of :math:`h\sum_q w_q[W(\delta_q) - W(\delta_{0,q}) - F_{0,q}(\delta_q
- \delta_{0,q})]` (w the face weights: ½ at a wall face, 0 at a free end face), so the
semi-discrete system conserves its energy and momentum.  Since GᵀG = L, the
semi-discrete linear dispersion is a function of L's eigenvalue λ = (4/h²)sin²(kh/2)
alone, (K_0/m) λ/P(λ)²; P is therefore taken as the Taylor polynomial in λ of
x/sin(n arcsin(x/n)), x = √λ/2 (:func:`averaging_coefficients` with ``nodes`` = n),
which makes it the lattice's 4 sin²(k/2) to O(λ^{M+1}) on every grid — one node per
grain gives P = 1 and the chain itself, n → ∞ the continuum's P_M (as Eq. 7's
``correct_h2``).  The remaining grid error, in the nonlinear terms, is O(h²).

Grain sampling (:func:`continuum.sample_grains`) reads the model's own contact overlap δ
(:meth:`GrainAveragedPDE.contact_overlaps`), not u_{j-1} − u_j: B⁻¹ ~ K^{-M} at high
wavenumbers, so sub-grain displacement patterns carry almost no energy and u may wiggle
on the grid scale where δ does not.

Not covered: periodic ends, dissipative laws or drag, and homogenised periodic cells
(a ValueError names them).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Mapping
from typing import Any

import numba as nb
import numpy as np
from scipy.linalg import cho_solve_banded, cholesky_banded
from scipy.sparse import diags
from scipy.special import bernoulli

from theory import jitcache
from theory.laws import ContactLaw

from . import _kernels as kern
from .base import WINDOW_TOLERANCE, ChainPDEBase
from .medium import Medium

__all__ = ["GrainAveragedPDE", "averaging_coefficients", "averaging_multiplier"]

WINDOW_PAD = 10.0
"""Grains of zero-strain faces added on either side of the active window
(:meth:`GrainAveragedPDE.make_chunk_stepper`)."""
MAX_TERMS = 6
"""Largest order M accepted (the series of 1/sinc converges for |k| < 2π; at M = 4 the
sonic-vacuum wave's energy is already within 0.13 % of the exact wave's)."""


def averaging_coefficients(terms: int, nodes: int | None = None) -> np.ndarray:
    r"""Coefficients a_0 … a_M of the averaging polynomial P_M, in K (grains⁻²).

    ``nodes`` None: the Taylor polynomial of 1/sinc(√K/2), from
    :math:`x/\sin x = \sum_j (-1)^{j+1}\,2(2^{2j-1}-1)\,B_{2j}\,x^{2j}/(2j)!` (Abramowitz &
    Stegun 4.3.68) at x = √K/2: a_j = 2(2^{2j-1}-1)|B_{2j}|/((2j)! 4^j) (1, 1/24, 7/5760,
    31/967680, …).  ``nodes`` = n: the grid's polynomial in the eigenvalue λ of L on
    n nodes per grain (module docstring, "Discretisation"), the Taylor polynomial of
    :math:`x/\sin(n\arcsin(x/n))`, x = √λ/2, so that the semi-discrete linear dispersion
    λ/P(λ)² is the lattice's 4 sin²(k/2) to O(λ^{M+1}) (n = 1: P = 1, the chain itself;
    n → ∞: the continuum's coefficients).
    """
    m = int(terms)
    if m != terms or not 1 <= m <= MAX_TERMS:
        raise ValueError(f"terms must be an integer in [1, {MAX_TERMS}] (got {terms!r})")
    if nodes is None:
        b = bernoulli(2 * m)
        return np.array([1.0] + [2.0 * (2.0 ** (2 * j - 1) - 1.0) * abs(b[2 * j])
                                 / math.factorial(2 * j) / 4.0**j for j in range(1, m + 1)])
    n = int(nodes)
    if n != nodes or n < 1 or n % 2 == 0:
        raise ValueError(f"nodes must be an odd integer >= 1 (got {nodes!r})")
    deg = 2 * m + 2  # truncated power series in x, degree < deg

    def mul(p, q):
        return np.convolve(p, q)[:deg]

    # z = n arcsin(x/n) = Σ_k (2k)!/(4^k k!² (2k+1)) x^{2k+1} / n^{2k}
    z = np.zeros(deg)
    for k in range(0, m + 1):
        if 2 * k + 1 < deg:
            z[2 * k + 1] = (math.factorial(2 * k) / (4.0**k * math.factorial(k) ** 2
                                                    * (2 * k + 1)) / n ** (2 * k))
    # sin z / x
    sz, power = np.zeros(deg), z.copy()
    for j in range(0, m + 1):
        sz += (-1) ** j * power / math.factorial(2 * j + 1)
        power = mul(mul(power, z), z)
    q = sz[1:]  # (sin z)/x, even in x: q[2j] the coefficient of x^{2j}
    # 1/q as a series (q[0] = 1)
    inv = np.zeros(deg - 1)
    inv[0] = 1.0
    for i in range(1, deg - 1):
        inv[i] = -sum(q[t] * inv[i - t] for t in range(1, i + 1))
    return np.array([inv[2 * j] / 4.0**j for j in range(m + 1)])


def averaging_multiplier(k: np.ndarray, terms: int) -> np.ndarray:
    """Fourier multiplier 1/P_M(k²) of the approximate grain average (k per grain)."""
    kk = np.asarray(k, float) ** 2
    return 1.0 / np.polynomial.polynomial.polyval(kk, averaging_coefficients(terms))


def band_rows(ub: np.ndarray) -> np.ndarray:
    """Rows of B = ŨᵀDŨ (Ũ unit upper banded) for :func:`_band_solve`, shape (n, 2M + 1).

    From the Cholesky factor ``ub`` in LAPACK's upper form (``ub[M + i - j, j] =
    U[i, j]``, B = UᵀU, Ũ = diag(U)⁻¹U, D = diag(U)²): column 0 holds 1/D_j, columns
    1 … M the entries Ũ[j - c, j] above the diagonal of column j (forward substitution),
    columns M + 1 … 2M the entries Ũ[j, j + c] of row j (backward substitution); entries
    outside the matrix are 0.  The unit diagonal keeps one multiply-add on each
    substitution's critical path.
    """
    m = ub.shape[0] - 1
    n = ub.shape[1]
    diag = ub[m]
    rows = np.zeros((n, 2 * m + 1))
    rows[:, 0] = 1.0 / diag**2
    for c in range(1, m + 1):
        unit = ub[m - c, c:] / diag[:n - c]  # Ũ[j - c, j] = U[j - c, j] / U[j - c, j - c]
        rows[c:, c] = unit
        rows[:n - c, m + c] = unit
    return np.ascontiguousarray(rows)


@nb.njit(cache=True, error_model="numpy")
def _band_solve(rows, b, x):
    """Solve ŨᵀDŨ x = b given as :func:`band_rows` (x may not alias b)."""
    m = (rows.shape[1] - 1) // 2
    n = b.size
    for j in range(n):  # Ũᵀ z = b
        acc = b[j]
        for c in range(1, min(m, j) + 1):
            acc -= rows[j, c] * x[j - c]
        x[j] = acc
    for j in range(n):
        x[j] *= rows[j, 0]
    for i in range(n - 1, -1, -1):  # Ũ x = D⁻¹ z
        acc = x[i]
        for c in range(1, min(m, n - 1 - i) + 1):
            acc -= rows[i, m + c] * x[i + c]
        x[i] = acc


_KERNELS: dict[str, Callable] = {}


def chunk_kernel(law: ContactLaw, terms: int) -> Callable:
    """The compiled chunk stepper of the quasi-continuum for ``law`` and M = ``terms``.

    ``chunk(u, v, nsteps, dt, alpha, beta, gidx, gcoef, w, k, d0, f0, rows, inv_m, s, dl)``
    advances (u, v) in place by ``nsteps`` steps of the splitting method with pass
    coefficients (α, β) (:func:`continuum.solver.splitting_coefficients`: drift α_j Δt,
    kick β_j Δt, closing drift) and returns the node-updates; each kick's acceleration is
    :meth:`GrainAveragedPDE._acceleration_numpy`'s (strain, two banded solves of
    :func:`band_rows`' form with M a compile-time constant, the law's force).  Built
    once per law and M, with a disk cache keyed by both and the sources
    (:func:`theory.jitcache.keyed_njit`).
    """
    cls = type(law)
    classes = [c for c in cls.__mro__ if isinstance(c, type) and issubclass(c, ContactLaw)]
    key = (f"quasicontinuum|{law.key()!r}|M={int(terms)}|"
           f"{jitcache.source_digest(sys.modules[__name__], *classes)}")
    if key not in _KERNELS:
        elastic = law.make_elastic()
        m = int(terms)

        def solve(rows, b, x, qa, qb):
            """B⁻¹ on faces [qa, qb] with the factor rows ``rows[0 … qb - qa]``."""
            n = qb + 1 - qa
            for j in range(min(m, n)):
                acc = b[qa + j]
                for c in range(j, 0, -1):
                    acc -= rows[j, c] * x[qa + j - c]
                x[qa + j] = acc
            for j in range(m, n):  # oldest term first: one multiply-add on the chain
                acc = b[qa + j]
                for c in range(m, 0, -1):
                    acc -= rows[j, c] * x[qa + j - c]
                x[qa + j] = acc
            for j in range(n):
                x[qa + j] *= rows[j, 0]
            for i in range(n - 1, max(n - 1 - m, -1), -1):  # the last M rows first
                acc = x[qa + i]
                for c in range(n - 1 - i, 0, -1):
                    acc -= rows[i, m + c] * x[qa + i + c]
                x[qa + i] = acc
            for i in range(n - 1 - m, -1, -1):
                acc = x[qa + i]
                for c in range(m, 0, -1):
                    acc -= rows[i, m + c] * x[qa + i + c]
                x[qa + i] = acc

        # one compiled copy for the chunk's two solves, without wrappers for Python callers
        solve_c = jitcache.keyed_njit(solve, key, cache=False, nogil=True,
                                      error_model="numpy", no_cpython_wrapper=True,
                                      no_cfunc_wrapper=True)

        def qc_chunk(u, v, nsteps, dt, alpha, beta, gidx, gcoef, w, k, d0, f0, rows, inv_m,
                     s, dl, trows, win, pad, tau_v, tau_d):
            n = u.size
            nf, width = gidx.shape
            nsub = beta.size
            work = 0
            for _ in range(nsteps):
                for j in range(nsub + 1):
                    # faces [qa, qb] and nodes [qa - 1, qb] swept: the whole chain, or
                    # the active window padded by ``pad`` faces of zero strain
                    if win[0] == -2:
                        qa, qb, fac = 0, nf - 1, rows
                    elif win[0] < 0:
                        continue
                    else:
                        qa, qb, fac = win[0] - pad, win[1] + 1 + pad, trows
                        if qb >= nf - 1:  # the right end: the whole chain from now on
                            win[0] = -2
                            qa, qb, fac = 0, nf - 1, rows
                        elif qa <= 0:  # the left end: the leading rows of the chain's own
                            qa, fac = 0, rows
                    lo, hi = max(qa - 1, 0), min(qb, n - 1)
                    a = alpha[j] * dt
                    if a != 0.0:
                        for i in range(lo, hi + 1):
                            u[i] += a * v[i]
                    if j == nsub:
                        break
                    for q in range(qa, qb + 1):
                        acc = 0.0
                        for c in range(width):
                            acc += gcoef[q, c] * u[gidx[q, c]]
                        s[q] = acc
                    solve_c(fac, s, dl, qa, qb)
                    for q in range(qa, qb + 1):
                        s[q] = w[q] * (elastic(d0[q] + dl[q], k[q]) - f0[q])
                    solve_c(fac, s, dl, qa, qb)
                    b = beta[j] * dt
                    for q in range(qa, qb + 1):
                        fq = b * dl[q]
                        for c in range(width):
                            i = gidx[q, c]
                            v[i] -= gcoef[q, c] * fq * inv_m[i]
                    work += hi + 1 - lo
                    if win[0] >= 0:
                        # the nodes still moving or next to a face with a force (faces
                        # qa … qb were evaluated just now)
                        new_lo = -1
                        for i in range(qa, qb):
                            if (abs(v[i]) > tau_v or abs(s[i]) > tau_d
                                    or abs(s[i + 1]) > tau_d):
                                new_lo = i
                                break
                        new_hi = new_lo
                        for i in range(qb - 1, new_lo, -1):
                            if (abs(v[i]) > tau_v or abs(s[i]) > tau_d
                                    or abs(s[i + 1]) > tau_d):
                                new_hi = i
                                break
                        win[0] = new_lo
                        win[1] = new_hi
            return work

        _KERNELS[key] = jitcache.keyed_njit(qc_chunk, key, nogil=True, error_model="numpy")
    return _KERNELS[key]


class GrainAveragedPDE(ChainPDEBase):
    r"""Grain-averaged quasi-continuum (module docstring) for any elastic contact law.

    .. math::
        \partial_t u = v,\qquad m\,\partial_t v = -\partial_X\,\tilde S_M\big[F(\delta) -
        F_0\big],\qquad \delta = \delta_0 + \tilde S_M\,s,\quad s = -\partial_X u,

    X in grains, u in m, t in s, m(X) grain mass (kg), F the law's elastic force at the
    face's constant k(X) (N), δ0(X), F0(X) the static overlap (m) and force (N);
    :math:`\tilde S_M = P_M(-\partial_{XX})^{-1}` the order-M Padé-type grain average.

    Parameters
    ----------
    medium : Medium
        Chain, with or without precompression (not dissipative, no periodic cells).
    n : int
        Nodes per grain (odd).
    bc : {"free", "wall"}
        Boundary condition at both ends.
    terms : int
        M, the order of the averaging polynomial, 1 … :data:`MAX_TERMS` (default 3).
    """

    name = "qc"
    label = "quasi-continuum"
    default_integrator = "position_verlet"
    """Position (drift-first) Verlet, second order: S̃_M damps the grid's wavenumbers as
    K^{-M}, so the wave's own frequencies lie far below ω_max and the step's error stays
    below the model's own; on ten strongly nonlinear points of the model-validity map
    its errors against the chain are Yoshida-4's within 0.2 % of the incident energy, for
    one force evaluation per step instead of Yoshida-4's three (docs/physics.md §24; the
    CPU times in docs/benchmarks.md)."""
    default_dt_safety = 0.8
    """ω_max Δt = 0.96 (:meth:`stable_dt`: 1.2 × safety/ω_max), half position Verlet's
    limit 2 (the scenario's check, 2 × safety < 2, is the more cautious here): with the
    wave's frequencies far below ω_max (S̃_M damps the grid's wavenumbers as K^{-M},
    docs/physics.md §24) the step is not at its stability limit, and on twelve strongly
    nonlinear points the errors against the chain moved by at most 0.7 % of the incident
    energy from those at safety 0.5, for 1.6 times fewer steps."""
    smooth_interpolation = "band_limited"
    """A smooth grain state is launched band-limited (:func:`continuum.initial.band_limited`):
    the chain's overlaps are then exactly the grain averages of its strain, which S̃_M
    approximates; a cubic spline hands the sonic-vacuum wave ~2 % less energy."""

    def __init__(self, medium: Medium, n: int = 5, *, bc: str = "free", terms: int = 3
                 ) -> None:
        if bc == "periodic":
            raise ValueError("bc must be 'free' or 'wall' for the quasi-continuum (got "
                             "'periodic')")
        super().__init__(medium, n, bc=bc)
        if self.dissipative:
            raise ValueError("the quasi-continuum is conservative: a dissipative law or "
                             "drag takes continuum 'eq4' or 'eq7'")
        d = self.disc
        if not np.all(d.dispersion == 1.0):
            raise ValueError("the quasi-continuum needs a chain without periodic cells "
                             "(homogenised dimers and trimers take 'eq4' or 'eq7')")
        self.terms = int(terms)
        self.coefficients = averaging_coefficients(terms, n)
        self._grad = kern.staggered_gradient(d.x_nodes.size, d.h, self._bc_code, 2)
        nf = d.x_faces.size
        self._band = self._factor(nf, d.h)
        self._rows = band_rows(self._band)
        self._f0 = d.f0
        self._last: tuple[np.ndarray, list] | None = None

    def _pade_band(self, nf: int, h: float, even_ends: bool):
        """B = P_M(L) on ``nf`` faces, as a sparse matrix and its upper band rows.

        L = DᵀD/h² is the three-point Laplacian; ``even_ends``: even (Neumann) ends,
        L·1 = 0 (the whole chain), else the plain stencil (a window of interior faces).
        """
        m = self.terms
        diag = np.full(nf, 2.0)
        if even_ends:
            diag[0] = diag[-1] = 1.0
        lap = diags([-np.ones(nf - 1), diag, -np.ones(nf - 1)], [-1, 0, 1],
                    format="csr") / (h * h)
        b = diags([np.full(nf, self.coefficients[0])], [0], format="csr")
        power = diags([np.ones(nf)], [0], format="csr")
        for j in range(1, m + 1):
            power = power @ lap
            b = b + self.coefficients[j] * power
        ab = np.zeros((m + 1, nf))
        for off in range(m + 1):
            ab[m - off, off:] = b.diagonal(off)
        return b, ab

    def _factor(self, nf: int, h: float) -> np.ndarray:
        """Upper banded Cholesky factor of B = P_M(L), L = DᵀD/h² on ``nf`` faces."""
        self._bmat, ab = self._pade_band(nf, h, even_ends=True)
        return np.ascontiguousarray(cholesky_banded(ab, lower=False))

    @classmethod
    def for_chain(cls, medium: Medium, *, nodes_per_grain: int, bc: str,
                  options: Mapping[str, Any]) -> GrainAveragedPDE:
        """See :meth:`ChainPDEBase.for_chain` (reads no option; M = 3)."""
        return cls(medium, nodes_per_grain, bc=bc)

    # ------------------------------------------------------------------ operators
    def strain(self, u: np.ndarray) -> np.ndarray:
        """Dynamic strain s = -u_X at the faces, m per grain (two-point difference)."""
        idx, coef = self._grad
        return np.einsum("qj,qj->q", coef, np.asarray(u, float)[idx])

    def divergence(self, p: np.ndarray) -> np.ndarray:
        """Node force density -Gᵀ(w p), the exact transpose of :meth:`strain`."""
        idx, coef = self._grad
        out = np.zeros(self.disc.x_nodes.size)
        np.add.at(out, idx.ravel(), -(coef * (self._face_weight * p)[:, None]).ravel())
        return out

    def average(self, y: np.ndarray) -> np.ndarray:
        """The approximate grain average B⁻¹y = P_M(L)⁻¹ y of a face field (NumPy)."""
        return cho_solve_banded((self._band, False), np.asarray(y, float))

    def overlaps(self, u: np.ndarray) -> np.ndarray:
        """Face overlaps δ = δ0 + B⁻¹ s, m (may be negative: a gap).

        The last displacement's overlaps are kept: a sample reads them up to three times
        (grain sampling, the energy monitor, the energy densities), and each is a banded
        solve over the chain.
        """
        return self._kept(u)[0].copy()

    def _kept(self, u: np.ndarray) -> list:
        """[δ, potential per face or None] of ``u``, recomputed when ``u`` changes."""
        u = np.asarray(u, float)
        last = self._last
        if last is None or last[0].shape != u.shape or not np.array_equal(last[0], u):
            last = self._last = (u.copy(), [self.disc.delta0 + self.average(self.strain(u)),
                                            None])
        return last[1]

    def _potential(self, u: np.ndarray) -> np.ndarray:
        r"""Dynamic potential energy per face h w [W(δ) − W(δ0) − F0 (δ − δ0)], J.

        Evaluated only on the faces with δ ≠ δ0 (the rest is exactly 0): a sonic-vacuum
        chain is mostly at rest; kept with the overlaps of the last ``u``.
        """
        kept = self._kept(u)
        if kept[1] is not None:
            return kept[1].copy()
        d = self.disc
        delta = kept[0]
        out = np.zeros(delta.size)
        q = np.flatnonzero(delta != d.delta0)
        out[q] = d.h * self._face_weight[q] * (
            self.law.energy(delta[q], d.k[q], d.delta0[q])
            - self._f0[q] * (delta[q] - d.delta0[q]))
        kept[1] = out
        return out.copy()

    def contact_overlaps(self, u: np.ndarray) -> np.ndarray:
        """The model's overlap δ of every contact (its face), m: what grain sampling reads.

        Not u_{j-1} - u_j: sub-grain displacement patterns of high wavenumber carry almost
        no energy in the model (B⁻¹ ~ K^{-M}), so u may wiggle on the grid scale where δ
        does not; δ is the quantity the model's forces and energy are made of
        (:func:`continuum.sample_grains` reads it).
        """
        return self.overlaps(u)[self.disc.contact_faces]

    def flux(self, u: np.ndarray) -> np.ndarray:
        """Averaged dynamic face force B⁻¹[w (F(δ) - F0)], N (NumPy)."""
        d = self.disc
        f = self.law.elastic(self.overlaps(u), d.k) - self._f0
        return self.average(self._face_weight * f)

    def _acceleration_numpy(self, u: np.ndarray) -> np.ndarray:
        idx, coef = self._grad
        p = self.flux(u)
        out = np.zeros(self.disc.x_nodes.size)
        np.add.at(out, idx.ravel(), -(coef * p[:, None]).ravel())
        return out / self.disc.mass

    def _make_acceleration_numba(self) -> Callable:
        d = self.disc
        idx, coef = (a.copy() for a in self._grad)
        nf, width = idx.shape
        ub = self._rows.copy()
        k, d0, f0, w = d.k.copy(), d.delta0.copy(), self._f0.copy(), self._face_weight.copy()
        inv_m = 1.0 / d.mass
        elastic = self.law.make_elastic()

        @nb.njit
        def accel(u, out):
            s = np.zeros(nf)
            for q in range(nf):
                acc = 0.0
                for j in range(width):
                    acc += coef[q, j] * u[idx[q, j]]
                s[q] = acc
            dl = np.empty(nf)
            _band_solve(ub, s, dl)
            for q in range(nf):
                s[q] = w[q] * (elastic(d0[q] + dl[q], k[q]) - f0[q])
            _band_solve(ub, s, dl)
            out[:] = 0.0
            for q in range(nf):
                for j in range(width):
                    out[idx[q, j]] -= coef[q, j] * dl[q]
            for i in range(out.size):
                out[i] *= inv_m[i]

        return accel

    # ------------------------------------------------------------------ fused stepper
    def make_chunk_stepper(self, state, dt: float, alpha, beta) -> Callable:
        """Compiled ``chunk(state_data, nsteps) -> node_updates`` (:func:`chunk_kernel`).

        Only the active window is swept, with or without precompression (a chain at
        rest ahead of and behind a wave has s = 0, so δ = δ0 and F(δ) − F0 = 0 there
        exactly): the nodes that move (|v| above 2⁻⁵² of the state's largest) or
        touch a face whose dynamic force |w (F(δ) − F0)| exceeds 2⁻⁵² of the largest
        (the kernel tests it after each kick), padded by :data:`WINDOW_PAD` grains of
        faces on either side; B⁻¹ there is the leading block of the factor of the
        constant-coefficient (Toeplitz) band matrix (a leading principal submatrix's
        Cholesky factor is the leading block of the whole's), whose kernel decays as
        e^{−κ|X|} (κ ≈ 3.8 per grain at M = 3), so the padding leaves out terms below
        e^{−κ·WINDOW_PAD} ≈ 1e-16 of the wave's.  A window from the left end uses the
        leading rows of the chain's own factor (the same prefix property); once the padded
        window reaches the right end the whole chain is swept from then on.
        """
        kernel = chunk_kernel(self.law, self.terms)
        d = self.disc
        gidx, gcoef = (np.ascontiguousarray(a) for a in self._grad)
        arrays = (gidx, gcoef, self._face_weight.copy(), d.k.copy(), d.delta0.copy(),
                  self._f0.copy(), self._rows, 1.0 / d.mass)
        nf = d.x_faces.size
        s, dl = np.zeros(nf), np.zeros(nf)
        alpha = np.ascontiguousarray(alpha, dtype=float)
        beta = np.ascontiguousarray(beta, dtype=float)
        dt = float(dt)
        data = np.asarray(state.data)
        pad = int(math.ceil(WINDOW_PAD / d.h))
        win = np.array([-2, -2], dtype=np.int64)
        tau_v = tau_d = 0.0
        tau_v = WINDOW_TOLERANCE * float(np.abs(data[1]).max(initial=0.0))
        force = np.abs(self._face_weight * (self.law.elastic(self.overlaps(data[0]), d.k)
                                            - self._f0))
        tau_d = WINDOW_TOLERANCE * float(force.max(initial=0.0))
        act = (np.abs(data[1]) > tau_v) | (force[:-1] > tau_d) | (force[1:] > tau_d)
        idx = np.flatnonzero(act)
        win[:] = [idx[0], idx[-1]] if idx.size else [-1, -1]
        trows = self._toeplitz_rows(nf)

        def chunk(state_data: np.ndarray, nsteps: int) -> int:
            return kernel(state_data[0], state_data[1], int(nsteps), dt, alpha, beta,
                          *arrays, s, dl, trows, win, pad, tau_v, tau_d)

        chunk.window = win  # type: ignore[attr-defined]
        return chunk

    def _toeplitz_rows(self, nf: int) -> np.ndarray:
        """:func:`band_rows` of the constant-coefficient band matrix P(L) on ``nf`` faces.

        L here is the plain three-point Laplacian (no even ends): the matrix a window of
        interior faces sees.
        """
        _, ab = self._pade_band(nf, self.disc.h, even_ends=False)
        return band_rows(np.ascontiguousarray(cholesky_banded(ab, lower=False)))

    def make_monitor(self) -> Callable:
        """``monitor(state_data) -> (energy J, momentum kg m/s)``, as :meth:`invariants`."""
        def monitor(state_data: np.ndarray) -> tuple[float, float]:
            u, v = np.asarray(state_data[0]), np.asarray(state_data[1])
            d = self.disc
            ep = self._potential(u)
            return (float(0.5 * d.h * np.sum(d.mass * v * v) + ep.sum()),
                    float(d.h * np.sum(d.mass * v)))

        return monitor

    # ------------------------------------------------------------------ energy
    def energy_density(self, state) -> tuple[np.ndarray, np.ndarray]:
        r"""Kinetic energy per node ½ h m v² and potential energy per face, J.

        Potential: :math:`h\,w_q[U(\delta_q) - U(\delta_{0,q}) - F_{0,q}(\delta_q -
        \delta_{0,q})]` with U the law's elastic energy (Hertz (2/5) k δ^{5/2}).
        """
        d = self.disc
        u, v = np.asarray(state[0].data), np.asarray(state[1].data)
        return 0.5 * d.h * d.mass * v * v, self._potential(u)

    def max_frequency_factor(self) -> float:
        """Largest, over the grid's wavenumbers, of K/P_M(K)², K ∈ [0, 4/h²] (grains⁻²).

        ω_max² = (K_0/m) × this, with K_0 the largest contact stiffness (N/m).
        """
        kk = np.linspace(0.0, 4.0 / self.disc.h**2, 4001)
        return float(np.max(kk / np.polynomial.polynomial.polyval(kk, self.coefficients)
                            ** 2))

    def stable_dt(self, state, safety: float = 0.5) -> float:
        """Time step 1.2 ``safety``/ω_max, s (ω_max Δt = 0.6 at the default safety).

        ω_max from :meth:`max_frequency_factor` and the law's stiffness at the largest
        overlap of ``state`` over the lightest grain: bounded whatever the grid (module
        docstring), about the lattice's own 2 (K/m)^{1/2}.  The scenario's check of
        ``[models] dt_safety`` (ω_max Δt = 2 safety below the integrator's limit,
        Yoshida-4 1.57) is more cautious here, as for Eq. 7.  With Yoshida-4 the energy
        error of a sonic-vacuum solitary wave is ~1e-5 at ω_max Δt = 0.6 and grows as
        Δt⁴; at 1.0 a wave crossing into grains four times heavier drifts by 6e-3.
        """
        d = self.disc
        delta = np.maximum(self.overlaps(np.asarray(state[0].data)), d.delta0)
        c2 = np.max(self.law.stiffness(delta, d.k)) / d.mass.min()
        return float(safety * 1.2 / np.sqrt(c2 * self.max_frequency_factor()))

    @property
    def parameters(self) -> dict:
        """Run parameters for HDF5 attributes."""
        return {**super().parameters, "averaging_terms": self.terms,
                "regularisation": "grain average S -> 1/P_M(-d_XX), P_M Taylor of 1/sinc"}
