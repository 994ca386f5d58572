"""The discrete chain and a continuum model run side by side from one grain state.

Both are sampled per grain at the same times with the same definitions (kinetic energy
½ m v², contact energy U(δ) - U(δ0) of the law: continuum.sample_grains), and the
transmitted wave is measured on both the same way: its peak (parabola through the
three largest grain velocities right of the interface) and the energy right of the
interface contact.
"""

from dataclasses import dataclass

import numpy as np

import continuum
import discrete
import theory


@dataclass
class Samples:
    """Grain velocities (m/s), kinetic and potential energies per grain/contact (J)."""

    t: np.ndarray
    v: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray


def discrete_samples(chain, init, law, times, drag=0.0) -> Samples:
    sim = discrete.Simulation(chain, init.u, init.v, wall_left=init.wall_left,
                              wall_right=init.wall_right, law=law, drag=drag)
    v, ek, ep = [], [], []
    for t in times:
        if t > 0:
            sim.run(float(t), progress=False)
        r = sim.overlaps()
        v.append(sim.v.copy())
        ek.append(0.5 * chain.mass * sim.v**2)
        ep.append(law.energy(r, chain.k, chain.delta0))
    return Samples(np.asarray(times), np.array(v), np.array(ek), np.array(ep))


def continuum_samples(pde, init, times, method="position_yoshida4", safety=0.5):
    state = continuum.from_grains(pde, init.u, init.v)
    dt = pde.stable_dt(state, safety)
    v, ek, ep, drift = [], [], [], 0.0
    t0 = 0.0
    for t in times:
        if t > t0:
            res = continuum.run(pde, state, float(t - t0), dt=dt, method=method)
            state, t0 = res["state"], float(t)
            drift = max(drift, res.energy_drift)
        g = continuum.sample_grains(pde, state)
        v.append(g.v)
        ek.append(g.kinetic)
        ep.append(g.potential)
    return Samples(np.asarray(times), np.array(v), np.array(ek), np.array(ep)), drift


def peak(v: np.ndarray, start: int = 0) -> float:
    """Grain position of the largest v[start:] (parabola through three grains)."""
    i = start + int(np.argmax(v[start:]))
    if i <= 0 or i >= v.size - 1:
        return float(i)
    a, b, c = v[i - 1], v[i], v[i + 1]
    den = a - 2 * b + c
    return float(i + (0.5 * (a - c) / den if den != 0 else 0.0))


def right_energy(s: Samples, row: int, iface: int) -> float:
    """Energy of grains >= iface and contacts > iface (the interface contact half), J."""
    return float(s.kinetic[row, iface:].sum() + s.potential[row, iface + 1:].sum()
                 + 0.5 * s.potential[row, iface])


def total_energy(s: Samples, row: int) -> float:
    return float(s.kinetic[row].sum() + s.potential[row].sum())


def two_section_chain(n_left, n_right, alpha_rho, alpha_kn, delta0_over_d, law):
    d = theory.PAPER_DIAMETER
    secs = [discrete.Section(n_left, d, theory.PAPER_MATERIAL),
            discrete.Section(n_right, d, theory.PAPER_MATERIAL.scaled(alpha_rho, alpha_kn))]
    return discrete.Chain.from_sections(secs, delta0=delta0_over_d * d,
                                        exponent=law.exponent)


def transmitted(chain, law, iface, strain_max, model, *, lead=45, past=(40, 100), tail=1e-7,
                nodes=5, drag=0.0, **pde_kw):
    """Transmitted peak speed (grains/s) and energy fraction, discrete and continuum.

    The exact discrete solitary wave of peak dynamic strain ``strain_max`` starts
    ``lead`` grains before the interface; the transmitted peak is timed between
    ``past[0]`` and ``past[1]`` grains past it (times from the discrete run's linear
    sound speed, then both models sampled at the same times); the transmitted energy is
    taken at the later time, over the incident energy.
    """
    c0 = iface - lead
    init = discrete.exact_wave(chain, c0, strain_max=strain_max, law=law, tail=tail)
    med = chain.medium(law, drag)
    # the times at which the discrete wave's peak passes past[0], past[1] grains beyond
    # the interface (discrete.WaveAt)
    probe = discrete.Simulation(chain, init.u, init.v, wall_left=init.wall_left,
                                wall_right=init.wall_right, law=law, drag=drag)
    times = [0.0]
    for p in past:
        probe.run(1e6, until=iface + p, progress=False)
        times.append(probe.t)
    times = np.array(times)
    ds = discrete_samples(chain, init, law, times, drag)
    cls = continuum.MODELS[model]
    pde = cls(med, nodes, bc="free", **pde_kw)
    cs, drift = continuum_samples(pde, init, times)
    out = {}
    for name, s in (("discrete", ds), ("continuum", cs)):
        x1, x2 = peak(s.v[1], iface), peak(s.v[2], iface)
        out[name] = {"speed": (x2 - x1) / (times[2] - times[1]),
                     "energy": right_energy(s, 2, iface) / total_energy(s, 0),
                     "x1": x1, "x2": x2}
    out["drift"] = drift
    out["times"] = times
    return out


def rms_width(e: np.ndarray, half: int = 25) -> float:
    """RMS width (grains) of a per-grain energy profile within ``half`` grains of its peak."""
    x = np.arange(e.size, dtype=float)
    i = int(np.argmax(e))
    sel = slice(max(i - half, 0), i + half)
    w, xx = e[sel], x[sel]
    mu = (w * xx).sum() / w.sum()
    return float(np.sqrt((w * (xx - mu) ** 2).sum() / w.sum()))


def kinetic_peak_run(chain, init, law, start, past, pde, drag=0.0):
    """Peak speed (grains/s) from the kinetic-energy peak right of ``start``.

    Timed between the discrete wave's passing grains ``past[0]`` and ``past[1]``
    (discrete.WaveAt), for the discrete chain and ``pde``; also the RMS width of the
    kinetic energy at the later time.  Returns {model: {"speed", "width"}}, drift.
    """
    probe = discrete.Simulation(chain, init.u, init.v, wall_left=init.wall_left,
                                wall_right=init.wall_right, law=law, drag=drag)
    times = [0.0]
    for p in past:
        probe.run(1e6, until=p, progress=False)
        times.append(probe.t)
    times = np.array(times)
    ds = discrete_samples(chain, init, law, times, drag)
    cs, drift = continuum_samples(pde, init, times)
    out = {}
    for name, s in (("discrete", ds), ("continuum", cs)):
        x1, x2 = peak(s.kinetic[1], start), peak(s.kinetic[2], start)
        out[name] = {"speed": (x2 - x1) / (times[2] - times[1]),
                     "width": rms_width(s.kinetic[2, start:])}
    return out, drift
