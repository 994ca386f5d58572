r"""Lattice acoustics: the linear scattering of a solitary wave at a discrete interface.

The paper's interface theory (Eqs. 9–13, :mod:`theory.interface`) is long-wave linear
acoustics: every Fourier component of the pulse sees the same impedances, so the
quadratic wave energy transmits with 4γ/(1+γ)².  In the chain the two sections are
lattices, low-pass filters with cut-off ω_c = 2 (K/m)^{1/2} (K = n k δ0^{n−1} the
linearised contact stiffness), and a short pulse entering a slow section (γ_c0 < 1) loses
the part of its spectrum above that section's cut-off to reflection.  Here each
component scatters as a plane wave of the two semi-infinite lattices joined by the
interface contact (docs/physics.md §16.2):

* left grains n ≤ −1 (mass m_L, springs K_L), right grains n ≥ 0 (m_R, K_R), interface
  spring K_I between grains −1 and 0 (the Hertz constant of the interface contact is
  the harmonic mean 2k_L k_R/(k_L + k_R), docs/physics.md §1, at its own static overlap
  from F0 = k δ0^{3/2});
* u_n = e^{i(q_L n − ωt)} + r e^{−i(q_L n + ωt)} (n ≤ −1), u_n = t e^{i(q_R n − ωt)}
  (n ≥ 0), ω² = (4K/m) sin²(q/2) in each section; the equations of motion of grains −1
  and 0 fix r and t;
* energy flux ½ K ω sin q |amplitude|² per wave, so the energy transmission is
  T(ω) = K_R sin q_R |t|² / (K_L sin q_L) (zero above the right cut-off), and
  |r|² + T = 1.  At ω → 0 it is 4γ/(1+γ)², γ = γ_RG (paper Eq. 13), and the displacement
  transmission t → 2/(1+γ).

The incident pulse is the exact discrete solitary wave (:func:`theory.discrete_solitary_wave`;
below ε = 1e-2 its KdV limit, whose spectrum is analytic).  Its energy flux through a
contact has the spectral density S(ω) ∝ (K_L sin q_L/ω) |v̂(ω)|², v̂ the spectrum of one
grain's velocity history, |v̂(sq)| = s |q ŵ(q)| / (2 sin(q/2)) for the strain profile
w(ζ) travelling at s grains per second.  The part of S above the left cut-off (the
solitary wave is faster than sound, so a strongly nonlinear one has some) is left out of
the average.  The energy partition then keeps the structure of the paper's Table 2
(:func:`theory.table2_prediction`): the linear energy F0 D — D the net shift, the ω = 0
content — transmits with 2/(1+γ) and reflects with (γ−1)/(γ+1), the rest E − F0 D
with the pulse average τ = ∫T S dω / ∫S dω instead of 4γ/(1+γ)².

Compared with the chain (docs/physics.md §16.5, benchmarks/strong_interface.py), this
holds to a few per cent up to an incident strain/δ0 of about 2 and fails above (the
strongly nonlinear wave does not scatter like its Fourier components:
:mod:`theory.strong_interface`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ._validate import check_positive
from .solitary_family import TABLE_RANGE, SolitaryWaveFamily, precompressed_invariants

__all__ = ["lattice_energy_transmission", "pulse_transmission", "LatticeScattering",
           "lattice_acoustic_scattering"]


def _sections(alpha_rho: float, alpha_kn: float) -> tuple[float, float, float, float, float]:
    """(m_L, K_L, m_R, K_R, K_I) in units k_L = m_L = δ0_L = 1 (Hertz, n = 3/2)."""
    a_r = float(check_positive("alpha_rho", alpha_rho))
    a_k = float(check_positive("alpha_kn", alpha_kn))
    k_i = 2.0 * a_k / (1.0 + a_k)
    # K = (3/2) k δ0^{1/2} with k δ0^{3/2} = F0 = 1: K = (3/2) k^{2/3}
    return 1.0, 1.5, a_r, 1.5 * a_k ** (2.0 / 3.0), 1.5 * k_i ** (2.0 / 3.0)


def lattice_energy_transmission(omega, alpha_rho: float, alpha_kn: float):
    r"""Plane-wave energy transmission T(ω) of the precompressed Hertz lattice interface.

    Module docstring: T = K_R sin q_R |t|²/(K_L sin q_L), zero above the right section's
    cut-off, → 4γ_RG/(1+γ_RG)² as ω → 0.

    Parameters
    ----------
    omega : float or array
        Angular frequency in units of (k_L δ0_L^{1/2}/m_L)^{1/2}, in [0, ω_c^L) with
        ω_c^L = 2 (3/2)^{1/2} = √6 the left section's cut-off.
    alpha_rho, alpha_kn : float
        ρ^R/ρ^L and k_n^R/k_n^L (> 0).

    Returns
    -------
    float or ndarray
        T(ω): a float for scalar ``omega``, else an array of its shape.
    """
    m_l, k_l, m_r, k_r, k_i = _sections(alpha_rho, alpha_kn)
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    cut = 2.0 * math.sqrt(k_l / m_l)
    if np.any(~np.isfinite(w)) or np.any(w < 0) or np.any(w >= cut):
        raise ValueError(f"omega must lie in [0, {cut:.6g}) (the left section's cut-off "
                         f"2 (K_L/m_L)^(1/2)); got min {w.min()!r}, max {w.max()!r}")
    out = np.empty(w.shape)
    zero = w == 0
    g = math.sqrt(k_r * m_r / (k_l * m_l))
    out[zero] = 4.0 * g / (1.0 + g) / (1.0 + g)
    wz = w[~zero]
    q_l = 2.0 * np.arcsin(wz / cut)
    s_r = wz / (2.0 * math.sqrt(k_r / m_r))
    prop = s_r < 1.0
    q_r = np.where(prop, 2.0 * np.arcsin(np.minimum(s_r, 1.0)), 0.0)
    # above the right cut-off q_R = π + iκ, e^{iq_R} = −e^{−κ} with cosh κ = 2 s_r² − 1
    kappa = np.arccosh(np.maximum(2.0 * s_r * s_r - 1.0, 1.0))
    e_r = np.where(prop, np.exp(1j * q_r), -np.exp(-kappa))
    e_l = np.exp(1j * q_l)
    c1 = -m_l * wz * wz + k_l + k_i
    c2 = -m_r * wz * wz + k_i + k_r
    # unknowns (r, t); incident e^{i q_L n}, reflected e^{-i q_L n} at n = -1, -2
    a = np.empty(wz.shape + (2, 2), dtype=complex)
    b = np.empty(wz.shape + (2,), dtype=complex)
    a[..., 0, 0] = c1 * e_l - k_l * e_l * e_l
    a[..., 0, 1] = -k_i
    b[..., 0] = -(c1 / e_l - k_l / (e_l * e_l))
    a[..., 1, 0] = -k_i * e_l
    a[..., 1, 1] = c2 - k_r * e_r
    b[..., 1] = k_i / e_l
    t = np.linalg.solve(a, b[..., None])[..., 1, 0]
    flux = np.where(prop, k_r * np.sin(q_r), 0.0) * np.abs(t) ** 2
    out[~zero] = flux / (k_l * np.sin(q_l))
    return out if np.ndim(omega) else float(out[0])


@lru_cache(maxsize=64)
def _pulse_spectrum(eps: float) -> tuple[np.ndarray, np.ndarray]:
    """(ω, S(ω)) of the incident wave's energy flux below the left cut-off (docstring)."""
    cut = 2.0 * math.sqrt(1.5)
    if eps < TABLE_RANGE[0]:  # KdV: w = ε sech²(κζ), ŵ(q) = ε π q / (κ² sinh(π q/(2κ)))
        s = math.sqrt(1.5 * (1.0 + eps / 6.0))
        kappa = math.sqrt(eps / 2.0)
        q = np.linspace(0.0, min(cut / s * (1.0 - 1e-9), 60.0 * kappa), 4097)[1:]
        w_hat = eps * math.pi * q / (kappa * kappa * np.sinh(np.pi * q / (2.0 * kappa)))
    else:
        from .profiles import discrete_solitary_wave

        wave = discrete_solitary_wave(1.0, 1.0, 1.0, 1.0, amplitude=eps, points_per_grain=16)
        s, ppg = wave.grain_rate, wave.points_per_grain
        w = wave.overlap - 1.0
        q = 2.0 * np.pi * np.fft.rfftfreq(w.size, d=1.0 / ppg)
        keep = (q > 0) & (s * q < cut)
        q, w_hat = q[keep], np.abs(np.fft.rfft(w))[keep]
    omega = s * q
    v_hat = s * q * np.abs(w_hat) / (2.0 * np.sin(q / 2.0))
    q_l = 2.0 * np.arcsin(omega / cut)
    weight = 1.5 * np.sin(q_l) / omega * v_hat**2
    return omega, weight


