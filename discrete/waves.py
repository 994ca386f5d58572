r"""Wave analysis: arrival times and speeds, wave trains, damped solitary waves.

Arrival time and speed at a grain
---------------------------------
:func:`arrival_times` times the passage of the leading pulse's velocity peak at recorded
grains (``Recording.series_grains``, sampled every step or every few) with the cubic
Hermite interpolant of v between samples, its derivative a taken from the contact law
and the recorded overlaps (:func:`series_accelerations`; :mod:`discrete.interpolation`):
O(Δt³) in time.  :func:`wave_speed` is the distance between two grains over the
difference of their arrival times.

Wave trains
-----------
:func:`split_train` cuts a snapshot's velocity profile into its pulses
(:func:`discrete.diagnostics.find_pulses`) and gives for each its position (the peak
grain velocity's, refined by a parabola), energy (the grain energies over its extent),
and the peak velocity, peak dynamic overlap (amplitude) and speed of the exact lattice
wave that carries that energy on the local grains (docs/physics.md §7).  A Hertz wave
is about five grains wide, so the peak values *sampled* at grains and contacts depend on
where the wave stands between them — by up to 24 % (velocity) and 21 % (overlap) for the
exact wave, and a parabola through the top three samples still leaves 16 % and 12 % —
while its energy does not (the exact wave's is conserved, 7e-15): the wave of equal
energy gives phase-independent amplitudes and speeds (within 2e-3 of a placed exact
wave at every phase, ``tests/discrete/test_chains_sensors.py``).  :class:`Train` keeps
the waves with the split's parameters (the per-wave arrays and units of
:data:`TRAIN_FIELDS`); :func:`hertzchain.measure.wave_train` measures the train of a
finished run in its window.

Damped solitary wave (first-order estimate)
-------------------------------------------
A weakly dissipative law (:class:`~theory.laws.ViscoelasticHertz` with a small A)
changes the shape of a solitary wave only at O(A); to first order the wave stays the
*lossless* exact wave (:func:`theory.discrete_solitary_wave`) with a slowly decreasing
amplitude, and its energy falls at the rate the law dissipates in that wave:

.. math::
    \frac{dE}{dt} = -P, \qquad
    P = \Big\langle \sum_j \big(F(r_j, \dot r_j) - F_{el}(r_j)\big)\,\dot r_j \Big\rangle

(W; the average is over the wave's position relative to the lattice, r_j and
:math:`\dot r_j = v_{j-1} - v_j` taken from the exact wave), which
:func:`wave_dissipation` evaluates with the law's own force (its clip at F = 0
included).  In a sonic vacuum (δ0 = 0) the amplitude then obeys
dv_max/dj = -P/(2 c s v_max) per grain travelled (E = c v_max², s the grain rate); for
the viscoelastic Hertz law its solution is the closed form
:func:`theory.dissipation.kuwabara_kono_wave_decay`, v_max(j) = v0 (1 + j/j_*)^{-5}
(docs/physics.md §14), whose rate equals this P to 1e-12
(``tests/theory/test_dissipation.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from theory import DiscreteSolitaryWave, discrete_solitary_wave, sonic_vacuum_wave_constants
from theory.laws import ContactLaw, as_law

from .diagnostics.waves import arrival_times as _arrival_times
from .diagnostics.waves import find_pulses
from .reference import overlap_rates

__all__ = ["wave_dissipation", "series_accelerations", "arrival_times", "wave_speed",
           "TrainWave", "Train", "TRAIN_FIELDS", "split_train"]


def series_accelerations(sim) -> np.ndarray:
    """Accelerations (R, S) of the recorded series grains, m/s², from the recorded state.

    a_i = (F(r_i) - F(r_{i+1}) + m_i g)/m_i - β v_i with the law's force at the recorded
    overlaps (paper Eq. 2; exact for position-dependent laws; for a dissipative law the
    overlap rates are not recorded and its force is taken at ṙ = 0).
    """
    rec, ch, law = sim.record, sim.chain, sim.law
    a = rec.arrays()
    ser = a["series"]
    g = np.asarray(rec.series_grains, dtype=np.int64)
    fl = law.force(ser[:, :, 2], 0.0, ch.k[g])
    fr = law.force(ser[:, :, 3], 0.0, ch.k[g + 1])
    acc = (fl - fr + ch.body_force[g]) / ch.mass[g]
    if sim.drag:
        acc = acc - sim.drag * ser[:, :, 1]
    return acc


def arrival_times(sim, grains=None, *, threshold: float = 0.5) -> np.ndarray:
    """Times at which the leading velocity peak passes recorded grains, s (module docstring).

    Parameters
    ----------
    sim : Simulation
        A run that recorded the grains (``Recording(series_grains=...)``).
    grains : sequence of int, optional
        Which of the recorded grains (default: all, in recorded order).
    threshold : float
        The pulse timed is the first whose peak reaches this fraction of the grain's
        largest |v|.

    Returns
    -------
    ndarray
        Arrival times, s (NaN where no pulse).
    """
    rec = sim.record
    rg = [int(x) for x in rec.series_grains]
    grains = rg if grains is None else [int(x) for x in grains]
    missing = [x for x in grains if x not in rg]
    if missing:
        raise ValueError(f"grains {missing} were not recorded (series_grains {rg})")
    cols = [rg.index(x) for x in grains]
    a = rec.arrays()
    acc = series_accelerations(sim)
    return _arrival_times(a["series_t"], a["series"][:, cols, 1], threshold=threshold,
                          interpolation="hermite", derivative=acc[:, cols])


def wave_speed(sim, grain_a: int, grain_b: int, **kwargs) -> float:
    """Mean speed of the leading peak between two recorded grains, m/s.

    (x_b - x_a)/(t_b - t_a) with the grains' uncompressed centre positions
    (:attr:`Chain.positions <discrete.Chain.positions>`) and :func:`arrival_times`.
    """
    ta, tb = arrival_times(sim, [grain_a, grain_b], **kwargs)
    x = sim.chain.positions
    return float((x[grain_b] - x[grain_a]) / (tb - ta))


@dataclass(frozen=True)
class TrainWave:
    """One solitary wave of a train (:func:`split_train`).

    Attributes
    ----------
    position : float
        Grain index of its velocity peak (parabola through the peak grain and its
        neighbours).
    velocity_max : float
        Peak grain velocity of the exact lattice wave of the same energy, m/s (signed:
        < 0 for a left-going compression; the sampled peak where there is no exact wave).
    amplitude : float
        Peak dynamic overlap r - δ0 of that exact wave, m (the sampled one, refined by a
        parabola, where there is none).
    energy : float
        Sum of the grain energies (kinetic + potential) over its extent, J.
    speed : float
        Speed of that exact wave, m/s (NaN where the theory has none: n ≠ 3/2 with
        δ0 > 0).
    start, stop : int
        Its grains: ``start … stop - 1``.
    sampled_velocity : float
        The peak grain velocity of the snapshot (parabola-refined), m/s: phase-dependent.
    """

    position: float
    velocity_max: float
    amplitude: float
    energy: float
    speed: float
    start: int
    stop: int
    sampled_velocity: float = float("nan")


TRAIN_FIELDS = {
    "position": "1", "velocity_max": "m/s", "amplitude": "m", "energy": "J",
    "speed": "m/s", "start": "1", "stop": "1", "sampled_velocity": "m/s",
}
"""The per-wave arrays of a :class:`Train` and their units (``position``, ``start``,
``stop``: grain indices, counted from 0 as everywhere in the package)."""


@dataclass(frozen=True)
class Train:
    """The solitary waves of a state and how they were split (:func:`split_train`).

    Attributes
    ----------
    waves : tuple of TrainWave
        Sorted by position (grain index, increasing); empty if no pulse reached the
        threshold.
    t : float
        Time of the state split, s.
    threshold, valley : float
        :func:`split_train`'s pulse threshold (fraction of the largest |v| in the
        range) and valley depth.
    lo, hi : int
        The grains searched, ``lo … hi - 1``.
    """

    waves: tuple[TrainWave, ...]
    t: float
    threshold: float
    valley: float
    lo: int
    hi: int

    def __len__(self) -> int:
        """The number of waves."""
        return len(self.waves)

    def arrays(self) -> dict[str, np.ndarray]:
        """One array per field of :data:`TRAIN_FIELDS`, one entry per wave (float64 or int64)."""
        out = {}
        for name in TRAIN_FIELDS:
            kind = np.int64 if name in ("start", "stop") else np.float64
            out[name] = np.array([getattr(w, name) for w in self.waves], dtype=kind)
        return out

    def params(self) -> dict[str, float | int]:
        """The split's parameters (``t`` in s, the rest dimensionless or grains)."""
        return {"t": float(self.t), "threshold": float(self.threshold),
                "valley": float(self.valley), "lo": int(self.lo), "hi": int(self.hi)}

    @classmethod
    def from_arrays(cls, arrays: dict, params: dict) -> Train:
        """The train :meth:`arrays` and :meth:`params` describe.

        ValueError naming the field if one is missing or the arrays differ in length.
        """
        missing = [k for k in TRAIN_FIELDS if k not in arrays] + \
            [k for k in ("t", "threshold", "valley", "lo", "hi") if k not in params]
        if missing:
            raise ValueError(f"train: missing {missing}")
        lengths = {k: np.shape(arrays[k]) for k in TRAIN_FIELDS}
        if len(set(lengths.values())) != 1 or len(lengths["position"]) != 1:
            raise ValueError(f"train: the per-wave arrays must be 1-D of one length (got "
                             f"shapes {lengths})")
        n = lengths["position"][0]
        waves = tuple(TrainWave(**{k: (int(arrays[k][i]) if k in ("start", "stop")
                                       else float(arrays[k][i])) for k in TRAIN_FIELDS})
                      for i in range(n))
        return cls(waves, float(params["t"]), float(params["threshold"]),
                   float(params["valley"]), int(params["lo"]), int(params["hi"]))


