r"""Strongly nonlinear interface theory: the solitary wave as a quasi-particle.

A solitary wave reaching the interface of two sections of a Hertz chain (ratios
α_ρ = ρ^R/ρ^L, α_kn = k_n^R/k_n^L, equal diameters) leaves it as solitary waves of the
two sections.  When the waves are strongly nonlinear (the sonic vacuum, δ0 = 0, or an
incident strain well above δ0) this module predicts them from the two conservation laws
of the chain alone (docs/physics.md §16):

* **energy** E and **momentum** P = Σ m v_i are conserved (paper Eq. 2 is Hamiltonian
  and translation invariant);
* every outgoing wave is the exact discrete solitary wave of its own section, so its E
  and P are tied by that section's family (:class:`theory.solitary_family.SolitaryWaveFamily`;
  in the sonic vacuum E = P²/(2M), M = (p̂²/2ê) m = 1.304 m for Hertz, independent of k);
* **a collision**: the incident wave (E, P) becomes a transmitted wave (E_T, P_T) and a
  wave of the left section with the rest, E_L(|P − P_T|) = E − E_R(P_T).  This has one
  root besides the trivial P_T = 0 whenever E_R'(0) < E_L'(P) (always in the sonic
  vacuum).  P − P_T < 0: the left wave is the reflected, left-going solitary wave
  (compressive; light → heavy).  In the sonic vacuum the collision is the elastic one of
  two particles of masses M_L, M_R: E_T/E = 4α_ρ/(1+α_ρ)², P_T/P = 2α_ρ/(1+α_ρ) — the
  quasi-particle model of Tichler, Gómez, Upadhyaya, Campman, Nesterenko & Vitelli,
  PRL 111, 048001 (2013), here with the exact discrete wave's own E(P);
* **trains** (closure derived here, docs/physics.md §16.3): P − P_T > 0 (heavy → light)
  leaves a right-going wave in the left section, which collides with the interface
  again.  Repeating the collision gives the transmitted train (in the sonic vacuum the
  energies E_T (1−T)^{j−1}, T = 4α_ρ/(1+α_ρ)², summing to the whole incident energy;
  the "anomalous" heavy → light behaviour of Nesterenko, Daraio, Herbold & Jin,
  PRL 95, 158702 (2005), and the trains of Sen et al., Phys. Rep. 462, 21 (2008), §6).
  The leading (first) transmitted wave is the largest and fastest: its speed is the
  transmitted front's.  Under precompression a left wave too weak for another collision
  (no root) scatters by lattice acoustics (:mod:`theory.lattice_interface`) at its own
  amplitude; its energy is reported as ``remainder_energy``.

What the quasi-particle picture leaves out (docs/physics.md §16.5): the
grains at the interface keep a slow recoil that carries momentum (up to −0.16 P of the
incident at α_ρ = 4) but almost no energy, and linear (acoustic) waves under
precompression.  Energy and momentum conservation with solitary waves alone cannot see
them: light → heavy in the sonic vacuum it gives E_T = 4α_ρ/(1+α_ρ)² whatever α_kn,
where the chain transmits up to 0.08 more.

:func:`predict_strong` chooses the theory by the incident amplitude: the quasi-particle
theory from :data:`STRONG_THRESHOLD` (and in the sonic vacuum), lattice acoustics below.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from ._validate import check_positive, check_range
from .lattice_interface import lattice_acoustic_scattering
from .solitary_family import SolitaryWaveFamily

__all__ = ["STRONG_THRESHOLD", "THEORIES", "OutgoingWave", "StrongInterfacePrediction",
           "quasi_particle_scattering", "predict_strong"]

STRONG_THRESHOLD = 2.6
"""Incident strain/δ0 from which :func:`predict_strong` uses the quasi-particle theory.

The crossover (2.64, rounded) of the two theories' median errors against the discrete
chain on interfaces off the validity map's grid (docs/physics.md §16.4;
benchmarks/strong_interface.py prints it): lattice acoustics is the better one below it,
the quasi-particle theory above."""

THEORIES = ("auto", "quasi-particle", "lattice acoustics")
"""Values of :func:`predict_strong`'s ``theory``."""

