r"""Weakly nonlinear long-wave equation of a precompressed chain (corrected Eq. 4).

Regularisation
--------------
The paper's Eq. 4, corrected (docs/physics.md §2), reads in grain units X = x/d

.. math:: u_{tt} = \frac{K}{m}\Big(u_{XX} + \frac{1}{12}u_{XXXX}
          - \frac{1}{2\delta_0}u_X u_{XX}\Big),\qquad K = \tfrac32 k_n\delta_0^{1/2},

i.e. :math:`c_0^2 (u_{xx} + (d^2/12)u_{xxxx} - (d/(2\delta_0))u_x u_{xx})` with
:math:`c_0^2 = K d^2/m`.  Linearised it has :math:`\omega^2 = c_0^2k^2(1 - k^2d^2/12)`,
negative for :math:`k > \sqrt{12}/d`: ill-posed (docs/physics.md §4).  We solve instead the
Rosenau quasi-continuum / "improved Boussinesq" form, which replaces
:math:`(c_0^2 d^2/12)u_{xxxx}` by :math:`(d^2/12)u_{xxtt}` (equal to leading order
because :math:`u_{tt} = c_0^2 u_{xx} + \dots`), written in flux form for a composite
medium:

.. math:: \Big(m - \partial_X \frac{m}{12} \partial_X\Big) u_{tt} = -\partial_X P(s, X),
          \qquad s = -u_X,\qquad P = K s + \frac{K}{4\delta_0} s^2 .

Why this form (and not a spectral cut-off at the Brillouin zone):

* it is well-posed — :math:`\omega^2 = c_0^2k^2/(1 + k^2d^2/12) \le 12 c_0^2/d^2` for
  every k, so explicit time steps do not shrink with the grid spacing;
* it keeps the long-wave accuracy of Eq. 4 (both agree to O(k⁴)) *and* its solitary
  wave: the travelling wave is the sech² of Eq. 4 with exactly the same amplitude–speed
  relation :math:`V^2 = c_0^2(1 + A/(6\delta_0))` (Eq. 5 to first order), only wider
  by the factor V/c0 (:func:`continuum.initial.solitary_wave`);
* the mass operator is symmetric positive definite and local, so the equation keeps a
  flux form (force and particle velocity continuous at an interface, paper Eq. 10) and
  conserves momentum and the energy

  .. math:: E = \int \tfrac12 m\,u_t^2 + \tfrac{m}{24}u_{Xt}^2
            + W(s, X)\,dX,\qquad W = \tfrac12 K s^2 + \frac{K}{12\delta_0}s^3;

  the regularisation moves the dispersive energy from the (indefinite) potential into
  the (positive) kinetic energy.  A spectral cut-off would need periodic, uniform media.

P is the *dynamic* contact force (F - F0); the static F0 is uniform (force equilibrium,
paper below Eq. 9) and drops out of the flux divergence.  ``nonlinearity="hertz"``
replaces the quadratic P by the full law :math:`k[\delta_0 + s]_+^{3/2} - F_0` (Eq. 1) —
the Rosenau quasi-continuum of the Hertz chain — for amplitude studies.

Discretisation: staggered second-order finite volumes (:mod:`continuum.medium`); the
mass operator is a constant symmetric tridiagonal matrix (m at nodes, m at faces = mean
of the two nodes), factored once and solved in O(N) per evaluation.  py-pde has no
operator for this Helmholtz-type inverse, hence :mod:`continuum._kernels`.

The two-point differences add their own dispersion: linearised, the semi-discrete
relation is ω² = (K/m) D_h/(1 + ℓ² D_h) with D_h = (4/h²) sin²(kh/2) = k²(1 - k²h²/12 +
…), i.e. the continuum's with ℓ² = 1/12 replaced by (1 + h²)/12 to O(k⁴).  With
``correct_h2`` (default) the mass operator uses ℓ_h² = (1 - h²)/12 (grain units), which
cancels it: the linear dispersion is then exact to O(h⁴k⁶) (the error coefficient of
k⁶ is -h⁴/240), and at n = 1 the scheme is the discrete chain with the quadratic
contact law.  What remains is the O(h²) of the nonlinear flux, a factor ~A/δ0 smaller:
measured on the paper's wave over 20 d, errors 1.5e-5, 7e-6, 2.5e-6 at n = 3, 5, 9
against 3.0e-3, 1.1e-3, 3.4e-4 uncorrected (tests).  Time stepping adds Verlet's
O(Δt²) dispersion of the opposite sign (it cancels the uncorrected scheme's at the
"magic" c Δt = h, n = 3 with the default step); use ``order=4`` for accuracy
(benchmarks/continuum.py ``--accuracy``).  The fused compiled stepper
(:mod:`continuum._stepper`) solves the tridiagonal system with a twisted ("burn at both
ends") factorisation over the active window.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numba as nb
import numpy as np
from scipy.sparse import csc_matrix, diags
from scipy.sparse.linalg import splu

from . import _kernels as kern
from . import _stepper
from .base import ChainPDEBase
from .medium import Medium

__all__ = ["BoussinesqPDE", "DISPERSION_LENGTH2"]

DISPERSION_LENGTH2 = 1.0 / 12.0
"""Dispersive length² of the lattice, d²/12 (Taylor series of the second difference;
paper Eq. 4 corrected), in grain diameters²."""


class BoussinesqPDE(ChainPDEBase):
    r"""Regularised (Rosenau) form of the corrected Eq. 4 for a composite chain.

    .. math::
        \partial_t u &= v \\
        \Big(m - \partial_X \frac{m}{12}\partial_X\Big)\partial_t v
            &= -\partial_X \Big(K s + \frac{K}{4\delta_0}s^2\Big),\quad s = -\partial_X u

    with X in grain diameters, u in m, t in s, m(X) the grain mass (kg), K(X) the
    linearised contact stiffness (N/m) and δ0(X) the static overlap (m).  See the
    module docstring for the regularisation and its conserved energy.

    Parameters
    ----------
    medium : Medium
        Chain; must be precompressed (δ0 > 0).
    n : int
        Nodes per grain (odd).
    bc : {"free", "wall", "periodic"}
        Boundary condition at both ends.
    nonlinearity : {"quadratic", "hertz", "linear"}
        Flux P(s): Eq. 4's quadratic expansion (default), the full Hertz law (Eq. 1),
        or its linearisation K s (for dispersion and acoustic tests).
    correct_h2 : bool
        Use ℓ_h² = (1 - h²)/12 in the mass operator (module docstring): cancels the
        O(h²) dispersion of the differences.  Attribute ``ell2`` holds the value used.
    """

    def __init__(self, medium: Medium, n: int = 5, *, bc: str = "free",
                 nonlinearity: str = "quadratic", correct_h2: bool = True) -> None:
        super().__init__(medium, n, bc=bc)
        if not medium.precompressed:
            raise ValueError("BoussinesqPDE needs a precompressed chain (delta0 > 0); "
                             "use NesterenkoPDE for the sonic vacuum")
        if nonlinearity not in ("quadratic", "hertz", "linear"):
            raise ValueError(f"nonlinearity must be 'quadratic', 'hertz' or 'linear' "
                             f"(got {nonlinearity!r})")
        self.nonlinearity = nonlinearity
        self._nl_code = {"linear": 0, "quadratic": 1, "hertz": 2}[nonlinearity]
        d = self.disc
        self._K = d.stiffness
        self._b = self._K / (4.0 * d.delta0)  # quadratic coefficient, N/m²
        self.correct_h2 = bool(correct_h2)
        # ℓ_h² = (1 - h²)/12: the staggered second difference adds h²/12 u_XXXX, so
        # this makes the linear dispersion exact to O(h⁴ k⁶) (module docstring)
        self.ell2 = DISPERSION_LENGTH2 * (1.0 - d.h**2) if self.correct_h2 \
            else DISPERSION_LENGTH2
        diag, off, corner = kern.mass_operator_bands(
            d.mass, d.face_mass, d.h, self.ell2, self._bc_code
        )
        self._bands = (diag, off, corner)
        self._factors = kern.tridiag_factor(diag, off, corner)
        self._factor_cache: list = []

    @functools.cached_property
    def _lu(self):
        """The NumPy path's independent sparse LU of the same operator, built on first use.

        Only :meth:`_acceleration_numpy` reads it (the compiled steppers use
        ``_factors``): a run on the fused stepper does not pay ``splu`` (0.11 s at
        150,000 nodes, Fig. 5 --full).  Built in CSC directly (a LIL detour cost ~0.4 s).
        """
        diag, off, corner = self._bands
        n_nodes = diag.size
        mat = diags([off, diag, off], [-1, 0, 1], shape=(n_nodes, n_nodes), format="csc")
        if corner != 0.0:
            mat = mat + csc_matrix(([corner, corner], ([0, n_nodes - 1], [n_nodes - 1, 0])),
                                   shape=(n_nodes, n_nodes))
        return splu(mat)

    # ------------------------------------------------------------------ flux
    def flux(self, s: np.ndarray) -> np.ndarray:
        """Dynamic contact force P(s) = F - F0 at the faces, N (NumPy)."""
        d = self.disc
        if self._nl_code == 0:
            return self._K * s
        if self._nl_code == 1:
            return self._K * s + self._b * s * s
        return d.k * np.maximum(d.delta0 + s, 0.0) ** 1.5 - d.k * d.delta0**1.5

    def potential(self, s: np.ndarray) -> np.ndarray:
        """Dynamic potential energy density W(s) = ∫0^s P ds' per face, J per grain length."""
        d = self.disc
        if self._nl_code == 0:
            return 0.5 * self._K * s * s
        if self._nl_code == 1:
            return 0.5 * self._K * s * s + self._b * s**3 / 3.0
        dl = np.maximum(d.delta0 + s, 0.0)
        return 0.4 * d.k * (dl**2.5 - d.delta0**2.5) - d.k * d.delta0**1.5 * s

    def _acceleration_numpy(self, u: np.ndarray) -> np.ndarray:
        rhs = self.divergence(self.flux(self.strain(u)))
        return self._lu.solve(rhs)

    def _make_acceleration_numba(self) -> Callable:
        d = self.disc
        h, bc, nl = float(d.h), int(self._bc_code), int(self._nl_code)
        kk, bb = self._K.copy(), self._b.copy()
        kh, d0 = d.k.copy(), d.delta0.copy()
        f0 = kh * d0**1.5
        den, cp, off, z, vfac = self._factors
        n_faces = d.x_faces.size
        face_strain, flux_div, solve = kern.face_strain, kern.flux_divergence, kern.tridiag_solve

        @nb.njit
        def accel(u, out):
            s = np.empty(n_faces)
            face_strain(u, h, bc, s)
            for q in range(n_faces):
                if nl == 0:
                    s[q] = kk[q] * s[q]
                elif nl == 1:
                    s[q] = (kk[q] + bb[q] * s[q]) * s[q]
                else:
                    dl = d0[q] + s[q]
                    s[q] = (kh[q] * dl**1.5 if dl > 0.0 else 0.0) - f0[q]
            rhs = np.empty(u.size)
            flux_div(s, h, bc, rhs)
            solve(den, cp, off, z, vfac, rhs, out)

        return accel

    # ------------------------------------------------------------------ fused stepper
    def _kernel_arrays(self) -> tuple:
        """Face coefficients (K, B, k, δ0, f0) of the compiled kernels."""
        d = self.disc
        kh, d0 = d.k.copy(), d.delta0.copy()
        # f0 with the kernel's own arithmetic, so that P(0) = 0 exactly (Hertz flux)
        f0 = kh * (d0 * np.sqrt(d0))
        return self._K.copy(), self._b.copy(), kh, d0, f0

    def make_chunk_stepper(self, state, dt: float, alpha, beta) -> Callable:
        """Compiled chunk stepper (:func:`continuum._stepper.rosenau_chunk`).

        Periodic chains: :func:`~continuum._stepper.rosenau_chunk_periodic`.  Returns
        ``chunk(state_data, nsteps) -> node_updates`` advancing the (2, N) array in place
        by ``nsteps`` splitting steps of ``dt`` (s) with drift/kick coefficients
        ``alpha``/``beta``; it keeps the active window between calls (attribute
        ``window``).
        """
        if not self._factor_cache:
            fac, z, vfac = _stepper.rosenau_factors(*self._bands)
            # (periodic chains are swept whole by the cyclic solve: no runs needed)
            runs = None if self.bc == "periodic" else _stepper.constant_runs(fac)
            self._factor_cache.extend((fac, z, vfac, runs))
        fac, z, vfac, runs = self._factor_cache
        kk, bb, kh, d0, f0 = self._kernel_arrays()
        h, bc, nl = float(self.disc.h), int(self._bc_code), int(self._nl_code)
        margin = _stepper.window_margin(fac)
        data = np.asarray(state.data)
        tau_s, tau_v, win = self._initial_window(data[0], data[1])
        y = np.zeros(data.shape[1])
        alpha = np.ascontiguousarray(alpha, dtype=float)
        beta = np.ascontiguousarray(beta, dtype=float)
        dt = float(dt)

        if self.bc == "periodic":
            def chunk(state_data: np.ndarray, nsteps: int) -> int:
                return _stepper.rosenau_chunk_periodic(
                    state_data[0], state_data[1], y, int(nsteps), dt, alpha, beta, h, nl,
                    kk, bb, kh, d0, f0, fac, z, vfac)
        else:
            def chunk(state_data: np.ndarray, nsteps: int) -> int:
                return _stepper.rosenau_chunk(
                    state_data[0], state_data[1], y, int(nsteps), dt, alpha, beta, h, bc,
                    nl, kk, bb, kh, d0, f0, fac, runs, win, margin, tau_s, tau_v)

        chunk.window = win  # type: ignore[attr-defined]
        chunk.margin = margin  # type: ignore[attr-defined]
        return chunk

    def make_monitor(self) -> Callable:
        """Compiled ``monitor(state_data) -> (energy J, momentum kg m/s)``.

        The same functional as :meth:`energy` and :meth:`momentum`
        (:func:`continuum._stepper.rosenau_monitor`).
        """
        d = self.disc
        kk, bb, kh, d0, f0 = self._kernel_arrays()
        h, bc, nl = float(d.h), int(self._bc_code), int(self._nl_code)
        w = self._face_weight.copy()
        wgrad = w * self.ell2 * d.face_mass
        mass = d.mass.copy()

        def monitor(state_data: np.ndarray) -> tuple[float, float]:
            return _stepper.rosenau_monitor(state_data[0], state_data[1], h, bc, nl, kk, bb,
                                            kh, d0, f0, mass, wgrad, w)

        return monitor

    # ------------------------------------------------------------------ energy
    def energy_density(self, state) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic energy per node (incl. the Rosenau term) and potential per face, J."""
        d = self.disc
        u, v = (np.asarray(f.data) for f in state)
        ek = 0.5 * d.h * d.mass * v * v
        dv = -self.strain(v)  # v_X at faces (ghosts as for u)
        ek_grad = 0.5 * d.h * self._face_weight * self.ell2 * d.face_mass * dv * dv
        ep = d.h * self._face_weight * self.potential(self.strain(u))
        # attribute the face part of the kinetic energy to the faces' potential array
        # would mix kinds; instead split it half to each adjacent node
        ek = ek + _faces_to_nodes(ek_grad, self.bc)
        return ek, ep

    def stable_dt(self, state=None, safety: float = 0.5) -> float:
        """Velocity-Verlet stability: dt < 2/ω_max, ω_max² = max 12 K_eff/m (s).

        The Rosenau operator bounds ω² by 12 K/m for every k (module docstring);
        K_eff includes the stiffening of the quadratic/Hertz flux at the largest strain
        of ``state`` (if given).  At ``safety`` = 0.5, Verlet's (bounded, oscillating)
        energy error is ~1e-6 for solitary waves but ~15 % for pure grid-scale content
        (ω Δt ≈ 1); it scales as Δt².
        """
        d = self.disc
        k_eff = self._K.copy()
        if state is not None and self._nl_code:
            s = np.maximum(self.strain(np.asarray(state[0].data)), 0.0)
            k_eff = k_eff + 2.0 * self._b * s
        # ω² ≤ (K/m_f) D/(1 + ℓ_h² D) with D ≤ 4/h² (the largest second difference)
        dmax = 4.0 / d.h**2
        omega2 = np.max(k_eff / d.face_mass) * dmax / (1.0 + self.ell2 * dmax)
        return float(safety * 2.0 / np.sqrt(omega2))

    def instability_hint(self, state) -> str:
        """Cause of an instability seen from the last finite ``state`` (for the error)."""
        if self._nl_code != 1:
            return ""
        s = self.strain(np.asarray(state[0].data))
        ratio = s / self.disc.delta0
        if np.min(ratio) < -1.0:
            return (f"amplitude: the strain reached {np.min(ratio):.3g} δ0; the quadratic "
                    "flux of Eq. 4, K s + K s²/(4δ0), loses its stiffness below s = -2δ0 "
                    "(Eq. 4 is ill-posed there: tension beyond the static overlap); use "
                    "nonlinearity='hertz', NesterenkoPDE or a smaller amplitude — or dt too "
                    "large")
        return ""

    @property
    def parameters(self) -> dict:
        """Run parameters for HDF5 attributes."""
        return {**super().parameters, "nonlinearity": self.nonlinearity,
                "dispersion_length2_grains2": DISPERSION_LENGTH2,
                "scheme_length2_grains2": self.ell2, "correct_h2": self.correct_h2,
                "regularisation": "Rosenau mass operator (m - d/dX m/12 d/dX) u_tt"}


def _faces_to_nodes(face_values: np.ndarray, bc: str) -> np.ndarray:
    """Split face quantities half to each adjacent node (walls: all to the one node)."""
    if bc == "periodic":
        return 0.5 * (face_values + np.roll(face_values, -1))
    out = 0.5 * (face_values[:-1] + face_values[1:])
    out[0] += 0.5 * face_values[0]
    out[-1] += 0.5 * face_values[-1]
    return out
