r"""Classification of transmitted and reflected waves (paper Section 3.2, 4; Fig. 7).

Transmitted: "fracture" (γ_c0 > 1: a train of solitary waves) vs "squeeze" (γ_c0 < 1: a
single leading solitary wave and an oscillatory tail).  Reflected: "compressive"
(γ_RG > 1) vs "expansive" (γ_RG < 1, the paper's "overshoot").  Each classifier returns
a dataclass with the numbers behind the decision, so the thresholds can be examined.

Sign conventions: for a right-going wave v = V ξ with the strain ξ = -u_x, for a
left-going one v = -V ξ; a compressive reflected (left-going) wave has v < 0
(paper Section 4 on Fig. 3b).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .waves import Pulse, find_pulses

__all__ = [
    "TransmittedClassification",
    "classify_transmitted",
    "ReflectedClassification",
    "classify_reflected",
]

FloatArray = NDArray[np.float64]
_OSCILLATORY = 0.05
"""A squeeze's tail counts as oscillatory when an opposite-sign lobe exceeds this × peak."""


@dataclass(frozen=True)
class TransmittedClassification:
    """Fracture vs squeeze of a transmitted wave (paper Fig. 7), with the numbers behind it.

    Attributes
    ----------
    label : str
        ``"fracture"``, ``"squeeze"`` or ``"none"`` (no leading pulse found).
    reason : str
        Which rule decided (see :func:`classify_transmitted`).
    n_pulses : int
        Solitary-like pulses: the leading one and the consecutive same-sign pulses behind
        it with |peak| ≥ ``min_ratio`` × leading, each separated from the pulse ahead of it
        by no opposite-sign lobe larger than ``max_oscillation`` × its own peak.
    leading_amplitude, leading_position : float
        Signed peak and position of the leading (front) pulse.
    second_ratio : float
        |peak| of the next same-sign pulse behind the front / leading |peak| (0 if none).
    oscillation_ratio : float
        Largest opposite-sign |signal| between the leading and that second pulse,
        relative to the second pulse's |peak| (0 if no second pulse).
    tail_oscillation : float
        Largest opposite-sign |signal| behind the leading pulse (within the
        trailing-excess window) relative to the leading |peak|.
    trailing_excess : float
        Asymmetry of the leading pulse: Σ_j [s(x_c - j) - s(x_c + j)] / (A/2 + Σ_j s(x_c + j))
        for j = 1 ... W (direction +1; mirrored for -1), s in units of the peak sign,
        x_c the refined peak position, values between grains by cubic interpolation,
        W = ``excess_window`` × the front half-width at half maximum.  0 for a symmetric
        (solitary) pulse, > 0 for a same-sign shelf trailing it (a train still forming),
        < 0 for a pulse followed by an opposite-sign lobe (oscillatory tail).
    gap_growth : float or None
        Change of the distance between the first two pulses between two snapshots
        (samples); positive when they separate.
    pulses : list of Pulse
        The solitary-like pulses, front first.
    thresholds : dict
        The thresholds used.
    """

    label: str
    reason: str
    n_pulses: int
    leading_amplitude: float
    leading_position: float
    second_ratio: float
    oscillation_ratio: float
    tail_oscillation: float
    trailing_excess: float
    gap_growth: float | None
    pulses: list[Pulse] = field(repr=False)
    thresholds: dict

    @property
    def is_fracture(self) -> bool:
        """True for a multipulse (fractured) transmitted wave."""
        return self.label == "fracture"


def _half_width(s: FloatArray, p: Pulse, direction: int, lo: int, hi: int) -> float:
    """Distance (samples) from the refined peak to half maximum on the front side."""
    half = 0.5 * abs(p.amplitude)
    sg = p.sign
    i = p.index
    while lo <= i + direction < hi and sg * s[i + direction] > half:
        i += direction
    j = i + direction
    if not lo <= j < hi:
        return float(abs(i - p.position)) + 0.5
    y0, y1 = sg * s[i], sg * s[j]
    frac = (y0 - half) / (y0 - y1) if y0 != y1 else 0.0
    return max(0.5, abs(i + direction * frac - p.position))