MAX_COLLISIONS = 200
"""Most collisions of a train (the sonic vacuum's left wave keeps ((1−α)/(1+α))² of its
energy per collision: 200 reach 1e-12 down to α_ρ = 0.07)."""
TRAIN_TOL = 1e-12
"""A train ends when the left section's right-going wave holds less than this fraction of
the incident energy; the rest joins the transmitted energy (sonic vacuum: the train's
geometric tail) or scatters by lattice acoustics (precompressed)."""


@dataclass(frozen=True)
class OutgoingWave:
    """One solitary wave leaving the interface (quantities over the incident wave's).

    Attributes
    ----------
    side : str
        ``"right"`` (transmitted) or ``"left"`` (reflected).
    energy, momentum : float
        E/E_in and P/P_in (momentum signed: negative is left-going).
    strain_over_delta0 : float
        Amplitude over its own section's δ0 (inf in the sonic vacuum).
    amplitude_ratio : float
        A/A_in, peak dynamic overlaps.
    speed_ratio : float
        V/V_in.
    """

    side: str
    energy: float
    momentum: float
    strain_over_delta0: float
    amplitude_ratio: float
    speed_ratio: float


@dataclass(frozen=True)
class StrongInterfacePrediction:
    """What :func:`predict_strong` predicts for one interface and amplitude.

    Attributes
    ----------
    alpha_rho, alpha_kn, strain_over_delta0, exponent : float
        The inputs (strain_over_delta0 = inf: the sonic vacuum).
    theory : str
        ``"quasi-particle"`` or ``"lattice acoustics"``: the theory that gave the numbers.
    regime : str
        ``"strongly nonlinear"`` or ``"weakly nonlinear"`` (:data:`STRONG_THRESHOLD`).
    energy_transmission, energy_reflection : float
        Total energy right and left of the interface over the incident energy (the paper's
        Table-2 E_T and E_R, total; they sum to 1).
    speed_ratio : float
        Speed of the leading transmitted wave (the transmitted front) over the incident
        wave's; the incident speed is the exact discrete wave's
        (:func:`theory.discrete_solitary_wave`).
    transmitted_count : int
        Solitary waves in the transmitted train (0 for lattice acoustics).
    waves : tuple of OutgoingWave
        The quasi-particle theory's solitary waves, in the order they leave (empty for
        lattice acoustics).
    remainder_energy, remainder_momentum : float
        Energy and momentum (over the incident's) of the left section's right-going wave
        that was scattered by lattice acoustics instead (0 when none).
    """

    alpha_rho: float
    alpha_kn: float
    strain_over_delta0: float
    exponent: float
    theory: str
    regime: str
    energy_transmission: float
    energy_reflection: float
    speed_ratio: float
    transmitted_count: int
    waves: tuple[OutgoingWave, ...] = ()
    remainder_energy: float = 0.0
    remainder_momentum: float = 0.0

    def to_dict(self) -> dict:
        """Plain dict (JSON-serialisable but for inf in the sonic vacuum)."""
        return asdict(self)


def _sections(alpha_rho: float, alpha_kn: float, eps: float, n: float):
    """Left and right families in units k_L = m_L = 1, δ0_L = 1 (or 0), and A_in."""
    if math.isinf(eps):
        return SolitaryWaveFamily(1.0, 1.0, 0.0, n), SolitaryWaveFamily(
            alpha_rho, alpha_kn, 0.0, n), 1.0
    # force balance k δ0^n equal on both sides: δ0_R = δ0_L α_kn^{-1/n}
    return SolitaryWaveFamily(1.0, 1.0, 1.0, n), SolitaryWaveFamily(
        alpha_rho, alpha_kn, alpha_kn ** (-1.0 / n), n), eps


def _energy_of_momentum(fam: SolitaryWaveFamily, p: float) -> float:
    return fam.invariants(fam.amplitude_of("momentum", p)).energy if p > 0 else 0.0