def pulse_transmission(alpha_rho: float, alpha_kn: float, strain_over_delta0: float) -> float:
    """τ: the flux-weighted mean of :func:`lattice_energy_transmission` over the incident wave.

    Parameters
    ----------
    alpha_rho, alpha_kn : float
        Interface ratios (> 0).
    strain_over_delta0 : float
        Incident ε = A/δ0 (> 0, finite).
    """
    eps = float(check_positive("strain_over_delta0", strain_over_delta0))  # finite: δ0 > 0
    omega, weight = _pulse_spectrum(eps)
    t = lattice_energy_transmission(omega, alpha_rho, alpha_kn)
    return float(np.sum(t * weight) / np.sum(weight))


@dataclass(frozen=True)
class LatticeScattering:
    """Lattice-acoustic energy partition of one incident solitary wave (module docstring).

    Attributes
    ----------
    energy_transmission, energy_reflection : float
        Total energy right and left of the interface over the incident energy (sum 1).
    pulse_transmission : float
        τ, the transmission of the energy beyond the linear part.
    shift_transmission : float
        2/(1+γ_RG): transmitted over incident net shift (the linear energy's share).
    transmitted_strain_over_delta0 : float
        A_T/δ0^R of the right section's solitary wave carrying the transmitted energy
        beyond the linear part (its speed is the transmitted front's).
    speed_ratio : float
        That wave's speed over the incident one's.
    """

    energy_transmission: float
    energy_reflection: float
    pulse_transmission: float
    shift_transmission: float
    transmitted_strain_over_delta0: float
    speed_ratio: float