def _trailing_excess(s: FloatArray, p: Pulse, direction: int, lo: int, hi: int,
                     window: float) -> tuple[float, float, int]:
    from scipy.interpolate import CubicSpline

    h = _half_width(s, p, direction, lo, hi)
    w = max(2, int(np.ceil(window * h)))
    a, b = max(lo, p.index - w - 2), min(hi, p.index + w + 3)
    x = np.arange(a, b, dtype=float)
    y = p.sign * s[a:b]
    if y.size < 4:
        return 0.0, 0.0, w
    f = CubicSpline(x, y, extrapolate=False)
    j = np.arange(1, w + 1, dtype=float)
    front = np.nan_to_num(f(p.position + direction * j))
    back = np.nan_to_num(f(p.position - direction * j))
    den = 0.5 * abs(p.amplitude) + float(np.sum(front))
    exc = float(np.sum(back - front) / den) if den > 0 else 0.0
    if direction == 1:
        seg = y[max(0, p.index - w - a):p.index - a]
    else:
        seg = y[p.index - a + 1:p.index - a + 1 + w]
    osc = float(max(0.0, -seg.min()) / abs(p.amplitude)) if seg.size else 0.0
    return exc, osc, h


def _solitary_train(s: FloatArray, lo: int, hi: int, direction: int, min_ratio: float,
                    max_osc: float, valley: float) -> tuple[list[Pulse], float, float]:
    """Leading pulse and the consecutive solitary-like same-sign pulses behind it."""
    pulses = find_pulses(s, threshold=0.5 * min_ratio, lo=lo, hi=hi, valley=valley)
    if not pulses:
        return [], 0.0, 0.0
    lead = pulses[-1] if direction == 1 else pulses[0]
    a1 = lead.amplitude
    same = [p for p in pulses if p.sign == lead.sign and direction * (lead.index - p.index) > 0]
    same.sort(key=lambda p: -direction * p.index)
    train = [lead]
    second_ratio = osc_ratio = 0.0
    for k, p in enumerate(same):
        prev = train[-1]
        i0, i1 = sorted((prev.index, p.index))
        seg = s[i0:i1 + 1]
        opp = seg[np.sign(seg) == -np.sign(a1)]
        o = float(np.abs(opp).max() / abs(p.amplitude)) if opp.size else 0.0
        if k == 0:
            second_ratio, osc_ratio = abs(p.amplitude / a1), o
        if abs(p.amplitude) >= min_ratio * abs(a1) and o <= max_osc:
            train.append(p)
        else:
            break
    return train, second_ratio, osc_ratio