def _collide(energy: float, momentum: float, left: SolitaryWaveFamily,
             right: SolitaryWaveFamily) -> float | None:
    """The non-trivial transmitted momentum P_T of one collision, or None (module docstring).

    Solves E_R(P_T) + E_L(|P − P_T|) = E for P_T > 0.  The left side is convex in P_T
    with the trivial root at 0, so a second root exists iff its minimum over
    (0, P_max] is negative, P_max the momentum of a right wave holding all of E.
    """
    from scipy.optimize import brentq, minimize_scalar

    if left.delta0 == 0 and right.delta0 == 0:  # E = P²/(2M): the elastic collision
        return 2.0 * right.mass / (left.mass + right.mass) * momentum
    p_max = right.invariants(right.amplitude_of("energy", energy)).momentum

    def f(pt: float) -> float:
        return _energy_of_momentum(right, pt) + _energy_of_momentum(left, abs(momentum - pt)) \
            - energy

    tol = 1e-12 * energy
    if abs(f(p_max)) <= tol:  # e.g. identical sections: everything transmits
        return p_max
    low = minimize_scalar(f, bounds=(0.0, p_max), method="bounded",
                          options={"xatol": 1e-10 * p_max})
    if not low.fun < -tol:
        return None
    return brentq(f, float(low.x), p_max, xtol=1e-14 * p_max, rtol=1e-15)


def quasi_particle_scattering(alpha_rho: float, alpha_kn: float, strain_over_delta0: float,
                              *, exponent: float = 1.5) -> StrongInterfacePrediction:
    """Scatter the incident solitary wave by collisions of quasi-particles (module docstring).

    Parameters
    ----------
    alpha_rho, alpha_kn : float
        ρ^R/ρ^L and k_n^R/k_n^L (> 0); equal grain diameters.
    strain_over_delta0 : float
        Incident A/δ0 (> 0; ``math.inf``: the sonic vacuum, δ0 = 0).
    exponent : float
        n of the contact law F = k r^n, in (1, 10]; n ≠ 3/2 only in the sonic vacuum.

    Returns
    -------
    StrongInterfacePrediction
        With ``theory = "quasi-particle"`` (or ``"lattice acoustics"`` if not even the first
        collision has a solitary-wave solution: then the whole wave is scattered that way).
    """
    a_r = float(check_positive("alpha_rho", alpha_rho))
    a_k = float(check_positive("alpha_kn", alpha_kn))
    eps = _check_amplitude(strain_over_delta0, exponent)
    n = float(exponent)
    left, right, a_in = _sections(a_r, a_k, eps, n)
    inc = left.invariants(a_in)
    e0, p0 = inc.energy, inc.momentum
    waves: list[OutgoingWave] = []
    energy, momentum = e0, p0

    def wave(fam: SolitaryWaveFamily, side: str, e: float, p: float) -> OutgoingWave:
        amp = fam.amplitude_of("momentum", abs(p))
        sol = fam.invariants(amp)
        return OutgoingWave(side, e / e0, p / p0, amp / fam.delta0 if fam.delta0 else math.inf,
                            amp / a_in, sol.grain_rate / inc.grain_rate)

    for _ in range(MAX_COLLISIONS):
        p_t = _collide(energy, momentum, left, right)
        if p_t is None:
            break
        e_t = min(_energy_of_momentum(right, p_t), energy)
        waves.append(wave(right, "right", e_t, p_t))
        energy, momentum = energy - e_t, momentum - p_t
        if momentum <= 0:  # left-going: the reflected wave, and the scattering is over
            if energy > TRAIN_TOL * e0:
                waves.append(wave(left, "left", energy, momentum))
            energy = momentum = 0.0
            break
        if energy <= TRAIN_TOL * e0:
            break
    if not waves:
        lat = lattice_acoustic_scattering(a_r, a_k, eps)
        return StrongInterfacePrediction(
            a_r, a_k, eps, n, "lattice acoustics", _regime(eps), lat.energy_transmission,
            lat.energy_reflection, lat.speed_ratio, 0, (), 1.0, 1.0)
    e_tr = sum(w.energy for w in waves if w.side == "right")
    rest, rest_p = energy / e0, momentum / p0
    if rest > TRAIN_TOL and left.delta0 > 0:  # too weak to collide: lattice acoustics
        e_tr += rest * lattice_acoustic_scattering(
            a_r, a_k, left.amplitude_of("momentum", momentum) / left.delta0
        ).energy_transmission
    else:  # the train's tail (sonic vacuum: geometric) transmits too
        e_tr += rest
    lead = next(w for w in waves if w.side == "right")
    return StrongInterfacePrediction(
        a_r, a_k, eps, n, "quasi-particle", _regime(eps), e_tr, 1.0 - e_tr, lead.speed_ratio,
        sum(w.side == "right" for w in waves), tuple(waves), rest, rest_p)