def _peak(y: np.ndarray) -> float:
    """Largest value of samples ``y``, refined by the parabola through the top three.

    A wave a few grains wide sampled at the contacts shows a peak that depends on its
    phase between them (up to ~20 % for Hertz); the parabola's vertex removes most of it.
    """
    j = int(np.argmax(y))
    if 0 < j < y.size - 1:
        y0, y1, y2 = float(y[j - 1]), float(y[j]), float(y[j + 1])
        den = y0 - 2.0 * y1 + y2
        if den < 0:
            return y1 - (y0 - y2) ** 2 / (8.0 * den)
    return float(y[j])


def split_train(sim, *, threshold: float = 0.05, valley: float = 0.5, lo: int = 0,
                hi: int | None = None) -> list[TrainWave]:
    """The solitary waves of the present state of ``sim`` (module docstring).

    Pulses of the grain velocity above ``threshold`` × the largest |v| in ``[lo, hi)``
    separated where |v| falls below ``valley`` × the smaller peak
    (:func:`discrete.diagnostics.find_pulses`); sorted by position.  :class:`Train`
    (``Train(tuple(waves), sim.t, threshold, valley, lo, hi)``) keeps them with these
    parameters, as ``hertzchain run`` writes them (:func:`discrete.io.save`).
    """
    ch = sim.chain
    v = sim.v
    ek, ep = sim.grain_energy()
    et = ek + ep
    r = sim.overlaps()
    out = []
    for p in find_pulses(v, threshold=threshold, valley=valley, lo=lo, hi=hi):
        g = p.index
        amp = _peak(r[p.start:p.stop + 1] - ch.delta0[p.start:p.stop + 1])
        energy = float(np.sum(et[p.start:p.stop]))
        j = min(max(g, 1), ch.n - 1)
        vm, speed = p.amplitude, float("nan")
        try:
            w = _wave_of_energy(ch.k[j], ch.mass[g], ch.diameter[g], ch.delta0[j],
                                sim.law.exponent, energy, abs(p.amplitude))
            vm, amp, speed = float(np.copysign(w.velocity_max, p.amplitude)), w.amplitude, \
                w.speed
        except (ValueError, RuntimeError):
            pass
        out.append(TrainWave(p.position, vm, amp, energy, float(speed), p.start, p.stop,
                             p.amplitude))
    return out


