r"""Weakly nonlinear long-wave equation of a precompressed chain (corrected Eq. 4).

Regularisation
--------------
The paper's Eq. 4, corrected (docs/physics.md §2), reads in grain units X = x/d

.. math:: u_{tt} = \frac{K}{m}\Big(u_{XX} + \frac{1}{12}u_{XXXX}
          - \frac{1}{2\delta_0}u_X u_{XX}\Big),\qquad K = \tfrac32 k_n\delta_0^{1/2},

for Hertz's law; for any law (docs/physics.md, "Long waves on any chain") K = F'(δ0)
and the coefficient of u_X u_XX is -2b/K with b = F''(δ0)/2 (b = K/(4δ0) for Hertz,
(n-1)K/(2δ0) for the power law k δ^n),

i.e. :math:`c_0^2 (u_{xx} + (d^2/12)u_{xxxx} - (d/(2\delta_0))u_x u_{xx})` with
:math:`c_0^2 = K d^2/m`.  Linearised it has :math:`\omega^2 = c_0^2k^2(1 - k^2d^2/12)`,
negative for :math:`k > \sqrt{12}/d`: ill-posed (docs/physics.md §4).  We solve instead the
Rosenau quasi-continuum / "improved Boussinesq" form, which replaces
:math:`(c_0^2 d^2/12)u_{xxxx}` by :math:`(d^2/12)u_{xxtt}` (equal to leading order
because :math:`u_{tt} = c_0^2 u_{xx} + \dots`), written in flux form for a composite
medium:

.. math:: \Big(m - \partial_X \frac{m}{12} \partial_X\Big) u_{tt} = -\partial_X P(s, X),
          \qquad s = -u_X,\qquad P = K s + b\,s^2 .

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
            + W(s, X)\,dX,\qquad W = \tfrac12 K s^2 + \tfrac13 b\,s^3;

  the regularisation moves the dispersive energy from the (indefinite) potential into
  the (positive) kinetic energy.  A spectral cut-off would need periodic, uniform media.

P is the *dynamic* contact force (F - F0); the static force F0 (uniform by force
equilibrium, paper below Eq. 9, or growing with depth under gravity, whose weight its
gradient balances) drops out.  ``nonlinearity="full"`` replaces the quadratic P by the
full law :math:`F_{el}(\delta_0 + s) - F_0` (Hertz: :math:`k[\delta_0 + s]_+^{3/2} -
F_0`, Eq. 1) — the Rosenau quasi-continuum of the chain — for amplitude studies.
Every coefficient (m, k, δ0, ℓ²) may vary from grain to grain and contact to contact
(sections, tapers, gravity, homogenised cells: :mod:`continuum.medium`,
:mod:`continuum.cells`).

Dissipation
-----------
A dissipative law adds the viscous flux of its damping coefficient at the face's strain
rate, :math:`c(\delta_0 + s)\,s_t` (Kuwabara & Kono: :math:`kA\delta^{1/2}\delta_t`, the
long-wave viscous term of Herbold & Nesterenko, Phys. Rev. E 75 (2007) 021304), and
on-site drag the term :math:`-\beta m u_t`:

.. math:: M u_{tt} = -\partial_X\big(P + c\,s_t\big) - \beta m u_t ,

integrated by splitting (the Crank–Nicolson dissipative sub-step of
:mod:`continuum._stepper`), with the dissipated energy booked in the state's field w.

Discretisation: staggered second-order finite volumes (:mod:`continuum.medium`); the
mass operator is a constant symmetric tridiagonal matrix (m at nodes, m ℓ² at faces, m
the mean of the two nodes), factored once and solved in O(N) per evaluation.  py-pde has no
operator for this Helmholtz-type inverse, hence :mod:`continuum._kernels`.

The two-point differences add their own dispersion: linearised, the semi-discrete
relation is ω² = (K/m) D_h/(1 + ℓ² D_h) with D_h = (4/h²) sin²(kh/2) = k²(1 - k²h²/12 +
…), i.e. the continuum's with ℓ² = 1/12 replaced by (1 + h²)/12 to O(k⁴).  With
``correct_h2`` (default) the mass operator uses ℓ_h² = (1 - h²)/12 (grain units), which
cancels it: the linear dispersion is then exact to O(h⁴k⁶) (the error coefficient of
k⁶ is -h⁴/240), and at n = 1 the scheme is the discrete chain with the quadratic
contact law.  What remains is the O(h²) of the nonlinear flux, a factor ~A/δ0 smaller:
on the paper's wave over 20 d the errors are 1.5e-5, 7e-6, 2.5e-6 at n = 3, 5, 9 against
3.0e-3, 1.1e-3, 3.4e-4 uncorrected (``tests/continuum/test_boussinesq.py``).  Time
stepping adds Verlet's O(Δt²) dispersion of the opposite sign (it cancels the
uncorrected scheme's at the "magic" c Δt = h, n = 3 with the default step); use
``order=4`` for accuracy (benchmarks/continuum.py ``--accuracy``).  The fused compiled
stepper (:mod:`continuum._stepper`) solves the tridiagonal system with a twisted ("burn
at both ends") factorisation over the active window.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import Any

import numba as nb
import numpy as np
from scipy.linalg import solve_banded
from scipy.sparse import csc_matrix, diags
from scipy.sparse.linalg import splu

from theory.laws import ContactLaw

from . import _kernels as kern
from . import _stepper
from .base import ChainPDEBase
from .medium import Medium

__all__ = ["BoussinesqPDE", "DISPERSION_LENGTH2", "NONLINEARITIES", "law_curvature"]

DISPERSION_LENGTH2 = 1.0 / 12.0
"""Dispersive length² of the lattice, d²/12 (Taylor series of the second difference;
paper Eq. 4 corrected), in grains²."""

NONLINEARITIES = {"linear": 0, "quadratic": 1, "full": 2, "hertz": 2}
"""Flux choices of :class:`BoussinesqPDE` and their kernel codes (``"hertz"``: the name
the scenario files use for the full law)."""


def law_curvature(law: ContactLaw, r, k) -> np.ndarray:
    r"""F_el''(r) of ``law`` at overlaps r (m) > 0 for constants k, N/m².

    For the power-law elastic part of :class:`theory.laws.ContactLaw`,
    :math:`F'' = (n-1)F'/r` exactly (Hertz: F'/(2r), so b = F''/2 = K/(4δ0), the
    quadratic coefficient of paper Eq. 4).  Any other elastic part: a fourth-order
    central difference of the law's stiffness with step 1e-3 r (relative error ~1e-12).
    """
    r = np.asarray(r, float)
    if np.any(r <= 0):
        raise ValueError("the curvature of the contact law is taken at overlaps r > 0")
    if all(getattr(type(law), m) is getattr(ContactLaw, m) for m in ("stiffness", "elastic")):
        return (law.exponent - 1.0) * law.stiffness(r, k) / r
    e = 1e-3 * r
    st = law.stiffness
    return (8.0 * (st(r + e, k) - st(r - e, k)) - (st(r + 2 * e, k) - st(r - 2 * e, k))) / (12 * e)


class BoussinesqPDE(ChainPDEBase):
    r"""Regularised (Rosenau) form of the corrected Eq. 4 for any chain and contact law.

    .. math::
        \partial_t u &= v \\
        \Big(m - \partial_X m\ell^2\partial_X\Big)\partial_t v
            &= -\partial_X \Big(P(s) + c(\delta)\,\partial_t s\Big) - \beta m v,
            \quad s = -\partial_X u

    with X in grains, u in m, t in s, m(X) the grain mass (kg), ℓ² = 1/12 grains² (the
    cell's in a homogenised periodic section), P the dynamic flux of ``nonlinearity``
    (N): K s + b s² with K = F'(δ0) (N/m), b = F''(δ0)/2 (N/m²) of the law at the static
    overlap δ0(X) (m) — Eq. 4's expansion — or the full F_el(δ0 + s) - F0; c the law's
    damping coefficient (N·s/m) and β the drag rate (1/s) of a dissipative medium.
    See the module docstring for the regularisation and its conserved energy.

    Parameters
    ----------
    medium : Medium
        Chain; must be precompressed (δ0 > 0 at every contact).
    n : int
        Nodes per grain (odd).
    bc : {"free", "wall", "periodic"}
        Boundary condition at both ends.
    nonlinearity : {"quadratic", "full", "linear"}
        Flux P(s): Eq. 4's quadratic expansion (default), the full law (``"hertz"`` is
        accepted for it), or its linearisation K s (for dispersion and acoustic tests).
    correct_h2 : bool
        Use ℓ_h² = ℓ² - h²/12 in the mass operator (module docstring): cancels the
        O(h²) dispersion of the differences.  Attribute ``ell2`` holds the value used.
    """

    name = "eq4"
    label = "Eq. 4"
    default_integrator = "position_yoshida4"
    """Yoshida's fourth-order triple jump, drift first (docs/physics.md §9): the Rosenau
    operator bounds ω² by K/(m ℓ²) and the grid's short waves reach that bound
    (:meth:`stable_dt`), so the step is set by ω_max and a fourth-order method keeps the
    long wave's phase error O(Δt⁴) at it (relative error 9.1e-5 at Δt = T/200, §9)."""
    default_dt_safety = 0.5
    """ω_max Δt = 1.0, 64 % of Yoshida-4's limit 1.573 (docs/physics.md §9): the step at
    which a solitary wave's energy error is ~1e-6 (:meth:`stable_dt`)."""

    def __init__(self, medium: Medium, n: int = 5, *, bc: str = "free",
                 nonlinearity: str = "quadratic", correct_h2: bool = True) -> None:
        super().__init__(medium, n, bc=bc)
        if not medium.precompressed:
            raise ValueError("BoussinesqPDE needs a precompressed chain (delta0 > 0 at every "
                             "contact); use NesterenkoPDE for the sonic vacuum")
        if nonlinearity not in NONLINEARITIES:
            raise ValueError(f"nonlinearity must be one of {sorted(NONLINEARITIES)} "
                             f"(got {nonlinearity!r})")
        self.nonlinearity = "full" if nonlinearity == "hertz" else nonlinearity
        self._nl_code = NONLINEARITIES[nonlinearity]
        d = self.disc
        self._K = d.stiffness
        self._b = 0.5 * law_curvature(self.law, d.delta0, d.k)  # quadratic coefficient, N/m²
        self._f0 = d.f0
        self.correct_h2 = bool(correct_h2)
        # ℓ_h² = ℓ² - h²/12 = (r - h²)/12, r = 12 ℓ² the face's dispersion ratio (1 on a
        # monoatomic chain): the staggered second difference adds h²/12 u_XXXX, so this
        # makes the linear dispersion exact to O(h⁴ k⁶) (module docstring)
        r = d.dispersion
        self.ell2 = DISPERSION_LENGTH2 * (r - d.h**2) if self.correct_h2 \
            else DISPERSION_LENGTH2 * r
        if np.ptp(self.ell2) == 0.0:
            self.ell2 = float(self.ell2[0])
        diag, off, corner = kern.mass_operator_bands(
            d.mass, d.face_mass, d.h, self.ell2, self._bc_code
        )
        self._bands = (diag, off, corner)
        self._factor_cache: list = []

    @classmethod
    def for_chain(cls, medium: Medium, *, nodes_per_grain: int, bc: str,
                  options: Mapping[str, Any]) -> BoussinesqPDE:
        """See :meth:`ChainPDEBase.for_chain`: reads ``nonlinearity``."""
        return cls(medium, nodes_per_grain, bc=bc,
                   nonlinearity=str(options.get("nonlinearity", "quadratic")))

    @functools.cached_property
    def _lu(self):
        """The NumPy path's independent sparse LU of the same operator, built on first use.

        Only :meth:`_acceleration_numpy` reads it (the compiled steppers use their own
        factors): a run on the fused stepper does not pay ``splu`` (0.11 s at 150,000
        nodes).  Built in CSC directly.
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
        return self.law.elastic(d.delta0 + s, d.k) - self._f0

    def potential(self, s: np.ndarray) -> np.ndarray:
        """Dynamic potential energy density W(s) = ∫0^s P ds' per face, J per grain length."""
        d = self.disc
        if self._nl_code == 0:
            return 0.5 * self._K * s * s
        if self._nl_code == 1:
            return 0.5 * self._K * s * s + self._b * s**3 / 3.0
        return self.law.energy(d.delta0 + s, d.k, d.delta0) - self._f0 * s

    def _acceleration_numpy(self, u: np.ndarray) -> np.ndarray:
        rhs = self.divergence(self.flux(self.strain(u)))
        return self._lu.solve(rhs)

    def _make_acceleration_numba(self) -> Callable:
        d = self.disc
        h, bc, nl = float(d.h), int(self._bc_code), int(self._nl_code)
        kk, bb = self._K.copy(), self._b.copy()
        kh, d0 = d.k.copy(), d.delta0.copy()
        f0 = np.empty_like(d0)
        _stepper.rosenau_kernels(self.law, self._nl_code).static_forces(d0, kh, f0)
        den, cp, off, z, vfac = kern.tridiag_factor(*self._bands)
        n_faces = d.x_faces.size
        face_strain, flux_div, solve = kern.face_strain, kern.flux_divergence, kern.tridiag_solve
        elastic = self.law.make_elastic()

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
                    s[q] = elastic(d0[q] + s[q], kh[q]) - f0[q]
            rhs = np.empty(u.size)
            flux_div(s, h, bc, rhs)
            solve(den, cp, off, z, vfac, rhs, out)

        return accel

    # ------------------------------------------------------------------ dissipation
    def _dissipation_bands(self, u: np.ndarray):
        """Bands (diag, off) of A = Gᵀ diag(w c) G + β m on the nodes (N·s/m per grain²)."""
        d = self.disc
        e = self._face_weight * self.damping_coefficients(u) / d.h**2
        if self.bc == "wall":
            e[0] *= 4.0  # g = ∓2/h at a wall face (module _stepper, "Dissipation")
            e[-1] *= 4.0
        diag = self.medium.drag * d.mass + e[:-1] + e[1:]
        diag[0] -= e[0] if self.bc != "wall" else 0.0
        diag[-1] -= e[-1] if self.bc != "wall" else 0.0
        off = -e[1:-1]
        return diag, off

    def _dissipative_rate(self, u: np.ndarray, v: np.ndarray):
        diag, off = self._dissipation_bands(u)
        av = diag * v
        av[1:] += off * v[:-1]
        av[:-1] += off * v[1:]
        return -self._lu.solve(av), self.disc.h * v * av

    def dissipate(self, state_data: np.ndarray, tau: float, forward: bool = True) -> None:
        """Crank–Nicolson dissipative sub-step (M + τ/2 A) v' = (M - τ/2 A) v (NumPy).

        A = Gᵀ diag(w c) G + β m (:mod:`continuum._stepper`, "Dissipation"); the
        kinetic energy falls by h τ v̄ᵀ A v̄, booked per node into ``state_data[2]``.  A
        banded solve (scipy) independent of the compiled Thomas sweep.  The step is
        self-adjoint: ``forward`` does not matter.
        """
        u, v = state_data[0], state_data[1]
        a_diag, a_off = self._dissipation_bands(u)
        m_diag, m_off, _ = self._bands
        ht = 0.5 * tau
        rhs = (m_diag - ht * a_diag) * v
        rhs[1:] += (m_off - ht * a_off) * v[:-1]
        rhs[:-1] += (m_off - ht * a_off) * v[1:]
        ab = np.zeros((3, v.size))
        ab[0, 1:] = m_off + ht * a_off
        ab[1] = m_diag + ht * a_diag
        ab[2, :-1] = m_off + ht * a_off
        vb = 0.5 * (v + solve_banded((1, 1), ab, rhs))
        av = a_diag * vb
        av[1:] += a_off * vb[:-1]
        av[:-1] += a_off * vb[1:]
        state_data[2] += self.disc.h * tau * vb * av
        state_data[1] = 2.0 * vb - v

    # ------------------------------------------------------------------ fused stepper
    def _kernel_arrays(self) -> tuple:
        """Face coefficients (K, B, k, δ0, f0) of the compiled kernels.

        f0 with the kernels' own arithmetic (the law's compiled elastic force), so that
        P(0) = 0 exactly for the full flux.
        """
        d = self.disc
        kh, d0 = d.k.copy(), d.delta0.copy()
        f0 = np.empty_like(d0)
        _stepper.rosenau_kernels(self.law, self._nl_code).static_forces(d0, kh, f0)
        return self._K.copy(), self._b.copy(), kh, d0, f0

    def make_chunk_stepper(self, state, dt: float, alpha, beta) -> Callable:
        """Compiled chunk stepper (:func:`continuum._stepper.rosenau_kernels` of the law and flux).

        ``chunk(state_data, nsteps) -> node_updates`` advances the state array in place
        by ``nsteps`` splitting steps of ``dt`` (s) with drift/kick coefficients
        ``alpha``/``beta``; it keeps the active window between calls (attribute
        ``window``).  Periodic chains: the cyclic kernel, swept whole; a dissipative
        medium: the Strang-split kernel with the Crank–Nicolson sub-steps, swept whole.
        """
        kern_ = _stepper.rosenau_kernels(self.law, self._nl_code)
        if not self._factor_cache:
            fac, z, vfac = _stepper.rosenau_factors(*self._bands)
            # (periodic chains are swept whole by the cyclic solve: no runs needed)
            runs = None if self.bc == "periodic" else _stepper.constant_runs(fac)
            self._factor_cache.extend((fac, z, vfac, runs))
        fac, z, vfac, runs = self._factor_cache
        kk, bb, kh, d0, f0 = self._kernel_arrays()
        h, bc = float(self.disc.h), int(self._bc_code)
        margin = _stepper.window_margin(fac)
        data = np.asarray(state.data)
        tau_s, tau_v, win = self._initial_window(data[0], data[1])
        nn = data.shape[1]
        y = np.zeros(nn)
        alpha = np.ascontiguousarray(alpha, dtype=float)
        beta = np.ascontiguousarray(beta, dtype=float)
        dt = float(dt)

        if self.dissipative:
            mdiag, moff, _ = (np.ascontiguousarray(x, dtype=float) for x in self._bands)
            wface, mass = self._face_weight.copy(), self.disc.mass.copy()
            drag, p = float(self.medium.drag), np.ascontiguousarray(self.law.params(), float)
            scratch = [np.zeros(nn), np.zeros(max(nn - 1, 1)), np.zeros(nn), np.zeros(nn)]
            win[:] = [0, nn - 1]

            def chunk(state_data: np.ndarray, nsteps: int) -> int:
                return kern_.chunk_dissipative(
                    state_data[0], state_data[1], state_data[2], y, int(nsteps), dt, alpha,
                    beta, h, bc, kk, bb, kh, d0, f0, fac, runs, win, mdiag, moff, wface,
                    mass, drag, p, *scratch)
        elif self.bc == "periodic":
            def chunk(state_data: np.ndarray, nsteps: int) -> int:
                return kern_.chunk_periodic(
                    state_data[0], state_data[1], y, int(nsteps), dt, alpha, beta, h, kk,
                    bb, kh, d0, f0, fac, z, vfac)
        else:
            def chunk(state_data: np.ndarray, nsteps: int) -> int:
                return kern_.chunk(
                    state_data[0], state_data[1], y, int(nsteps), dt, alpha, beta, h, bc,
                    kk, bb, kh, d0, f0, fac, runs, win, margin, tau_s, tau_v)

        chunk.window = win  # type: ignore[attr-defined]
        chunk.margin = margin  # type: ignore[attr-defined]
        return chunk

    def make_monitor(self) -> Callable:
        """Compiled ``monitor(state_data) -> (energy J, momentum kg m/s)``.

        The same functional as :meth:`energy` and :meth:`momentum` (the law's
        ``monitor`` kernel), plus the dissipated energy Σ w of a dissipative medium.
        """
        d = self.disc
        kk, bb, kh, d0, f0 = self._kernel_arrays()
        h, bc = float(d.h), int(self._bc_code)
        w = self._face_weight.copy()
        wgrad = w * self.ell2 * d.face_mass
        mass = d.mass.copy()
        mon = _stepper.rosenau_kernels(self.law, self._nl_code).monitor
        dissipative = self.dissipative

        def monitor(state_data: np.ndarray) -> tuple[float, float]:
            e, p = mon(state_data[0], state_data[1], h, bc, kk, bb, kh, d0, f0, mass, wgrad,
                       w)
            if dissipative:
                e += float(np.sum(state_data[2]))
            return e, p

        return monitor

    # ------------------------------------------------------------------ energy
    def energy_density(self, state) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic energy per node (incl. the Rosenau term) and potential per face, J."""
        d = self.disc
        u, v = np.asarray(state[0].data), np.asarray(state[1].data)
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

        The Rosenau operator bounds ω² by K/(m ℓ²) for every k (module docstring);
        K_eff is the flux's stiffness at the largest compressive strain of ``state``
        (if given): K + 2 b s for the quadratic flux, F'(δ0 + s) for the full law.  At
        ``safety`` = 0.5, Verlet's (bounded, oscillating) energy error is ~1e-6 for
        solitary waves but ~15 % for pure grid-scale content (ω Δt ≈ 1); it scales as
        Δt².  The dissipative sub-steps are unconditionally stable.
        """
        d = self.disc
        k_eff = self._K.copy()
        if state is not None and self._nl_code:
            s = np.maximum(self.strain(np.asarray(state[0].data)), 0.0)
            if self._nl_code == 1:
                k_eff = k_eff + 2.0 * self._b * s
            else:
                k_eff = np.maximum(k_eff, self.law.stiffness(d.delta0 + s, d.k))
        # ω² ≤ (K/m_f) D/(1 + ℓ_h² D) with D ≤ 4/h² (the largest second difference)
        dmax = 4.0 / d.h**2
        omega2 = np.max(k_eff / d.face_mass * dmax / (1.0 + self.ell2 * dmax))
        return float(safety * 2.0 / np.sqrt(omega2))

    def instability_hint(self, state) -> str:
        """Cause of an instability seen from the last finite ``state`` (for the error)."""
        if self._nl_code != 1:
            return ""
        s = self.strain(np.asarray(state[0].data))
        ratio = s / self.disc.delta0
        if np.min(ratio) < -1.0:
            return (f"amplitude: the strain reached {np.min(ratio):.3g} δ0; the quadratic "
                    "flux of Eq. 4, K s + b s², loses its stiffness below s = -K/(2b) "
                    "(Eq. 4 is ill-posed there: tension beyond the static overlap); use "
                    "nonlinearity='full', NesterenkoPDE or a smaller amplitude — or dt too "
                    "large")
        return ""

    @property
    def parameters(self) -> dict:
        """Run parameters for HDF5 attributes."""
        ell2 = np.atleast_1d(self.ell2)
        return {**super().parameters, "nonlinearity": self.nonlinearity,
                "dispersion_length2_grains2": DISPERSION_LENGTH2,
                "scheme_length2_grains2": [float(ell2.min()), float(ell2.max())],
                "correct_h2": self.correct_h2,
                "regularisation": "Rosenau mass operator (m - d/dX m l^2 d/dX) u_tt"}


def _faces_to_nodes(face_values: np.ndarray, bc: str) -> np.ndarray:
    """Split face quantities half to each adjacent node (walls: all to the one node)."""
    if bc == "periodic":
        return 0.5 * (face_values + np.roll(face_values, -1))
    out = 0.5 * (face_values[:-1] + face_values[1:])
    out[0] += 0.5 * face_values[0]
    out[-1] += 0.5 * face_values[-1]
    return out