def _check_amplitude(strain_over_delta0, exponent) -> float:
    eps = float(strain_over_delta0)
    if not (eps > 0):  # NaN too
        raise ValueError(f"strain_over_delta0 must be > 0 (got {strain_over_delta0!r}); "
                         "allowed range: (0, inf], inf for the sonic vacuum (delta0 = 0)")
    n = float(check_range("exponent", exponent, 1.0, 10.0, closed=(False, True)))
    if n != 1.5 and not math.isinf(eps):
        raise ValueError(f"exponent = {n:g} needs strain_over_delta0 = inf (the sonic "
                         "vacuum): precompressed waves are known for Hertz (1.5) only")
    return eps


def _regime(eps: float) -> str:
    return "strongly nonlinear" if eps >= STRONG_THRESHOLD else "weakly nonlinear"


def predict_strong(alpha_rho: float, alpha_kn: float, strain_over_delta0: float, *,
                   exponent: float = 1.5, theory: str = "auto") -> StrongInterfacePrediction:
    r"""Energy partition and transmitted speed for a solitary wave at an interface.

    ``theory = "auto"`` uses the quasi-particle theory (:func:`quasi_particle_scattering`)
    for an incident strain/δ0 ≥ :data:`STRONG_THRESHOLD` and in the sonic vacuum, and
    lattice acoustics (:func:`theory.lattice_interface.lattice_acoustic_scattering`)
    below; the answer names the theory that gave it.

    Parameters
    ----------
    alpha_rho, alpha_kn : float
        ρ^R/ρ^L and k_n^R/k_n^L (> 0), equal grain diameters.
    strain_over_delta0 : float
        Incident A/δ0: the exact discrete solitary wave's peak dynamic overlap over the
        left section's static overlap (the validity map's "incident strain / δ0"); > 0,
        ``math.inf`` for the sonic vacuum.
    exponent : float
        n of the contact law (3/2: Hertz); n ≠ 3/2 only in the sonic vacuum.
    theory : str
        One of :data:`THEORIES`.

    Returns
    -------
    StrongInterfacePrediction
    """
    if theory not in THEORIES:
        raise ValueError(f"theory must be one of {THEORIES} (got {theory!r})")
    eps = _check_amplitude(strain_over_delta0, exponent)
    a_r = float(check_positive("alpha_rho", alpha_rho))
    a_k = float(check_positive("alpha_kn", alpha_kn))
    if theory == "auto":
        theory = "quasi-particle" if eps >= STRONG_THRESHOLD else "lattice acoustics"
    if theory == "quasi-particle":
        return quasi_particle_scattering(a_r, a_k, eps, exponent=exponent)
    if math.isinf(eps):
        raise ValueError("theory = 'lattice acoustics' needs a finite strain_over_delta0 "
                         "(the sonic vacuum has no sound: use 'quasi-particle' or 'auto')")
    lat = lattice_acoustic_scattering(a_r, a_k, eps)
    return StrongInterfacePrediction(a_r, a_k, eps, float(exponent), "lattice acoustics",
                                     _regime(eps), lat.energy_transmission,
                                     lat.energy_reflection, lat.speed_ratio, 0)
