"""Compiled kernels shared by the continuum solvers (module-level ``@njit(cache=True)``).

py-pde provides finite-difference operators on its grids, but not the pieces the
staggered chain discretisation needs: face strains with the chain's boundary
conditions, flux divergences with face coefficients, and a solver for the constant
symmetric tridiagonal Rosenau mass operator.  These are the smallest such pieces.

Boundary codes: 0 = free (zero dynamic flux), 1 = wall (u = 0), 2 = periodic.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from theory import jitcache

jitcache.configure()  # compiled kernels cached outside the package (theory/jitcache.py)

FREE, WALL, PERIODIC = 0, 1, 2


@nb.njit(cache=True)
def face_strain(u, h, bc, s):
    """Dynamic overlap change s = -u_X at the faces (m per grain), with ghosts for ``bc``."""
    n = u.size
    if bc == PERIODIC:
        s[0] = -(u[0] - u[n - 1]) / h
        for q in range(1, n):
            s[q] = -(u[q] - u[q - 1]) / h
        return
    for q in range(1, n):
        s[q] = -(u[q] - u[q - 1]) / h
    if bc == WALL:
        s[0] = -2.0 * u[0] / h
        s[n] = 2.0 * u[n - 1] / h
    else:
        s[0] = 0.0
        s[n] = 0.0


@nb.njit(cache=True)
def flux_divergence(p, h, bc, out):
    """Node force density (P_q - P_{q+1})/h, N per grain length, from face forces ``p``."""
    n = out.size
    if bc == PERIODIC:
        for i in range(n - 1):
            out[i] = (p[i] - p[i + 1]) / h
        out[n - 1] = (p[n - 1] - p[0]) / h
    else:
        for i in range(n):
            out[i] = (p[i] - p[i + 1]) / h


def mass_operator_bands(mass, face_mass, h, ell2, bc):
    """Bands of the Rosenau mass operator M = m - ∂_X (m_f ℓ²) ∂_X on the nodes.

    ``ell2`` (grains²) is a scalar or one value per face.  Returns ``(diag, off,
    corner)``: the diagonal, the off-diagonal (between node p and p+1) and, for
    periodic chains, the wrap-around entry.  Ghost values: wall a_{-1} = -a_0, free
    a_{-1} = a_0 (see :mod:`continuum.boussinesq`).
    """
    w = np.broadcast_to(np.asarray(ell2, float), np.shape(face_mass)) * face_mass / h**2
    if bc == PERIODIC:
        # face q between node q-1 and q, q = 0..n-1
        diag = mass + w + np.roll(w, -1)
        return diag, -w[1:], -w[0]
    # n + 1 faces
    diag = mass + w[:-1] + w[1:]
    if bc == WALL:
        diag[0] += w[0]
        diag[-1] += w[-1]
    else:
        diag[0] -= w[0]
        diag[-1] -= w[-1]
    return diag, -w[1:-1], 0.0


def tridiag_factor(diag, off, corner):
    """Factor a symmetric tridiagonal (optionally cyclic) matrix for :func:`tridiag_solve`.

    Thomas algorithm; a cyclic matrix is handled by the Sherman–Morrison formula
    (Press et al., *Numerical Recipes*, 3rd ed., §2.7.2).  Returns a tuple of arrays.
    """
    n = diag.size
    d = diag.astype(float).copy()
    gamma = 0.0
    if corner != 0.0:
        gamma = -d[0]
        d[0] -= gamma
        d[-1] -= corner * corner / gamma
    den = np.empty(n)
    cp = np.zeros(n)
    den[0] = d[0]
    for i in range(1, n):
        cp[i - 1] = off[i - 1] / den[i - 1]
        den[i] = d[i] - off[i - 1] * cp[i - 1]
    offf = np.r_[off, 0.0].astype(float)
    z = np.zeros(n)
    vfac = np.zeros(3)
    if corner != 0.0:
        rhs = np.zeros(n)
        rhs[0], rhs[-1] = gamma, corner
        _thomas(den, cp, offf, rhs, z)
        vfac[0] = corner / gamma
        vfac[1] = 1.0 + z[0] + vfac[0] * z[-1]
        vfac[2] = 1.0
    return den, cp, offf, z, vfac


@nb.njit(cache=True)
def _thomas(den, cp, off, r, x):
    n = r.size
    x[0] = r[0] / den[0]
    for i in range(1, n):
        x[i] = (r[i] - off[i - 1] * x[i - 1]) / den[i]
    for i in range(n - 2, -1, -1):
        x[i] -= cp[i] * x[i + 1]


@nb.njit(cache=True)
def tridiag_solve(den, cp, off, z, vfac, r, x):
    """Solve M x = r with the factors of :func:`tridiag_factor` (O(n), in place in x)."""
    _thomas(den, cp, off, r, x)
    if vfac[2] != 0.0:
        f = (x[0] + vfac[0] * x[-1]) / vfac[1]
        for i in range(x.size):
            x[i] -= f * z[i]


def staggered_gradient(n_nodes: int, h: float, bc: int, order: int):
    r"""Stencil of the face strain s = -u_X of order 2 or 4 on the staggered grid.

    Face q lies between nodes q-1 and q.  Order 2: :math:`s_q = (u_{q-1} - u_q)/h`;
    order 4: :math:`s_q = (27(u_{q-1} - u_q) - (u_{q-2} - u_{q+1}))/(24h)` (Fornberg,
    Math. Comp. 51 (1988) 699, staggered weights 27/24 and -1/24).  Ghost nodes beyond
    the ends follow the boundary condition: wall (u = 0 at the end face) odd
    reflection u_{-1-j} = -u_j, free (no dynamic strain) even reflection u_{-1-j} = u_j
    — the strain of a free end face is set to exactly zero; periodic chains wrap.

    Returns ``(idx, coef)`` of shape (faces, width) with s_q = Σ_j coef[q, j] u[idx[q, j]]
    (m per grain for u in m, h in grains).  The matching node force density of face
    forces F is -Σ_q coef[q, j] F_q scattered to idx[q, j] (the exact transpose: the
    semi-discrete equations stay conservative and variational).
    """
    if order == 2:
        offs, wts = np.array([-1, 0]), np.array([1.0, -1.0]) / h
    elif order == 4:
        offs, wts = np.array([-2, -1, 0, 1]), np.array([-1.0, 27.0, -27.0, 1.0]) / (24 * h)
    else:
        raise ValueError(f"order must be 2 or 4 (got {order!r})")
    n = int(n_nodes)
    nf = n if bc == PERIODIC else n + 1
    q = np.arange(nf)[:, None]
    j = q + offs[None, :]
    coef = np.broadcast_to(wts, j.shape).copy()
    if bc == PERIODIC:
        idx = j % n
    else:
        sign = -1.0 if bc == WALL else 1.0
        left, right = j < 0, j >= n
        idx = np.where(left, -1 - j, np.where(right, 2 * n - 1 - j, j))
        coef = np.where(left | right, sign * coef, coef)
        if bc == FREE:
            coef[0] = coef[-1] = 0.0
    if np.any((idx < 0) | (idx >= n)):
        raise ValueError(f"{n} nodes are too few for the order-{order} stencil")
    return np.ascontiguousarray(idx, dtype=np.int64), np.ascontiguousarray(coef)
