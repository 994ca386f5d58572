r"""Linear-acoustic predictions for a solitary wave crossing a material interface.

The paper (Section 3.2) treats the interface between two precompressed sections in
the long-wave, linear-acoustic limit.  With α_ρ = ρ^R/ρ^L, α_kn = k_n^R/k_n^L and the
static force equilibrium k_n^L (δ0^L)^{3/2} = k_n^R (δ0^R)^{3/2}:

* γ_c0 = c0^R/c0^L = α_ρ^{-1/2} α_kn^{1/3}  (Eq. 9)
* γ_RG = R_G^R/R_G^L = α_ρ^{1/2} α_kn^{1/3} (Eq. 13), R_G = ρ c0
* continuity of force and particle velocity (Eq. 10, 11) gives the pressure (force,
  strain·stiffness) transmission P_Tr/P_In = 2/(1 + γ_RG^{-1}) (Eq. 12) and reflection
  P_Re/P_In = (γ_RG - 1)/(γ_RG + 1); particle velocity and displacement transmit with
  2/(1 + γ_RG) and reflect with (1 - γ_RG)/(1 + γ_RG) (Kinsler et al., *Fundamentals
  of Acoustics*, 4th ed., §6.2).
* the (quadratic) wave energy transmits with 4γ_RG/(1 + γ_RG)² and reflects with
  ((γ_RG - 1)/(γ_RG + 1))²; the two sum to 1.

Regions of the paper's Fig. 7 (Section 4): I = (γ_c0 > 1, γ_RG < 1), II = both > 1,
III = (γ_c0 < 1, γ_RG > 1), IV = both < 1.  The predicted effects are: fracture of the
transmitted wave (multipulse train) for γ_c0 > 1 and squeeze for γ_c0 < 1; an
expansive reflected wave ("overshoot", hard–soft interface) for γ_RG < 1 and a
compressive one for γ_RG > 1; no reflection at γ_RG = 1.

Note on the paper's text: Section 4 says of γ_RG > 1 that "the RSWs are expansive
waves"; Eq. 12, its own Section 3.2 and the simulations (Fig. 5b, d) show compressive
reflected waves there.  The conclusions also write "soft–hard interface, i.e. γ_c0 > 1"
where γ_RG > 1 is meant.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ._validate import check_nonnegative, check_positive

__all__ = [
    "gamma_c0",
    "gamma_rg",
    "alphas_from_gammas",
    "pressure_transmission",
    "pressure_reflection",
    "velocity_transmission",
    "velocity_reflection",
    "energy_transmission",
    "energy_reflection",
    "table2_prediction",
    "fission_parameter",
    "transmitted_soliton_count",
    "MAX_SOLITON_COUNT",
    "region",
    "InterfacePrediction",
    "predict",
    "PAPER_POINTS",
]


def _ret(x):
    x = np.asarray(x)
    return x if x.ndim else float(x)


def gamma_c0(alpha_rho, alpha_kn):
    """Sound-speed ratio γ_c0 = c0^R/c0^L = α_ρ^{-1/2} α_kn^{1/3} (paper Eq. 9), dimensionless."""
    a_r = check_positive("alpha_rho", alpha_rho)
    a_k = check_positive("alpha_kn", alpha_kn)
    return _ret(a_r**-0.5 * np.cbrt(a_k))


def gamma_rg(alpha_rho, alpha_kn):
    """Impedance ratio γ_RG = R_G^R/R_G^L = α_ρ^{1/2} α_kn^{1/3} (paper Eq. 13), dimensionless."""
    a_r = check_positive("alpha_rho", alpha_rho)
    a_k = check_positive("alpha_kn", alpha_kn)
    return _ret(a_r**0.5 * np.cbrt(a_k))


def alphas_from_gammas(gamma_c0_, gamma_rg_):
    """Invert Eqs. 9 and 13: α_ρ = γ_RG/γ_c0 and α_kn = (γ_c0 γ_RG)^{3/2}."""
    gc = check_positive("gamma_c0", gamma_c0_)
    gr = check_positive("gamma_rg", gamma_rg_)
    return _ret(gr / gc), _ret((gc * gr) ** 1.5)


def pressure_transmission(gamma_rg_):
    """Transmitted/incident pressure (contact-force) amplitude, 2/(1 + γ_RG^{-1}) (Eq. 12)."""
    g = check_positive("gamma_rg", gamma_rg_)
    return _ret(2.0 / (1.0 + 1.0 / g))


def pressure_reflection(gamma_rg_):
    """Reflected/incident pressure amplitude, (γ_RG - 1)/(γ_RG + 1) (from Eq. 11a and 12)."""
    g = check_positive("gamma_rg", gamma_rg_)
    return _ret((g - 1.0) / (g + 1.0))


def velocity_transmission(gamma_rg_):
    """Transmitted/incident particle-velocity (and displacement) amplitude, 2/(1 + γ_RG)."""
    g = check_positive("gamma_rg", gamma_rg_)
    return _ret(2.0 / (1.0 + g))


def velocity_reflection(gamma_rg_):
    """Reflected/incident particle-velocity amplitude, (1 - γ_RG)/(1 + γ_RG)."""
    g = check_positive("gamma_rg", gamma_rg_)
    return _ret((1.0 - g) / (1.0 + g))


def energy_transmission(gamma_rg_):
    """Transmitted fraction of the (quadratic) wave energy, 4γ_RG/(1 + γ_RG)²."""
    g = check_positive("gamma_rg", gamma_rg_)
    return _ret(4.0 * g / (1.0 + g) / (1.0 + g))  # not (1 + g)², which overflows at 1e155


def energy_reflection(gamma_rg_):
    """Reflected fraction of the (quadratic) wave energy, ((γ_RG - 1)/(γ_RG + 1))²."""
    g = check_positive("gamma_rg", gamma_rg_)
    return _ret(((g - 1.0) / (g + 1.0)) ** 2)


def table2_prediction(gamma_rg_, ek_in, ep_linear_in, ep_quadratic_in) -> dict[str, float]:
    r"""Linear-acoustic prediction of the paper's Table 2 energy ratios.

    Under precompression the wave's potential energy (contact energy minus the static
    energy of the same contacts, docs/physics.md §6) splits into a linear part
    F0 Σ(δ_j - δ0) = F0 × (net displacement across the wave), which transmits and
    reflects like the displacement (2/(1+γ_RG), (γ_RG-1)/(γ_RG+1) counted as
    compression), and a quadratic part which, like the kinetic energy, transmits with
    4γ_RG/(1+γ_RG)² and reflects with ((γ_RG-1)/(γ_RG+1))².  Hence

    .. math::
        \frac{E^p_{Tr}}{E^p_{In}} = \frac{L\,\tfrac{2}{1+\gamma} + Q\,T_E}{L+Q},\qquad
        \frac{E^t_{Tr}}{E^t_{In}} = \frac{L\,\tfrac{2}{1+\gamma} + (Q+K)\,T_E}{L+Q+K}

    with K, L, Q the incident kinetic, linear and quadratic potential energies.

    Parameters
    ----------
    gamma_rg_ : float
        Impedance ratio γ_RG.
    ek_in : float
        Incident kinetic energy K, J (>= 0).
    ep_linear_in : float
        Incident linear potential energy L = F0 Σ(δ_j - δ0), J.
    ep_quadratic_in : float
        Incident potential energy minus its linear part, Q, J.

    Returns
    -------
    dict
        Keys ``Ek_tr, Ek_re, Ep_tr, Ep_re, Et_tr, Et_re``.
    """
    g = float(check_positive("gamma_rg", gamma_rg_))
    k = float(check_nonnegative("ek_in", ek_in))
    lin = float(ep_linear_in)
    q = float(ep_quadratic_in)
    if k + lin + q == 0 or lin + q == 0:
        raise ValueError("incident energies must not all vanish (got zero total)")
    te, re = float(energy_transmission(g)), float(energy_reflection(g))
    td, rd = 2.0 / (1.0 + g), (g - 1.0) / (g + 1.0)
    ep = lin + q
    et = k + ep
    return {
        "Ek_tr": te,
        "Ek_re": re,
        "Ep_tr": (lin * td + q * te) / ep,
        "Ep_re": (lin * rd + q * re) / ep,
        "Et_tr": (lin * td + (q + k) * te) / et,
        "Et_re": (lin * rd + (q + k) * re) / et,
    }


def fission_parameter(alpha_rho, alpha_kn):
    r"""Weakly nonlinear fission parameter q = γ_c0 √(2γ_RG/(1+γ_RG)) of the transmitted pulse.

    A KdV solitary wave of corrected Eq. 4 has width ℓ with ℓ² (ξ_max/ξ0) = 2 d²
    (``theory.kdv_soliton_width``: ℓ² = 2δ0 d/ξ_max), the same in both sections.  The
    transmitted pulse keeps the incident duration, so its width in grains grows by γ_c0
    (Eq. 9), and its amplitude relative to the local precompression grows by the force
    transmission 2γ_RG/(1+γ_RG) (Eq. 12; F0 is the same on both sides).  Hence
    ℓ'²A'/(ℓ²A) = q².  A sech² initial pulse of KdV with that ratio is a Pöschl–Teller
    potential −λ(λ+1) sech² with λ(λ+1) = 2q², which binds ⌈λ⌉ solitons (Drazin &
    Johnson, *Solitons: an Introduction*, CUP 1989, §3.5): q > 1 → a train (the paper's
    "fracture"), q < 1 → one soliton and a dispersive tail ("squeeze").

    The paper (Section 3.2, Fig. 7) uses γ_c0 = 1 as the boundary; it ignores the
    amplitude change at the interface, which moves the boundary to q = 1 for γ_RG ≠ 1.
    """
    gc = np.asarray(gamma_c0(alpha_rho, alpha_kn))
    gr = np.asarray(gamma_rg(alpha_rho, alpha_kn))
    return _ret(gc * np.sqrt(2.0 * gr / (1.0 + gr)))


MAX_SOLITON_COUNT = 2**53
"""Largest λ for which :func:`transmitted_soliton_count` is exact: beyond 2^53 the double
λ no longer determines ⌈λ⌉ (its spacing exceeds 1)."""


def transmitted_soliton_count(alpha_rho, alpha_kn):
    """Number of solitons the transmitted pulse fissions into, ⌈λ⌉ with λ(λ+1) = 2q².

    From the KdV scattering problem of a sech² pulse (see :func:`fission_parameter`);
    q = 1 gives exactly one (λ = 1), and any q > 0 binds at least one (the ground state
    of a sech² well exists for every λ > 0).  Weakly nonlinear, long-wave estimate.
    λ = 2q²/((1 + √(1 + 8q²))/2) is evaluated without cancellation (small q) or overflow
    (q up to the largest double).

    Raises
    ------
    ValueError
        Naming ``alpha_rho`` and ``alpha_kn`` when λ ≥ :data:`MAX_SOLITON_COUNT`
        (2^53, q ≳ 6.4e15, e.g. α_ρ ≲ 1e-31 at α_kn = 1): a float λ no longer fixes the
        integer count (and the long-wave estimate has long lost its meaning).
    """
    q = np.asarray(fission_parameter(alpha_rho, alpha_kn), dtype=float)
    root = np.hypot(1.0, np.sqrt(8.0) * q)  # √(1 + 8q²), no overflow of q²
    lam = 2.0 * q * (q / (0.5 * (1.0 + root)))  # = (√(1 + 8q²) - 1)/2
    if np.any(lam >= MAX_SOLITON_COUNT):
        worst = float(np.max(lam))
        raise ValueError(
            f"alpha_rho = {_values(alpha_rho)}, alpha_kn = {_values(alpha_kn)}: the "
            f"transmitted pulse would fission into about {worst:.3g} solitons (fission "
            f"parameter q = {float(np.max(q)):.3g}), a count not representable exactly; "
            f"allowed: ratios with λ < 2**53 (q below about 6.4e15), far beyond any chain")
    # a bound state exists for every n < λ; round off λ = 1 + 1e-15 at q = 1 exactly
    out = np.maximum(np.ceil(lam - 1e-9), 1.0).astype(np.int64)
    return out if out.ndim else int(out)


def _values(x) -> str:
    arr = np.asarray(x, dtype=float)
    return repr(float(arr)) if arr.ndim == 0 else f"array (min {arr.min()!r}, max {arr.max()!r})"


def _side(x: float, tol: float) -> int:
    if abs(np.log(x)) <= tol:
        return 0
    return 1 if x > 1 else -1


def region(gamma_c0_: float, gamma_rg_: float, *, tol: float = 1e-9) -> str:
    """Region of the paper's Fig. 7 phase diagram.

    Returns ``"I"`` (γ_c0 > 1, γ_RG < 1), ``"II"`` (both > 1), ``"III"``
    (γ_c0 < 1, γ_RG > 1) or ``"IV"`` (both < 1) as the paper's Section 4 defines them.
    A point within ``tol`` (in |ln γ|) of a boundary line returns ``"boundary
    gamma_c0=1"``, ``"boundary gamma_RG=1"`` or ``"monodisperse"`` (both lines).
    """
    sc = _side(float(check_positive("gamma_c0", gamma_c0_)), tol)
    sr = _side(float(check_positive("gamma_rg", gamma_rg_)), tol)
    if sc == 0 and sr == 0:
        return "monodisperse"
    if sc == 0:
        return "boundary gamma_c0=1"
    if sr == 0:
        return "boundary gamma_RG=1"
    return {(1, -1): "I", (1, 1): "II", (-1, 1): "III", (-1, -1): "IV"}[(sc, sr)]


@dataclass(frozen=True)
class InterfacePrediction:
    """All linear-acoustic predictions for one interface (see module docstring)."""

    alpha_rho: float
    alpha_kn: float
    gamma_c0: float
    gamma_RG: float
    pressure_transmission: float
    pressure_reflection: float
    velocity_transmission: float
    velocity_reflection: float
    energy_transmission: float
    energy_reflection: float
    region: str
    fission_parameter: float
    transmitted_solitons: int
    transmitted_effect: str
    """Fracture or squeeze of the transmitted wave by the fission parameter q
    (:func:`fission_parameter`), consistent with ``transmitted_solitons``; the paper's
    own boundary γ_c0 = 1 (which ignores the amplitude change at the interface) is
    ``region``'s."""
    reflected_effect: str
    delta0_ratio: float
    """δ0^R/δ0^L = α_kn^{-2/3} from force equilibrium (paper below Eq. 9)."""

    def to_dict(self) -> dict:
        """Plain dict (JSON-serialisable)."""
        return asdict(self)