def lattice_acoustic_scattering(alpha_rho: float, alpha_kn: float,
                                strain_over_delta0: float) -> LatticeScattering:
    r"""Scatter the exact solitary wave of amplitude ε = A/δ0 by lattice acoustics.

    E_T/E_0 = [F0 D_0 · 2/(1+γ) + τ (E_0 − F0 D_0)]/E_0 (module docstring), E_R = E_0 − E_T,
    with E_0, D_0 the incident wave's energy and net shift
    (:func:`theory.solitary_family.precompressed_invariants`).  The transmitted front is
    taken as the right section's solitary wave whose energy beyond the linear part is
    τ (E_0 − F0 D_0) (Hertz, δ0_R = δ0_L α_kn^{-2/3}).

    Parameters
    ----------
    alpha_rho, alpha_kn : float
        ρ^R/ρ^L and k_n^R/k_n^L (> 0).
    strain_over_delta0 : float
        ε (> 0, finite).
    """
    eps = float(check_positive("strain_over_delta0", strain_over_delta0))  # finite: δ0 > 0
    a_r, a_k = float(alpha_rho), float(alpha_kn)
    g = math.sqrt(a_r) * a_k ** (1.0 / 3.0)
    tau = pulse_transmission(a_r, a_k, eps)
    inc = precompressed_invariants(eps)  # F0 = 1 in these units
    excess = inc.energy - inc.net_shift
    shift = 2.0 / (1.0 + g)
    e_t = (inc.net_shift * shift + tau * excess) / inc.energy
    right = SolitaryWaveFamily(a_r, a_k, a_k ** (-2.0 / 3.0))
    amp = right.amplitude_of("excess_energy", tau * excess)
    speed = right.invariants(amp).grain_rate / inc.grain_rate
    return LatticeScattering(e_t, 1.0 - e_t, tau, shift, amp / right.delta0, speed)
