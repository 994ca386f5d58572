r"""Initial conditions: impact (paper Fig. 2), settled cut wave (paper Section 2), exact wave.

All return an :class:`Initial` — a chain with u (m), v (m/s) and wall displacements (m)
— to be passed to :meth:`Initial.simulation`.

The paper's procedure (Section 2, end): run a monodisperse chain with the left section's
parameters from an impact until the leading solitary wave has settled, cut it out with
``half_width`` grains on each side of its velocity peak, and place it in the composite
chain "with the velocities of the other grains set to zero".  Grains behind the cut
wave and the left wall are shifted by the displacement of the first cut grain: without
this shift the contact at the back of the wave would be stretched by the wave's net
displacement (≈ 0.1 δ0 at δ0/d = 1e-3) and launch a rarefaction wave.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import warnings
import zipfile
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np

from theory import integrity
from theory.laws import ContactLaw, as_law

from .chain import Chain
from .recording import Recording, WaveAt
from .simulation import Simulation
from .timestep import DT_FRACTION, default_dt

__all__ = ["Initial", "SettledWave", "impact", "settled_wave", "place_wave", "cut_wave",
           "exact_wave", "kdv_wave"]


@dataclass
class Initial:
    """A chain and its initial state: u (m), v (m/s), wall displacements (m)."""

    chain: Chain
    u: np.ndarray
    v: np.ndarray
    wall_left: float = 0.0
    wall_right: float = 0.0
    params: dict = field(default_factory=dict)

    def simulation(self, **kwargs) -> Simulation:
        """A :class:`Simulation` starting from this state (keyword arguments passed on)."""
        return Simulation(self.chain, self.u, self.v, wall_left=self.wall_left,
                          wall_right=self.wall_right, **kwargs)


def impact(chain: Chain, v0: float = 1.0, *, striker_mass: float | None = None,
           striker_k: float | None = None, striker_diameter: float | None = None) -> Initial:
    """Impact: grain 0 (or a prepended striker) moves at ``v0`` (m/s), the rest at rest.

    The paper's Fig. 2 gives the left-most grain v0 = 1 m/s.  With ``striker_mass`` (kg)
    a striker grain is prepended as grain 0, touching grain 0 of ``chain`` with the
    contact constant ``striker_k`` (default: that of the chain's first grain–grain
    contact, N/m^{3/2}); the left wall (if any) stays behind the striker.
    """
    v0 = float(v0)
    if not np.isfinite(v0):
        raise ValueError(f"v0 must be finite (got {v0!r})")
    if striker_mass is not None:
        ms = float(striker_mass)
        if not np.isfinite(ms) or ms <= 0:
            raise ValueError(f"striker_mass must be finite and > 0 kg (got {striker_mass!r})")
        ks = float(chain.k[1] if striker_k is None else striker_k)
        if not np.isfinite(ks) or ks <= 0:
            raise ValueError(f"striker_k must be finite and > 0 (got {striker_k!r})")
        ds = float(chain.diameter[0] if striker_diameter is None else striker_diameter)
        k = np.r_[chain.k[0], ks, chain.k[1:]]
        d0 = 0.0 if not np.any(chain.delta0 > 0) else float(chain.delta0[1])
        chain = Chain.from_arrays(np.r_[ms, chain.mass], k, d0,
                                  diameter=np.r_[ds, chain.diameter],
                                  section=np.r_[-1, chain.section], exponent=chain.exponent,
                                  params={**chain.params, "striker_mass": ms, "striker_k": ks})
    v = np.zeros(chain.n)
    v[0] = v0
    return Initial(chain, np.zeros(chain.n), v,
                   params={"kind": "impact", "v0": v0, "striker_mass": striker_mass})


@dataclass(frozen=True)
class SettledWave:
    """A cut-out solitary wave: u (m), v (m/s) of 2·half_width + 1 grains, peak in the middle.

    ``mass`` (kg), ``k`` (N/m^{3/2}) and ``delta0`` (m) are the source chain's grain and
    contact parameters, ``diameter`` (m); ``params`` records how it was made.
    """

    u: np.ndarray
    v: np.ndarray
    mass: float
    k: float
    delta0: float
    diameter: float
    params: dict

    @property
    def half_width(self) -> int:
        """Grains on each side of the peak."""
        return (self.u.size - 1) // 2


def _settle_grains(delta0_over_d: float) -> int:
    # docs/physics.md §1: at δ0/d = 1e-3 the leading wave needs ~6,000–9,000 grains to settle;
    # without precompression ~100 suffice (v̄max/v0 constant to 1e-6 beyond grain 50).
    return 200 if delta0_over_d == 0 else 10_000


def settled_wave(mass: float, k: float, delta0: float = 0.0, *, diameter: float,
                 v0: float = 1.0, settle_grains: int | None = None, half_width: int = 40,
                 dt_fraction: float = DT_FRACTION, cache_dir: str | os.PathLike | None = None
                 ) -> SettledWave:
    """The paper's settled solitary wave in a monodisperse chain (cached).

    Impact at ``v0`` (m/s) on a monodisperse chain of grains of ``mass`` (kg), contact
    constant ``k`` (N/m^{3/2}), static overlap ``delta0`` (m) and ``diameter`` (m) with
    paper walls; run until the leading wave's velocity peak passes grain
    ``settle_grains`` (default 200 at δ0 = 0, 10,000 with precompression) and cut
    ``half_width`` grains on each side of the peak grain.  Results are memoised in
    memory and, with ``cache_dir``, in an ``.npz`` file keyed by the parameters.
    """
    args = tuple(float(x) for x in (mass, k, delta0, diameter, v0, dt_fraction))
    if any(not np.isfinite(x) for x in args) or min(args[0], args[1], args[3]) <= 0:
        raise ValueError("mass, k and diameter must be finite and > 0; delta0 finite >= 0")
    if args[2] < 0:
        raise ValueError(f"delta0 must be >= 0 m (got {delta0!r})")
    if args[4] <= 0:
        raise ValueError(f"v0 must be > 0 m/s (got {v0!r})")
    ng = _settle_grains(args[2] / args[3]) if settle_grains is None else int(settle_grains)
    hw = int(half_width)
    if hw < 1 or ng < hw + 1:
        raise ValueError(f"need half_width >= 1 and settle_grains > half_width "
                         f"(got {half_width!r}, {settle_grains!r})")
    key = (*args, ng, hw)
    if cache_dir is not None:
        return _disk_cached(key, Path(cache_dir))
    return _settled_memo(key)


@lru_cache(maxsize=32)
def _settled_memo(key: tuple) -> SettledWave:
    return _compute_settled(*key)


def _disk_cached(key: tuple, cache_dir: Path) -> SettledWave:
    """The settled wave of ``key`` from its sealed ``.npz`` cache file, or computed.

    The file is sealed and written atomically (:mod:`theory.integrity`); a damaged,
    unsealed or foreign one is recomputed and replaced, with a warning naming it.
    """
    h = hashlib.sha256(json.dumps(key).encode()).hexdigest()[:16]
    path = cache_dir / f"settled_wave_{h}.npz"
    if path.exists():
        try:
            payload = integrity.read_sealed_bytes(path, what="settled-wave cache")
            with np.load(io.BytesIO(payload), allow_pickle=False) as f:
                if json.loads(str(f["key"])) == list(key):
                    return SettledWave(f["u"], f["v"], *key[:4],
                                       json.loads(str(f["params"])))
            reason = "it holds another wave"
        except (ValueError, OSError, KeyError, EOFError, zipfile.BadZipFile) as exc:
            reason = str(exc)
        warnings.warn(f"recomputing the settled wave cached in {path}: {reason}",
                      RuntimeWarning, stacklevel=3)
    w = _settled_memo(key)
    buf = io.BytesIO()
    np.savez_compressed(buf, u=w.u, v=w.v, key=json.dumps(list(key)),
                        params=json.dumps(w.params))
    integrity.write_sealed_bytes(path, buf.getvalue())
    return w


def _compute_settled(mass, k, delta0, diameter, v0, dt_fraction, ng, hw) -> SettledWave:
    # The peak c is searched in [ng - hw, ng + hw] and the cut reaches c + hw, so the
    # settling chain needs ng + 2 hw + 1 grains and a margin before its far wall (with
    # ng + hw + 20 a strongly precompressed wave, whose peak the far wall pulls forward,
    # was clipped: 59 of 2 hw + 1 = 81 grains at δ0/d = 1e-2).
    n = ng + 2 * hw + 20
    kk = np.full(n + 1, k)
    chain = Chain.from_arrays(np.full(n, mass), kk, delta0, diameter=diameter)
    init = impact(chain, v0)
    dt = default_dt(chain, init.u, init.v, fraction=dt_fraction)
    sim = init.simulation(dt=dt, record=Recording(maxima=False, monitor_every=10**6))
    sim.run(until=WaveAt(ng), progress=False)
    c = int(np.argmax(sim.v[ng - hw:ng + hw + 1])) + ng - hw
    sl = slice(c - hw, c + hw + 1)
    params = {"v0": v0, "settle_grains": ng, "half_width": hw, "peak_grain": c,
              "t": sim.t, "dt": dt, "dt_fraction": dt_fraction, "v_peak": float(sim.v[c]),
              "energy_drift": sim.energy_drift}
    return SettledWave(sim.u[sl].copy(), sim.v[sl].copy(), mass, k, delta0, diameter, params)


def place_wave(chain: Chain, wave: SettledWave, centre: int, *, shift_behind: bool = True,
               rtol: float = 1e-9) -> Initial:
    """Place a cut wave with its peak at grain ``centre`` of ``chain`` (others at rest).

    Grains behind the wave and the left wall are shifted by the displacement of the
    first cut grain (``shift_behind``; module docstring).  The grains and contacts the
    wave covers must have the wave's mass, k and δ0 (to ``rtol``).
    """
    hw = wave.half_width
    c = int(centre)
    if c - hw < 0 or c + hw > chain.n - 1:
        raise ValueError(f"wave placed outside the chain: grains {c - hw}..{c + hw} must lie "
                         f"in [0, {chain.n - 1}] (centre in [{hw}, {chain.n - 1 - hw}])")
    sl = slice(c - hw, c + hw + 1)
    for name, arr, val in (("mass", chain.mass[sl], wave.mass),
                           ("k", chain.k[c - hw + 1:c + hw + 1], wave.k),
                           ("delta0", chain.delta0[c - hw + 1:c + hw + 1], wave.delta0)):
        if np.any(np.abs(arr - val) > rtol * abs(val)):
            raise ValueError(f"the chain's {name} under the placed wave differs from the "
                             f"wave's ({val!r}): place it in a section with the same grains")
    u = np.zeros(chain.n)
    v = np.zeros(chain.n)
    u[sl] = wave.u
    v[sl] = wave.v
    wl = 0.0
    if shift_behind:
        u[:c - hw] = wave.u[0]
        wl = float(wave.u[0]) if chain.k[0] > 0 else 0.0
    return Initial(chain, u, v, wall_left=wl,
                   params={"kind": "settled_wave", "centre": c, **wave.params})


def cut_wave(chain: Chain, centre: int, *, v0: float = 1.0, settle_grains: int | None = None,
             half_width: int = 40, dt_fraction: float = DT_FRACTION,
             cache_dir: str | os.PathLike | None = None) -> Initial:
    """The paper's procedure in one call: settle a wave and place it at ``centre``.

    The wave is settled with the parameters of grain ``centre`` (its mass, k, δ0,
    diameter; :func:`settled_wave`) and placed with :func:`place_wave`.
    """
    c = int(centre)
    if not 0 <= c < chain.n:
        raise ValueError(f"centre {c} outside the chain [0, {chain.n})")
    w = settled_wave(chain.mass[c], chain.k[c], chain.delta0[c], diameter=chain.diameter[c],
                     v0=v0, settle_grains=settle_grains, half_width=half_width,
                     dt_fraction=dt_fraction, cache_dir=cache_dir)
    return place_wave(chain, w, c)


def exact_wave(chain: Chain, centre: float, *, velocity_max: float | None = None,
               amplitude: float | None = None, strain_max: float | None = None,
               tail: float = 1e-12, law: ContactLaw | None = None, **kwargs) -> Initial:
    """The exact discrete solitary wave (:func:`theory.discrete_solitary_wave`), right-going.

    The travelling wave r_j(t) = R(j - centre - s t) of Eq. 2 (docs/physics.md §7) for the
    grains and contact at ``centre`` (their mass, k_n, δ0, diameter), with its overlap
    peak at contact ``centre`` (between grains centre-1 and centre) at t = 0.  Give
    exactly one of ``velocity_max`` (peak grain velocity, m/s), ``amplitude`` (peak
    dynamic overlap r_max - δ0, m) or ``strain_max`` (amplitude/d).

    Grains behind the wave and the left wall carry the net shift D of the wave.  Every
    grain and contact where the wave's velocity or dynamic overlap exceeds ``tail`` ×
    its peak must have the wave's parameters (ValueError otherwise: the wave does not
    fit in the chain or section).  Velocities below ``tail`` × peak are set to exactly 0
    (the spectral sampling leaves a uniform ~1e-13 × peak velocity behind the wave), so
    the grains behind it are inert.  ``law``: the contact law whose (elastic) exponent n
    the wave is solved for (:mod:`theory.laws`; default Hertz; any n, with or without
    precompression: build the chain with ``exponent=n``).
    Other keyword arguments go to :func:`theory.discrete_solitary_wave`.
    """
    from theory import discrete_solitary_wave

    c = float(centre)
    if not np.isfinite(c) or not 0 <= c <= chain.n:
        raise ValueError(f"centre {centre!r} outside the chain: contact index in [0, {chain.n}]")
    j = int(np.clip(round(c), 1, chain.n - 1))
    if strain_max is not None:
        if amplitude is not None or velocity_max is not None:
            raise ValueError("give exactly one of velocity_max, amplitude or strain_max")
        amplitude = float(strain_max) * float(chain.diameter[j])
    if law is not None:
        kwargs.setdefault("exponent", as_law(law).exponent)
    w = discrete_solitary_wave(chain.k[j], chain.mass[j], chain.diameter[j], chain.delta0[j],
                               amplitude=amplitude, velocity_max=velocity_max, **kwargs)
    st = w.sample(chain.n, c)
    u, v, r = st.displacement, st.velocity, st.overlap
    dyn = np.abs(r - w.delta0) > tail * w.amplitude
    dyn[0] |= abs(st.wall_displacement[0] - u[0]) > tail * max(abs(w.net_shift), 1e-300)
    mov = np.abs(v) > tail * w.velocity_max
    if dyn[0] or dyn[-1] or mov[0] or mov[-1]:
        raise ValueError(f"wave placed outside the chain: at centre {c} its tails (above "
                         f"{tail:g} of the peak) reach a chain end; move it inwards")
    grains = np.flatnonzero(mov | dyn[:-1] | dyn[1:])
    contacts = np.flatnonzero(dyn)
    for name, arr, val in (("mass", chain.mass[grains], w.mass),
                           ("k", chain.k[contacts], w.k_n),
                           ("delta0", chain.delta0[contacts], w.delta0)):
        if np.any(np.abs(arr - val) > 1e-9 * abs(val)):
            raise ValueError(f"the chain's {name} under the exact wave (grains "
                             f"{grains.min()}..{grains.max()}) differs from that at the "
                             f"centre: the wave does not fit in one section")
    wl = float(st.wall_displacement[0]) if chain.k[0] > 0 else 0.0
    v = np.where(mov, v, 0.0)
    return Initial(chain, u.copy(), v, wall_left=wl,
                   params={"kind": "exact_wave", "centre": c, "speed": w.speed,
                           "grain_rate": w.grain_rate, "velocity_max": w.velocity_max,
                           "amplitude": w.amplitude, "net_shift": w.net_shift,
                           "residual": w.residual})


def kdv_wave(chain: Chain, centre: float, strain_max: float, *,
             sample: str = "contacts", tail: float = 1e-12) -> Initial:
    r"""The KdV sech² solitary wave of the long-wave equation, as a chain state (right-going).

    :math:`\xi = A\,\mathrm{sech}^2(\kappa(x - x_0))`, :math:`\kappa^2 = A/(2\delta_0 d)`,
    v = V ξ with :math:`V = c_0\sqrt{1 + dA/(6\delta_0)}` (the corrected paper Eq. 4,
    docs/physics.md §2; :func:`theory.kdv_soliton_strain`, :func:`theory.kdv_soliton_motion`)
    for the grains and contact at ``centre`` (a precompressed region, δ0 > 0), its strain
    peak at contact ``centre`` (x measured in grains: contact j at j, grain i at i + ½).
    Where the continuum profile is *sampled* matters at the 1 % level (the lattice wave
    it settles into differs): ``sample`` is

    * ``"contacts"``: the overlaps are δ0 + d ξ at the contact positions, the
      displacements their sum from the right (u → 0 ahead), v_i = V ξ at grain i's
      centre;
    * ``"grains"``: u and v of the continuum wave at the grain centres, the overlaps
      their differences δ0 + u_{i-1} - u_i.

    Grains behind the wave and the left wall carry its net shift (as :func:`exact_wave`);
    velocities below ``tail`` × peak are set to 0.  ``strain_max``: the peak dynamic
    strain A = (r_max - δ0)/d (> 0).
    """
    from theory import c0 as sound_speed
    from theory import kdv_soliton_motion, kdv_soliton_strain, kdv_speed_exact

    c = float(centre)
    if not np.isfinite(c) or not 0 <= c <= chain.n:
        raise ValueError(f"centre {centre!r} outside the chain: contact index in [0, {chain.n}]")
    a = float(strain_max)
    if not (np.isfinite(a) and a > 0):
        raise ValueError(f"strain_max must be finite and > 0 (got {strain_max!r})")
    if sample not in ("contacts", "grains"):
        raise ValueError(f"sample must be 'contacts' or 'grains' (got {sample!r})")
    j = int(np.clip(round(c), 1, chain.n - 1))
    d, m, k, d0 = (float(chain.diameter[j]), float(chain.mass[j]), float(chain.k[j]),
                   float(chain.delta0[j]))
    if d0 <= 0:
        raise ValueError("the KdV wave needs precompression (delta0 > 0 at the centre)")
    c0_ = float(sound_speed(k, m, d, d0))
    xg = (np.arange(chain.n) + 0.5) * d  # grain centres, m
    xc = np.arange(chain.n + 1) * d      # contacts, m
    x0 = c * d
    if sample == "contacts":
        xi_c = np.asarray(kdv_soliton_strain(xc, a, d, d0, x0))
        dr = d * xi_c
        u = np.cumsum(dr[1:][::-1])[::-1]  # u_i = Σ_{j > i} (r_j - δ0)
        _, v = kdv_soliton_motion(xg, a, d, d0, c0_, x0)
        wl = float(u[0] + dr[0])
    else:
        u, v = kdv_soliton_motion(xg, a, d, d0, c0_, x0)
        wl = float(kdv_soliton_motion(-0.5 * d, a, d, d0, c0_, x0)[0])  # a grain -1
    u, v = np.asarray(u, float), np.asarray(v, float)
    vmax = float(np.max(np.abs(v)))
    if abs(v[0]) > tail * vmax or abs(v[-1]) > tail * vmax:
        raise ValueError(f"wave placed outside the chain: at centre {c} its tails (above "
                         f"{tail:g} of the peak) reach a chain end; move it inwards or "
                         "raise strain_max")
    mov = np.abs(v) > tail * vmax
    grains = np.flatnonzero(mov)
    for name, arr, val in (("mass", chain.mass[grains], m), ("k", chain.k[grains], k),
                           ("delta0", chain.delta0[grains], d0)):
        if np.any(np.abs(arr - val) > 1e-9 * abs(val)):
            raise ValueError(f"the chain's {name} under the KdV wave differs from that at "
                             "the centre: the wave does not fit in one section")
    v = np.where(mov, v, 0.0)
    return Initial(chain, u, v, wall_left=wl if chain.k[0] > 0 else 0.0,
                   params={"kind": "kdv_wave", "centre": c, "strain_max": a,
                           "sample": sample,
                           "speed": float(kdv_speed_exact(c0_, d, d0, a))})