def _wave_of_energy(k: float, mass: float, d: float, delta0: float, exponent: float,
                    energy: float, guess: float) -> DiscreteSolitaryWave:
    r"""The exact lattice wave of ``energy`` (J) on these grains.

    Without precompression (δ0 = 0) the exact waves of F = k r^n form one self-similar
    family (Nesterenko 2001, *Dynamics of Heterogeneous Materials*, §1.1; English & Pego,
    Proc. AMS 133, 1763 (2005); :func:`theory.discrete_solitary_wave`): scaling the peak
    velocity v_max → μ v_max scales the overlaps by μ^{2/(n+1)}, the speed by
    μ^{(n-1)/(n+1)} and the energy by μ², so

    .. math:: E = \hat e\, m\, v_{max}^2, \qquad v_{max} = \sqrt{E/(\hat e\, m)}

    with ê = :attr:`theory.SonicVacuumWave.energy` (1.0693 for Hertz), independent of k
    and d: the wave is one rescaling of the cached unit solve, no root finding
    (``guess`` is not needed).  With δ0 > 0 the family has a second scale (ε = A/δ0) and
    the root of ln E(v) − ln E is bracketed around ``guess`` (m/s; the sampled peak is
    within ~25 % of the wave's) and refined by Brent's method to 1e-10 in ln v (SciPy's
    root finder is imported only then).  ValueError if there is no exact wave (an
    exponent outside (1, 10]) or no root; zero energy or velocity has no wave.
    """
    if not (energy > 0 and guess > 0):
        raise ValueError("no wave: zero energy or velocity")
    if delta0 == 0.0:
        e_hat = sonic_vacuum_wave_constants(exponent).energy
        return discrete_solitary_wave(k, mass, d, 0.0,
                                      velocity_max=math.sqrt(energy / (e_hat * mass)),
                                      exponent=exponent)
    from scipy.optimize import brentq

    def wave(lv):
        return discrete_solitary_wave(k, mass, d, delta0, velocity_max=math.exp(lv),
                                      exponent=exponent)

    def f(lv):
        return math.log(wave(lv).energy() / energy)

    lo, hi = math.log(guess) - 0.2, math.log(guess) + 0.6
    flo, fhi = f(lo), f(hi)
    for _ in range(10):  # widen until bracketed
        if flo < 0 < fhi:
            break
        if flo >= 0:
            lo -= 0.5
            flo = f(lo)
        if fhi <= 0:
            hi += 0.5
            fhi = f(hi)
    else:
        raise ValueError("no exact wave of this energy near the sampled peak")
    return wave(brentq(f, lo, hi, xtol=1e-10))


def wave_dissipation(wave: DiscreteSolitaryWave, law: ContactLaw, *, phases: int = 16
                     ) -> float:
    """Power P (W) that ``law`` dissipates in the exact lossless ``wave`` (module docstring).

    Averaged over ``phases`` positions of the peak between two contacts.
    """
    law = as_law(law)
    n_dom = wave.z.size // wave.points_per_grain
    total = 0.0
    for ph in np.arange(int(phases)) / int(phases):
        st = wave.sample(n_dom, n_dom // 2 + ph)
        r = st.overlap
        rd = overlap_rates(st.velocity)
        f = law.force(r, rd, wave.k_n)
        total += float(np.sum((f - law.elastic(r, wave.k_n)) * rd))
    return total / int(phases)