def classify_transmitted(
    signal: ArrayLike,
    *,
    lo: int = 0,
    hi: int | None = None,
    direction: int = 1,
    min_ratio: float = 0.2,
    max_oscillation: float = 0.5,
    min_excess: float = 0.1,
    excess_window: float = 4.0,
    min_half_width: float = 2.0,
    valley: float = 0.5,
    later_signal: ArrayLike | None = None,
) -> TransmittedClassification:
    """Classify a transmitted wave as "fracture" (multipulse train) or "squeeze".

    Paper Section 3.2/4 and Fig. 7: for γ_c0 > 1 the incident wave fractures into a train
    of solitary waves that separate (Figs. 3a, 4b, 5a, 5d); for γ_c0 < 1 it is squeezed
    into a single leading solitary wave followed by an oscillatory tail (Figs. 5b, 5c) or,
    without precompression, by pulses much weaker than the front (Figs. 3b, 4a).

    Rules, in order (all numbers returned):

    1. **fracture, "multipulse train"** — at least two solitary-like pulses (see
       :class:`TransmittedClassification`: same sign, |peak| ≥ ``min_ratio`` × front,
       not separated by an opposite-sign lobe > ``max_oscillation`` × their peak — a
       solitary wave returns to rest between pulses, an oscillatory tail swings to the
       other sign), and, if ``later_signal`` is given, the first two drift apart;
    2. **fracture, "trailing shelf"** — ``trailing_excess`` ≥ ``min_excess`` and the front
       pulse is resolved (front half-width ≥ ``min_half_width`` samples): the front pulse
       carries a same-sign shoulder behind it, the train not yet separated (under
       precompression the pulses separate only over thousands of grains, which is why
       the paper uses 50,000 grains).  Compact pulses (δ0 = 0: ~1 grain half-width) are
       too coarsely sampled for the mirror test;
    3. otherwise **squeeze** (``reason`` says "oscillatory tail" if an opposite-sign lobe
       behind the front exceeds 5 % of its peak).

    Defaults were chosen on the paper's cases a–d of Figs. 3–5 run to ~400–500 grains
    past the interface (exact incident solitary wave, see the tests): second-pulse
    ratios 0.56–0.68 (a) and 0.25–0.32 (d) vs 0.11–0.12 (c) and none (b) at δ0 = 0;
    trailing excess 0.15–0.45 (a) and 0.3–0.7 (d) vs -0.28 to -0.6 (b, c) at
    δ0/d = 1e-3; symmetric resolved pulses give |excess| < 0.02.

    Parameters
    ----------
    signal : array_like, shape (N,)
        Snapshot of grain velocity (m/s) or strain.
    lo, hi : int
        Grain range of the transmitted section.
    direction : int
        Propagation direction of the transmitted wave (+1 right).
    min_ratio, max_oscillation, min_excess, excess_window, min_half_width, valley : float
        Thresholds (see above and :func:`find_pulses`).
    later_signal : array_like, optional
        A later snapshot of the same quantity, for the separation test of rule 1.

    Returns
    -------
    TransmittedClassification
    """
    if direction not in (1, -1):
        raise ValueError("direction must be +1 or -1")
    s = np.asarray(signal, dtype=float)
    hi = s.size if hi is None else hi
    thr = {"min_ratio": min_ratio, "max_oscillation": max_oscillation,
           "min_excess": min_excess, "excess_window": excess_window,
           "min_half_width": min_half_width, "valley": valley}
    train, r2, osc = _solitary_train(s, lo, hi, direction, min_ratio, max_oscillation, valley)
    if not train:
        return TransmittedClassification("none", "no pulse", 0, 0.0, float("nan"), 0.0, 0.0,
                                         0.0, 0.0, None, [], thr)
    lead = train[0]
    exc, tail, hw = _trailing_excess(s, lead, direction, lo, hi, excess_window)
    growth = None
    if later_signal is not None and len(train) >= 2:
        later, *_ = _solitary_train(np.asarray(later_signal, dtype=float), lo, hi, direction,
                                    min_ratio, max_oscillation, valley)
        if len(later) >= 2:
            growth = abs(later[0].position - later[1].position) - abs(
                train[0].position - train[1].position)
    if len(train) >= 2 and (growth is None or growth > 0):
        label, reason = "fracture", "multipulse train"
    elif exc >= min_excess and hw >= min_half_width:
        label, reason = "fracture", "trailing shelf"
    else:
        label = "squeeze"
        reason = ("single pulse with oscillatory tail" if tail > _OSCILLATORY
                  else "single dominant pulse")
    return TransmittedClassification(label, reason, len(train), lead.amplitude, lead.position,
                                     r2, osc, tail, exc, growth, train, thr)


@dataclass(frozen=True)
class ReflectedClassification:
    """Compressive vs expansive reflected wave (paper Fig. 7), with the numbers behind it.

    Attributes
    ----------
    label : str
        ``"compressive"``, ``"expansive"`` or ``"none"`` (no pulse above ``min_ratio``).
    quantity : str
        ``"strain"`` (precompressed: sign of r - δ0) or ``"velocity"`` (δ0 = 0: a
        left-going compressive wave has v < 0).
    dominant_amplitude : float
        Signed peak of the dominant (largest |·|) reflected pulse, in the units of
        ``quantity`` (strain (r - δ0)/δ0, or m/s).
    dominant_position : float
        Its position (contact or grain index).
    relative_amplitude : float
        |dominant| / ``reference`` (NaN without a reference).
    net_strain : float
        Σ (r_j - δ0_j)/δ0_j over the examined contacts (NaN for velocity): its sign is
        that of the linear potential energy carried (docs/physics.md §6).
    min_ratio : float
        Threshold on ``relative_amplitude`` below which the label is ``"none"``.
    """

    label: str
    quantity: str
    dominant_amplitude: float
    dominant_position: float
    relative_amplitude: float
    net_strain: float
    min_ratio: float