def predict(alpha_rho: float, alpha_kn: float, *, tol: float = 1e-9) -> InterfacePrediction:
    """Evaluate every linear-acoustic prediction for the ratios (α_ρ, α_kn).

    Parameters
    ----------
    alpha_rho : float
        Density ratio ρ^R/ρ^L (> 0).
    alpha_kn : float
        Contact-stiffness ratio k_n^R/k_n^L (> 0).
    tol : float
        Tolerance in |ln γ| for declaring a point on a boundary line.
    """
    gc = float(gamma_c0(alpha_rho, alpha_kn))
    gr = float(gamma_rg(alpha_rho, alpha_kn))
    q = float(fission_parameter(alpha_rho, alpha_kn))
    count = int(transmitted_soliton_count(alpha_rho, alpha_kn))
    sq, sr = _side(q, tol), _side(gr, tol)
    trans = {1: f"fracture (a transmitted train of {count} solitary waves: q = {q:.3g} > 1)",
             -1: f"squeeze (one transmitted solitary wave and an oscillatory tail: q = "
                 f"{q:.3g} < 1)",
             0: "on the fission boundary q = 1 (one transmitted solitary wave)"}[sq]
    refl = {-1: "overshoot: expansive reflected wave", 1: "compressive reflected wave",
            0: "no reflection (total transmission)"}[sr]
    return InterfacePrediction(
        alpha_rho=float(alpha_rho),
        alpha_kn=float(alpha_kn),
        gamma_c0=gc,
        gamma_RG=gr,
        pressure_transmission=float(pressure_transmission(gr)),
        pressure_reflection=float(pressure_reflection(gr)),
        velocity_transmission=float(velocity_transmission(gr)),
        velocity_reflection=float(velocity_reflection(gr)),
        energy_transmission=float(energy_transmission(gr)),
        energy_reflection=float(energy_reflection(gr)),
        region=region(gc, gr, tol=tol),
        fission_parameter=q,
        transmitted_solitons=count,
        transmitted_effect=trans,
        reflected_effect=refl,
        delta0_ratio=float(alpha_kn) ** (-2.0 / 3.0),
    )


def _point(gc: float, gr: float) -> tuple[float, float]:
    a_r, a_k = alphas_from_gammas(gc, gr)
    return float(a_r), float(a_k)


PAPER_POINTS: dict[str, tuple[float, float]] = {
    "a": (0.2, 1.0),
    "b": (5.0, 1.0),
    "c": (1.0, 0.2),
    "d": (1.0, 5.0),
    "M": _point(1.0, 0.5),
    "N": _point(1.0, 2.0),
    "P": _point(0.5, 1.0),
    "Q": _point(2.0, 1.0),
}
"""(α_ρ, α_kn) of the paper's named points: a–d of Fig. 5, M, N, P, Q of Fig. 8 / Table 2
(given there as (γ_c0, γ_RG) = (1, 0.5), (1, 2), (0.5, 1), (2, 1))."""
