r"""Nesterenko's strongly nonlinear long-wave equation (corrected Eq. 7), regularised.

The equation
------------
In conservative form (docs/physics.md §3), with overlap δ = δ0 - u_X (m) and X the
grain index (X = x/d for identical grains), for the contact law F = kδ^n

.. math:: m\,u_{tt} = -\partial_X F,\qquad
          F = k\Big[\delta^{n} + a\,\delta^{(n-1)/2}\,\partial_{XX}\delta^{(n+1)/2}\Big],
          \qquad a = \frac{n}{6(n+1)}

(Nesterenko, *Dynamics of Heterogeneous Materials*, 2001, §1.2: the law's
:class:`~theory.laws.LongWave` coefficients in grain units; docs/physics.md, "Long
waves for a power-law contact").  For Hertz (n = 3/2) it is the paper's Eq. 7 with
:math:`u_{xxxx}` and :math:`u_{xx}u_{xxx}` restored, :math:`F = k[\delta^{3/2} +
\tfrac1{10}\delta^{1/4}\partial_{XX}\delta^{5/4}]` (:math:`c^2 = k_n d^{5/2}/m`,
:math:`\xi = \delta/d`).  It is Hamiltonian: F is the variational derivative of
:math:`\Pi = \int k[\delta^{n+1}/(n+1) - \tfrac{a}{n+1}(\partial_X\delta^{(n+1)/2})^2]
\,dX`.  Its travelling wave is the compacton (:func:`theory.compacton_strain`; for
Hertz :math:`\xi = (5V^2/4c^2)^2\cos^4(\sqrt{10}X/5)`, speed Eq. 8).  In a homogenised
periodic section (:mod:`continuum.cells`) a is multiplied by the cell's dispersion
ratio 12ℓ².  The elastic force, its energy and (for a dissipative law) its damping come
from the contact law (:mod:`theory.laws`), whose elastic part must be k δ^n.

Regularisation: saturated dispersion (cap at the coercivity limit)
-------------------------------------------------------------------
Linearised, the dispersive term gives :math:`\omega^2 = c_0^2k^2(1 - k^2/12)`: ill-posed
(docs/physics.md §4), and Π is unbounded below.  We replace :math:`\partial_{XX}` in the
dispersive term by the operator H with Fourier multiplier :math:`-\min(k^2, C)`,
``cap`` C = 10 by default:

* H = ∂_XX exactly for :math:`|k| \le \sqrt{C} = 3.16/d`, i.e. on the whole Brillouin
  zone :math:`|k| \le \pi/d` — the long-wave equation is unchanged wherever it means
  anything; only grid-scale content beyond it is affected;
* the energy stays bounded below: :math:`\Pi \ge \tfrac{1 - aC}{n+1}\int k\,\delta^{n+1}
  \ge 0` for C ≤ 1/a = 6(n+1)/n (10 for Hertz: the largest such cap, the default; C =
  11.56 was seen to blow up), so the semi-discrete system is nonlinearly stable in the
  energy norm, and linearised about any precompression :math:`\omega^2 =
  c_0^2k^2(1 - \min(k^2,C)/12) > 0`.  For n > 1.74 the cap 1/a < π² touches the top of
  the Brillouin zone (k > 3.0 for n = 2, 2.9 for n = 2.5): the price of coercivity.

The Rosenau mass operator used for Eq. 4 (:mod:`continuum.boussinesq`) is *not* used
here: for a strongly nonlinear flux it changes the O(k²) dispersive term (its solitary
wave is sech⁴, not the cos⁴ compacton), and a Padé (1 - β∂²)⁻¹ smoothing of ∂_XX
distorts k ~ 1–2 by 20–40 % and was seen to reshape the compacton by > 40 % in 50 d;
the saturated operator keeps it within ~1 % (tests).  H needs FFTs (py-pde has no such
operator).  For ends other than periodic H is the restriction to the chain's faces of
the infinite-lattice operator (the Toeplitz matrix of :func:`saturated_kernel`, whose
entries decay as 1/j²) — symmetric, negative semi-definite, bounded by C and
independent of the chain's length.  The compiled stepper (:mod:`continuum._stepper`)
applies it with DUCC real FFTs (through rocket-fft, inside the compiled loop) over the
active window, zero-padded to a length that is a multiple of 8 with no prime factor
above 5 (:func:`continuum._stepper.fft_size`), or by a direct sum over the compressed
faces where that is cheaper: in the sonic vacuum φ(δ) = 0 wherever δ = 0, so only
compressed faces take part.  Its kernel is long-ranged by construction (docs/physics.md
§4, "Evaluating H"), so a banded or compact operator cannot replace it.

Discretisation
--------------
Staggered grid of :mod:`continuum.medium` (u, v on nodes; δ, F on faces).  The strain
s = -u_X is a staggered difference of order ``space_order``
(:func:`continuum._kernels.staggered_gradient`) and the force density is its exact
transpose applied to the face forces, so the semi-discrete system is Hamiltonian (it
conserves the discrete Π + kinetic energy) for either order:

* ``space_order=4`` (default): weights 27/24 and -1/24 over four nodes.  On the
  paper's sonic-vacuum compacton over 300 d against 11 nodes per grain: a peak
  shift of 0.02–0.05 grain at n = 3 (speed error ≤ 2e-4) — better than the second-order
  scheme at n = 11.  It reaches two nodes further per force evaluation, and ahead of a
  compacton it leaves a precursor below 1e-7 of the peak velocity within 3 grains (the
  vacuum beyond stays exactly at rest; tests).
* ``space_order=2``: two-point differences.  Their error, -(h²/24)∂[2F'δ_XX + F''δ_X²]
  for F = kδ^n, is exactly h² times the dispersive flux a k δ^{(n-1)/2}∂²δ^{(n+1)/2}
  (the chain itself is this scheme at h = d), so the dispersive coefficient is taken as
  a(1 - h²) (``correct_h2``, default; a(r - h²) at a dispersion ratio r): the O(h²) term
  then cancels, which cuts the Hertz compacton's speed error 3.4× (0.14 % → 0.04 % at
  n = 3 → 5; without it 0.48 %, 0.18 %); what remains is second order.

Sonic vacuum (δ → 0)
--------------------
δ = [δ0 - u_X]_+ (gaps carry no force, paper Eq. 1).  Every power in the conservative
form is non-negative, so nothing is NaN at δ = 0; but φ = δ^{(n-1)/2} (δ^{1/4} for
Hertz) has an infinite slope there for n < 3, which makes the dispersive force
non-Lipschitz at the edges of a wave and let grid-scale noise grow behind it when
refining the grid.  Below ``delta_floor`` = ε the factor φ is therefore continued
linearly, φ(ε)(δ/ε), and ζ = δ^{(n+1)/2} by the matching C¹ quadratic
εφ(ε)(a (δ/ε)² + 1 - a), a = (n+1)/4 (Hertz: ε^{5/4}(5/8 (δ/ε)² + 3/8)), keeping the
variational structure (energy conservation) and coercivity.  The vacuum itself (δ = 0)
stays force-free.  ε ≈ 1e-2 of the wave's peak overlap is recommended; the Hertz
compacton's speed changes by < 1e-3 between ε = 3e-3 and 3e-2 of the peak (tests).

Dissipation
-----------
A dissipative law adds the viscous flux of its damping coefficient at the face's
strain rate, c(δ) s_t (Kuwabara & Kono: k A δ^{n-1} δ_t; Herbold & Nesterenko, Phys.
Rev. E 75 (2007) 021304, the viscous long-wave equation), and drag the term -β m u_t;
the fused stepper splits them off (exact face flows, :mod:`continuum._stepper`,
"Dissipation") and books the dissipated energy in the state's field w.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numba as nb
import numpy as np
from scipy.fft import next_fast_len
from scipy.sparse import csr_matrix

from theory.laws import ContactLaw

from . import _kernels as kern
from . import _stepper
from .base import WINDOW_TOLERANCE, ChainPDEBase
from .cells import power_elastic
from .medium import Medium

__all__ = ["NesterenkoPDE", "saturated_kernel", "dispersion_coefficient", "coercivity_cap"]


def dispersion_coefficient(law: ContactLaw) -> float:
    """The dispersion a = n/(6(n+1)) of the strongly nonlinear equation, grains² (Hertz: 1/10).

    The law's :class:`~theory.laws.LongWave` dispersion in grain units (d = 1); the law's
    elastic part must be the power law k δ^n.
    """
    if not power_elastic(law):
        raise ValueError(f"the strongly nonlinear long-wave equation needs a power-law "
                         f"elastic part k delta^n (got {law.describe()})")
    return float(law.long_wave(1.0, 1.0, 1.0).dispersion)


def coercivity_cap(law: ContactLaw, ratio: float = 1.0) -> float:
    """Largest dispersion cap C keeping the regularised energy bounded below, grains⁻².

    1/(a r) = 6(n+1)/(n r) for the dispersion coefficient a of the law
    (:func:`dispersion_coefficient`) and the largest dispersion ratio r (module
    docstring): 10 for Hertz.
    """
    return 1.0 / (dispersion_coefficient(law) * float(ratio))


def saturated_kernel(n_faces: int, h: float, cap: float) -> np.ndarray:
    r"""Kernel c_j (j = 0 … n_faces-1) of the saturated second derivative, grains⁻².

    On the infinite lattice of spacing h (grains) the operator with Fourier multiplier
    :math:`\sigma(k) = -\min(k^2, C)` on the Brillouin zone :math:`|k| \le \pi/h` has

    .. math:: c_j = \frac{h}{2\pi}\int_{-\pi/h}^{\pi/h}\sigma(k)\,e^{ikjh}\,dk
              = \frac{h}{\pi}\Big[-\frac{K^2\sin aK}{a} - \frac{2K\cos aK}{a^2}
              + \frac{2\sin aK}{a^3} + \frac{C\sin aK}{a}\Big],\quad a = jh,

    with :math:`K = \min(\sqrt C, \pi/h)` (sin(jπ) = 0 removes the upper limit), and
    :math:`c_0 = (h/\pi)(-K^3/3 - C(\pi/h - K))`.  Without the cap (C → ∞) this is the
    spectral second derivative -2(-1)^j/(jh)²; with it the 1/a terms cancel and
    c_j = O(1/j²).
    """
    kk = min(np.sqrt(cap), np.pi / h)
    j = np.arange(1, n_faces)
    a = j * h
    sn, cs = np.sin(a * kk), np.cos(a * kk)
    c = np.empty(n_faces)
    c[0] = (h / np.pi) * (-(kk**3) / 3.0 - cap * (np.pi / h - kk))
    c[1:] = (h / np.pi) * ((cap - kk * kk) * sn / a - 2.0 * kk * cs / a**2 + 2.0 * sn / a**3)
    return c


class NesterenkoPDE(ChainPDEBase):
    r"""Regularised conservative Nesterenko equation (corrected paper Eq. 7) for F = k δ^n.

    .. math::
        \partial_t u &= v \\
        m\,\partial_t v &= -\partial_X\Big(F_{el}(\delta) - F_0
            + a\sqrt{k}\,\varphi(\delta)\,
              H\big[\sqrt{k}\,(\zeta(\delta) - \zeta(\delta_0))\big]
            + c(\delta)\,\partial_t s\Big) - \beta m v,
            \qquad \delta = [\delta_0 + s]_+,\ s = -\partial_X u

    with X in grains, u in m, t in s, m(X) grain mass (kg), k(X) contact constant
    (N/m^n), δ0(X) static overlap (m), F_el = kδ^n the law's elastic force and F0 its
    static value, φ = δ^{(n-1)/2}, ζ = δ^{(n+1)/2}, a = n/(6(n+1)) (× 12ℓ² in a
    homogenised cell) and H the saturated second derivative (multiplier -min(k², cap));
    c (N·s/m) the law's damping coefficient and β (1/s) the drag of a dissipative
    medium.  For uniform k, δ0 this is exactly Nesterenko's flux with ∂_XX → H (Hertz:
    a = 1/10, φ = δ^{1/4}, ζ = δ^{5/4}); subtracting the static part keeps a
    precompressed composite (or gravity-loaded) chain in equilibrium.  See the module
    docstring for the regularisation and the δ → 0 floor.

    Parameters
    ----------
    medium : Medium
        Chain, with or without precompression; its law's elastic part must be k δ^n.
    n : int
        Nodes per grain (odd).
    delta_floor : float
        ε (m): φ is continued linearly below it (module docstring).
    bc : {"free", "wall", "periodic"}
        Boundary condition at both ends.
    cap : float, optional
        C, grains⁻²: the dispersive multiplier is -min(k², C); default (and largest
        coercive value) :func:`coercivity_cap`, 10 for Hertz; at most 1.2 times it.
    space_order : {2, 4}
        Order of the staggered differences (module docstring, "Discretisation").
    correct_h2 : bool
        Second order only: dispersive coefficient a(r - h²) instead of a r, which
        cancels the O(h²) truncation error of the differences.
    """

    name = "eq7"
    label = "Eq. 7"
    default_integrator = "position_yoshida4"
    """Yoshida's fourth-order triple jump, drift first (docs/physics.md §9): the saturated
    dispersion keeps grid-scale waves at the stencil's largest frequency, which sets the
    step (:meth:`stable_dt`), and a fourth-order method keeps the wave's phase error
    O(Δt⁴) at it."""
    default_dt_safety = 0.5
    """The factor of :meth:`stable_dt`'s 0.4 × safety × h/c: stable with δ_floor ≥ 3e-3 of
    the peak overlap, energy error ~1e-6 for a compacton in a uniform chain (ω_max Δt ≈
    0.8 × safety before dispersion, below Yoshida-4's limit 1.573)."""

    def __init__(self, medium: Medium, n: int = 5, *, delta_floor: float,
                 bc: str = "free", cap: float | None = None, space_order: int = 4,
                 correct_h2: bool = True) -> None:
        super().__init__(medium, n, bc=bc)
        if space_order not in (2, 4):
            raise ValueError(f"space_order must be 2 or 4 (got {space_order!r})")
        self.space_order = int(space_order)
        if not delta_floor >= 0:
            raise ValueError(f"delta_floor must be >= 0 m (got {delta_floor})")
        d = self.disc
        a = dispersion_coefficient(self.law)
        self.exponent = float(self.law.exponent)
        limit = coercivity_cap(self.law, float(d.dispersion.max()))
        if cap is None:
            cap = limit
        if not 0 < cap <= 1.2 * limit:
            raise ValueError(f"cap must lie in (0, {1.2 * limit:.4g}] grains^-2 (1.2 times "
                             f"the coercivity limit {limit:.4g} of this law; got {cap})")
        self.delta_floor = float(delta_floor)
        self.cap = float(cap)
        self.correct_h2 = bool(correct_h2)
        # strain stencil and its transpose (module docstring, "Discretisation")
        self._grad = kern.staggered_gradient(d.x_nodes.size, d.h, self._bc_code,
                                             self.space_order)
        idx, coef = self._grad
        rows = np.repeat(np.arange(idx.shape[0]), idx.shape[1])
        self._gmat = csr_matrix((coef.ravel(), (rows, idx.ravel())),
                                shape=(idx.shape[0], d.x_nodes.size))
        # second order: dispersive coefficient a(1 - h²), since the staggered second
        # differences add a h² φ ∂²ζ (module docstring); a dispersion ratio r ≠ 1 enters
        # through √k: g = √((r - h²)/(1 - h²)) (corrected) or √r, exactly 1 for r = 1
        h = d.h
        corrected = self.correct_h2 and self.space_order == 2
        self._disp = a * (1.0 - h * h) if corrected else a
        r = d.dispersion
        g = np.sqrt((r - h * h) / (1.0 - h * h)) if corrected else np.sqrt(r)
        nf = d.x_faces.size
        if self.bc == "periodic":
            self._npad = nf
            kwave = 2 * np.pi * np.fft.rfftfreq(nf, d=d.h)
            self._mult = -np.minimum(kwave**2, self.cap)
            self._kernel = np.fft.irfft(self._mult, nf)  # circulant kernel c_j
        else:
            # restriction of the infinite-lattice operator: Toeplitz c_{|q-p|}, applied
            # by embedding in a circulant of size >= 2 nf - 1
            self._kernel = saturated_kernel(nf, d.h, self.cap)
            self._npad = next_fast_len(2 * nf)
            col = np.zeros(self._npad)
            col[:nf] = self._kernel
            col[self._npad - nf + 1:] = self._kernel[1:][::-1]
            self._mult = np.fft.rfft(col).real
        self._sqrt_k = np.sqrt(d.k) * g
        # dispersive term only on interior faces (ends: the plain law, see energy_density)
        self._disp_mask = np.ones(nf)
        if self.bc != "periodic":
            self._disp_mask[0] = self._disp_mask[-1] = 0.0
        self._f0 = d.f0
        self._zeta0 = _zeta(d.delta0, self.delta_floor, self.exponent)[0]

    @classmethod
    def for_chain(cls, medium: Medium, *, nodes_per_grain: int, bc: str,
                  options: Mapping[str, Any]) -> NesterenkoPDE:
        """See :meth:`ChainPDEBase.for_chain`.

        Reads ``delta_floor`` (a fraction of ``incident_overlap``, the incident wave's
        peak overlap in m) and ``dispersion_cap`` (capped at the law's coercivity limit).
        """
        floor = float(options.get("delta_floor", 1e-2)) * float(options["incident_overlap"])
        probe = cls(medium, nodes_per_grain, bc=bc, delta_floor=floor)
        cap = min(float(options.get("dispersion_cap", probe.cap)), probe.cap)
        if cap == probe.cap:
            return probe
        return cls(medium, nodes_per_grain, bc=bc, delta_floor=floor, cap=cap)

    # ------------------------------------------------------------------ stencils
    def strain(self, u: np.ndarray) -> np.ndarray:
        """Dynamic overlap change s = -u_X at the faces, m (order ``space_order``)."""
        return self._gmat @ np.asarray(u, dtype=float)

    def divergence(self, p: np.ndarray) -> np.ndarray:
        """Node force density -Gᵀ(w p) of face forces p (the transpose of :meth:`strain`).

        The face weights w (wall faces ½, free end faces 0) make it the exact gradient
        of the energy h Σ w_q W(s_q); in the interior it is (p_q - p_{q+1})/h at second
        order and (27(p_q - p_{q+1}) - (p_{q-1} - p_{q+2}))/(24h) at fourth.
        """
        return -(self._gmat.T @ (self._face_weight * np.asarray(p, dtype=float)))

    # ------------------------------------------------------------------ operator H
    def saturated_laplacian(self, y: np.ndarray) -> np.ndarray:
        """H y: second derivative with multiplier -min(k², cap), grains⁻² (NumPy, FFT).

        Periodic chains: the circulant with that multiplier on the chain's own
        frequencies.  Other ends: the restriction to the chain's faces of the
        infinite-lattice operator, (H y)_q = Σ_p c_{|q-p|} y_p with the kernel of
        :func:`saturated_kernel` (independent of the chain's length), evaluated as a
        zero-padded circulant product of size ≥ 2 N_faces - 1 (exact to round-off).
        """
        if self.bc == "periodic":
            return np.fft.irfft(self._mult * np.fft.rfft(y), self._npad)
        ypad = np.zeros(self._npad)
        ypad[: y.size] = y
        return np.fft.irfft(self._mult * np.fft.rfft(ypad), self._npad)[: y.size]

    def _overlaps(self, u: np.ndarray):
        d = self.disc
        delta = np.maximum(d.delta0 + self.strain(u), 0.0)
        zeta, phi = _zeta(delta, self.delta_floor, self.exponent)
        y = self._disp_mask * self._sqrt_k * (zeta - self._zeta0)
        return delta, phi, y

    def flux(self, u: np.ndarray) -> np.ndarray:
        """Conservative dynamic contact force at the faces, N (NumPy)."""
        d = self.disc
        delta, phi, y = self._overlaps(u)
        hy = self.saturated_laplacian(y)
        return (self.law.elastic(delta, d.k) - self._f0
                + self._disp * self._disp_mask * self._sqrt_k * phi * hy)

    def _acceleration_numpy(self, u: np.ndarray) -> np.ndarray:
        return self.divergence(self.flux(u)) / self.disc.mass

    def _make_acceleration_numba(self) -> Callable:
        d = self.disc
        eps = self.delta_floor
        kern_ = _stepper.nesterenko_kernels(self.law)
        k, d0, sk = d.k.copy(), d.delta0.copy(), self._sqrt_k.copy()
        f0 = np.empty_like(d0)
        kern_.static_forces(d0, k, f0)
        z0, mask = self._kernel_zeta0(), self._disp_mask.copy()
        inv_m, mult, npad = 1.0 / d.mass, self._mult.copy(), int(self._npad)
        disp, w = self._disp, self._face_weight.copy()
        idx, coef = (a.copy() for a in self._grad)
        nf, width = idx.shape
        elastic = self.law.make_elastic()
        phi_ = _stepper.power_piece(0.5 * (self.exponent - 1.0))
        ca = 0.25 * (self.exponent + 1.0)
        cb = 1.0 - ca

        @nb.njit
        def accel(u, out):
            e4 = phi_(eps)
            e54 = eps * e4
            s = np.zeros(nf)
            for q in range(nf):
                for j in range(width):
                    s[q] += coef[q, j] * u[idx[q, j]]
            ypad = np.zeros(npad)
            phi = np.empty(nf)
            for q in range(nf):
                dl = d0[q] + s[q]
                if dl < 0.0:
                    dl = 0.0
                s[q] = dl
                if dl >= eps:
                    phi[q] = phi_(dl)
                    zq = dl * phi[q]
                else:
                    r = dl / eps
                    zq, phi[q] = e54 * (ca * r * r + cb), e4 * r
                ypad[q] = mask[q] * sk[q] * (zq - z0[q])
            with nb.objmode(hy="float64[:]"):
                hy = np.fft.irfft(mult * np.fft.rfft(ypad), npad)
            out[:] = 0.0
            for q in range(nf):
                dl = s[q]
                fq = (w[q] * (elastic(dl, k[q]) - f0[q])
                      + disp * mask[q] * sk[q] * phi[q] * hy[q])
                for j in range(width):
                    out[idx[q, j]] -= coef[q, j] * fq
            for i in range(out.size):
                out[i] *= inv_m[i]

        return accel

    # ------------------------------------------------------------------ dissipation
    def _dissipative_rate(self, u: np.ndarray, v: np.ndarray):
        d = self.disc
        c = self.damping_coefficients(u)
        pv = self._face_weight * c * self.strain(v)  # viscous flux w c s_t, N
        force = -(self._gmat.T @ pv)
        drag = self.medium.drag * d.mass * v
        return (force - drag) / d.mass, d.h * (-v * force + v * drag)

    def dissipate(self, state_data: np.ndarray, tau: float, forward: bool = True) -> None:
        """Exact face-by-face dissipative flows of ``tau`` (s), in place (NumPy).

        The faces of one residue class q mod (stencil width) have disjoint stencils and
        are relaxed at once (vectorised; the compiled kernel does them one after the
        other, :mod:`continuum._stepper`, "Dissipation"), the classes in turn, ascending
        (``forward``) or descending, the drag first (forward) or last; the removed
        energy is booked into ``state_data[2]``.
        """
        d = self.disc
        u, v, wd = state_data[0], state_data[1], state_data[2]
        idx, coef = self._grad
        width = idx.shape[1]
        inv_m = 1.0 / d.mass
        delta = d.delta0 + self.strain(u)
        c = self._face_weight * self.law.damping(delta, d.k)
        # g_qᵀ M⁻¹ g_q with repeated stencil nodes (reflected ends) merged
        same = (idx[:, :, None] == idx[:, None, :]).astype(float)
        gam = np.einsum("qj,qk,qjk,qj->q", coef, coef, same, inv_m[idx])
        active = (delta > 0) & (c > 0) & (gam > 0)
        drag = self.medium.drag

        def drag_flow():
            v1 = v * np.exp(-drag * tau)
            wd[:] += 0.5 * d.h * d.mass * (v * v - v1 * v1)
            v[:] = v1

        if forward and drag > 0:
            drag_flow()
        classes = range(width) if forward else range(width - 1, -1, -1)
        for r in classes:
            q = np.flatnonzero(active & (np.arange(idx.shape[0]) % width == r))
            if not q.size:
                continue
            z = np.einsum("qj,qj->q", coef[q], v[idx[q]])
            z1 = z * np.exp(-c[q] * gam[q] * tau)
            a = (z - z1) / gam[q]
            np.add.at(v, idx[q].ravel(), -(inv_m[idx[q]] * coef[q] * a[:, None]).ravel())
            np.add.at(wd, idx[q, width // 2 - 1], 0.5 * d.h * (z * z - z1 * z1) / gam[q])
        if not forward and drag > 0:
            drag_flow()

    # ------------------------------------------------------------------ fused stepper
    def _kernel_zeta0(self) -> np.ndarray:
        """ζ(δ0) with the compiled kernels' own arithmetic (Hertz: δ·√√δ, not δ^{5/4}).

        The kernel forms y ∝ ζ(δ) − ζ(δ0); with z0 = δ0^{5/4} (1 ulp apart for ~30 % of
        δ0) a precompressed chain at rest would not be at rest (|v| ~ 4e-17 after 100
        steps); with this z0 it stays exactly at rest, as f0 = F_el(δ0) with the
        kernels' arithmetic does for the force.
        """
        out = np.empty(self.disc.delta0.size)
        _stepper.nesterenko_kernels(self.law).zeta(self.disc.delta0, self.delta_floor, out)
        return out

    def _kernel_arrays(self) -> dict:
        """Arrays of the compiled kernels (:mod:`continuum._stepper`), with scratch."""
        d = self.disc
        nf = d.x_faces.size
        k, d0 = d.k.copy(), d.delta0.copy()
        f0 = np.empty_like(d0)
        _stepper.nesterenko_kernels(self.law).static_forces(d0, k, f0)
        periodic = self.bc == "periodic"
        m_max = nf if periodic else int(_stepper.fft_size(2 * nf))
        gidx, gcoef = (x.copy() for x in self._grad)
        return {
            "gidx": gidx, "gcoef": gcoef, "w": self._face_weight.copy(),
            "k": k, "d0": d0, "f0": f0, "sk": self._sqrt_k.copy(),
            "z0": self._kernel_zeta0(), "mask": self._disp_mask.copy(),
            "c": self._kernel.copy(),
            "spec": self._mult.copy() if periodic else np.zeros(m_max // 2 + 1),
            "scratch": [np.zeros(m_max), np.zeros(m_max // 2 + 1, np.complex128),
                        np.zeros(1, np.int64), np.zeros(nf), np.zeros(nf), np.zeros(nf),
                        np.zeros(nf), np.zeros(nf), np.zeros(nf, np.int64)],
        }

    def make_chunk_stepper(self, state, dt: float, alpha, beta) -> Callable:
        """Compiled chunk stepper (:func:`continuum._stepper.nesterenko_kernels` of the law).

        ``chunk(state_data, nsteps) -> node_updates`` advances the state array in place.
        In the sonic vacuum (δ0 = 0, ends not periodic) only the active window is
        swept (exactly: outside it δ = 0 and v = 0); precompressed or periodic chains
        are swept whole (the saturated operator couples every face).  A dissipative
        medium: the Strang-split kernel with the exact face flows.
        """
        kern_ = _stepper.nesterenko_kernels(self.law)
        a = self._kernel_arrays()
        d = self.disc
        h, bc, eps = float(d.h), int(self._bc_code), float(self.delta_floor)
        inv_m = 1.0 / d.mass
        windowed = self.bc != "periodic" and self.effective.sonic_vacuum
        data = np.asarray(state.data)
        _, tau_v, win = self._initial_window(data[0], data[1])
        dl = np.maximum(d.delta0 + self.strain(data[0]), 0.0)
        tau_d = WINDOW_TOLERANCE * float(dl.max())
        if windowed:
            # at rest: v = 0 and no compressed face, to 2^-52 of the wave's values (a
            # strained gap is at rest)
            comp = dl > tau_d
            act = (np.abs(data[1]) > tau_v) | comp[:-1] | comp[1:]
            idx = np.flatnonzero(act)
            win[:] = [idx[0], idx[-1]] if idx.size else [-1, -1]
        alpha = np.ascontiguousarray(alpha, dtype=float)
        beta = np.ascontiguousarray(beta, dtype=float)
        dt = float(dt)
        sc = a["scratch"]

        margin = 1 if self.space_order == 2 else 3
        mass, no_monitor = d.mass.copy(), np.zeros(0)
        # the kernel writes the plain stencil out for the interior faces half..n-half:
        # their rows of the table must be it
        gidx = a["gidx"]
        half = gidx.shape[1] // 2
        q = np.arange(half, d.x_nodes.size - half + 1)
        if not np.array_equal(gidx[q], q[:, None] + np.arange(-half, half)[None, :]):
            raise RuntimeError("staggered_gradient: interior rows are not the plain stencil")
        args = (bc, h, a["gidx"], a["gcoef"], a["w"], a["k"], a["d0"], a["f0"], a["sk"],
                a["z0"], a["mask"], eps, self._disp, inv_m, a["c"], a["spec"], *sc, win,
                windowed, margin, tau_v, tau_d, mass)

        if self.dissipative:
            drag, p = float(self.medium.drag), np.ascontiguousarray(self.law.params(), float)

            def chunk(state_data: np.ndarray, nsteps: int) -> int:
                return kern_.chunk_dissipative(state_data[0], state_data[1], state_data[2],
                                               int(nsteps), dt, alpha, beta, *args, drag, p)
        else:
            def chunk(state_data: np.ndarray, nsteps: int) -> int:
                return kern_.chunk(state_data[0], state_data[1], int(nsteps), dt, alpha,
                                   beta, *args, no_monitor)

        chunk.window = win  # type: ignore[attr-defined]
        return chunk

    def make_monitor(self) -> Callable:
        """Compiled ``monitor(state_data) -> (energy J, momentum kg m/s)``.

        The same functional as :meth:`energy` and :meth:`momentum`: the law's chunk
        kernel run for no step, with scratch arrays of its own, evaluating it (plus the
        dissipated energy Σ w of a dissipative medium).
        """
        kern_ = _stepper.nesterenko_kernels(self.law)
        a = self._kernel_arrays()
        d = self.disc
        h, bc, eps = float(d.h), int(self._bc_code), float(self.delta_floor)
        mass, inv_m = d.mass.copy(), 1.0 / d.mass
        sc = a["scratch"]
        no_step = np.zeros(1)
        win = np.full(2, -1, np.int64)
        out = np.zeros(2)
        dissipative = self.dissipative

        def monitor(state_data: np.ndarray) -> tuple[float, float]:
            kern_.chunk(
                state_data[0], state_data[1], 0, 0.0, no_step, no_step, bc, h, a["gidx"],
                a["gcoef"], a["w"], a["k"], a["d0"], a["f0"], a["sk"], a["z0"], a["mask"],
                eps, self._disp, inv_m, a["c"], a["spec"], *sc, win, False, 0, 0.0,
                0.0, mass, out)
            e = float(out[0])
            if dissipative:
                e += float(np.sum(state_data[2]))
            return e, float(out[1])

        return monitor

    # ------------------------------------------------------------------ energy
    def energy_density(self, state) -> tuple[np.ndarray, np.ndarray]:
        r"""Kinetic energy per node and potential energy per face, J.

        Potential: :math:`h w_q [U(\delta) - U(\delta_0) - F_0 s]` (U the law's elastic
        energy, Hertz :math:`\tfrac25 k\delta^{5/2}`) plus the dispersive
        :math:`\tfrac{a}{n+1} h\, y_q (H y)_q` (w_q = face weights).
        """
        d = self.disc
        u, v = np.asarray(state[0].data), np.asarray(state[1].data)
        s = self.strain(u)
        delta, _, y = self._overlaps(u)
        elastic = self.law.energy(delta, d.k, d.delta0) - self._f0 * s
        ep = d.h * (self._face_weight * elastic
                    + (self._disp / (self.exponent + 1.0)) * y * self.saturated_laplacian(y))
        return 0.5 * d.h * d.mass * v * v, ep

    def stable_dt(self, state, safety: float = 0.5) -> float:
        """Explicit time step 0.4 ``safety`` h/c_loc (second order), 6/7 of it (fourth), s.

        ``inf`` for a state that compresses no contact (a sonic vacuum at rest, or an
        impact's velocities alone): callers take the minimum with the step of a state
        at the wave's overlap (``run`` refuses an infinite dt, naming it).

        The fourth-order stencil's largest eigenvalue is 7/6 of the second-order one
        ((27 + 1)/12 against 2, per h).  c_loc is the sound speed at the largest overlap
        of ``state`` (grains/s; the law's stiffness there); the default ``safety`` = 0.5
        was stable with δ_floor ≥ 3e-3 of the peak overlap (energy error ~1e-6 for a
        compacton in a uniform chain).  Across an interface into lighter or stiffer
        grains the wave's overlap grows beyond the initial one: there ``safety`` = 0.1
        keeps the energy error near 1e-4 (α_ρ = 5: 2e-3 at 0.5; 5e-5 at 0.1
        with n = 5, 4e-4 with n = 3).  The dissipative sub-steps are unconditionally
        stable.
        """
        d = self.disc
        delta = np.maximum(d.delta0 + self.strain(np.asarray(state[0].data)), 0.0)
        c2 = self.law.stiffness(delta.max(), d.k) / d.mass.min()
        if not np.max(c2) > 0:  # no compressed contact: no sound speed, no bound
            return math.inf
        stencil = 1.0 if self.space_order == 2 else 6.0 / 7.0
        return float(safety * stencil * 0.4 * d.h / np.sqrt(np.max(c2)))

    @property
    def parameters(self) -> dict:
        """Run parameters for HDF5 attributes."""
        return {**super().parameters, "delta_floor_m": self.delta_floor,
                "dispersion_cap_grains^-2": self.cap, "space_order": self.space_order,
                "dispersion_coefficient": self._disp,
                "regularisation": "d_XX -> multiplier -min(k^2, cap) in the dispersive term"}


def _zeta(delta: np.ndarray, eps: float, n: float) -> tuple[np.ndarray, np.ndarray]:
    """ζ(δ) = δ^{(n+1)/2} and φ = δ^{(n-1)/2} (= 2ζ'/(n+1)), continued C¹ below ``eps``."""
    delta = np.asarray(delta, dtype=float)
    q = 0.5 * (n - 1.0)
    if eps <= 0:
        phi = _phi_np(delta, q)
        return delta * phi, phi
    r = delta / eps
    small = delta < eps
    # φ(ε) as the compiled kernels form it (Hertz: √√ε), so that ζ(0) - ζ(δ0 = 0) is
    # exactly 0 in both paths: a gap carries y = 0 and is not counted as compressed
    e4 = _phi_np(np.float64(eps), q)
    ca = 0.25 * (n + 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        big = _phi_np(delta, q)
        zeta = np.where(small, eps * e4 * (ca * r * r + (1.0 - ca)), delta * big)
        phi = np.where(small, e4 * r, big)
    return zeta, phi


def _phi_np(x, q: float):
    """x^q with the products of :func:`continuum._stepper.power_piece` (√√x for q = 1/4)."""
    if q == 0.25:
        return np.sqrt(np.sqrt(x))
    if q == 0.5:
        return np.sqrt(x)
    if q == 1.0:
        return x
    return x**q