def classify_reflected(
    *,
    overlaps: ArrayLike | None = None,
    delta0: ArrayLike | None = None,
    velocity: ArrayLike | None = None,
    lo: int = 0,
    hi: int | None = None,
    direction: int = -1,
    reference: float | None = None,
    min_ratio: float = 0.05,
) -> ReflectedClassification:
    """Classify the reflected wave as compressive or expansive (paper Fig. 7).

    Sign of the dominant (largest |·|) pulse of the strain (r - δ0)/δ0 over contacts
    ``lo ... hi - 1`` (precompressed chains; give ``overlaps`` and ``delta0``), or, for
    δ0 = 0 where the strain of an open contact is meaningless, of the grain velocity over
    grains ``lo ... hi - 1`` (give ``velocity``): a left-going (``direction=-1``)
    compressive wave has v < 0 (paper Section 4 on Fig. 3b), an expansive one v > 0.
    Overlap-based classification is used when ``overlaps`` are given and all δ0 in range
    are > 0.  For the reflected wave in the left section of a two-section chain of N_L
    grains, use contacts ``lo=1, hi=N_L`` (excluding wall and interface contacts) or grains
    ``lo=0, hi=N_L``.

    Parameters
    ----------
    overlaps, delta0 : array_like, shape (N + 1,), optional
        Contact overlaps and static overlaps, m.
    velocity : array_like, shape (N,), optional
        Grain velocities, m/s.
    lo, hi : int
        Contact (or grain) range of the reflected wave.
    direction : int
        Direction of the reflected wave (-1 left), used only with ``velocity``.
    reference : float, optional
        Incident amplitude in the same units, for ``relative_amplitude`` and ``"none"``.
    min_ratio : float
        Below ``min_ratio × reference`` the reflected wave counts as absent.  Default
        0.05: at δ0/d = 1e-3 the points with γ_RG = 1 (P, Q; "no reflection", Table 2
        E_Re ≲ 2e-4) reflect 0.4–1.5 % of the incident amplitude, the points a–d, M, N
        24–39 %.

    Notes
    -----
    Without precompression only compressive waves propagate (a sonic vacuum cannot carry
    an expansive wave: the contacts just open), so at δ0 = 0 the tiny reflected trains of
    hard–soft interfaces (paper Fig. 4a) come out compressive; the paper's
    compressive/expansive phase diagram (Fig. 7) is for δ0/d = 1e-3.
    """
    if direction not in (1, -1):
        raise ValueError("direction must be +1 or -1")
    use_strain = overlaps is not None
    if use_strain:
        if delta0 is None:
            raise ValueError("overlaps need delta0")
        r = np.asarray(overlaps, dtype=float)
        d0 = np.broadcast_to(np.asarray(delta0, dtype=float), r.shape)
        hi_ = r.size if hi is None else hi
        if np.any(d0[lo:hi_] <= 0):
            if velocity is None:
                raise ValueError("delta0 = 0 in range: classify by velocity instead")
            use_strain = False
    if use_strain:
        s = (r - d0)[lo:hi_] / d0[lo:hi_]
        quantity, net = "strain", float(np.sum(s))
        orient = 1.0
    else:
        if velocity is None:
            raise ValueError("give overlaps and delta0, or velocity")
        v = np.asarray(velocity, dtype=float)
        s = v[lo:(v.size if hi is None else hi)]
        quantity, net = "velocity", float("nan")
        orient = float(direction)
    if s.size == 0:
        raise ValueError("empty range")
    i = int(np.argmax(np.abs(s)))
    pulses = find_pulses(s, threshold=0.0, lo=max(0, i - 1), hi=min(s.size, i + 2))
    pk = next((p for p in pulses if p.index == i), None)
    pos, amp = (pk.position, pk.amplitude) if pk is not None else (float(i), float(s[i]))
    rel = abs(amp) / abs(reference) if reference else float("nan")
    if amp == 0.0 or (reference and rel < min_ratio):
        label = "none"
    else:
        # strain: compressive iff > 0.  velocity: v = direction·V·ξ for a wave moving in
        # ``direction`` (v = V ξ right-going, v = -V ξ left-going), so ξ has the sign of
        # direction·v.
        comp = amp > 0 if quantity == "strain" else orient * amp > 0
        label = "compressive" if comp else "expansive"
    return ReflectedClassification(label, quantity, amp, pos + lo, rel, net, min_ratio)
