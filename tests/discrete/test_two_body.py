r"""Two-body reference tests: every contact law, and the drag, against the two-body ODE.

Two equal steel grains (d = 5 mm, paper material; free ends) meet at w0 = 1 m/s.  Their
relative coordinate obeys the two-body ODE

.. math:: \dot\delta = w,\qquad \mu\dot w = -F(\delta, w; k) - \mu\beta w

(μ = m/2 the reduced mass, F the law's force from its NumPy twin ``law.force``, β the
drag rate), solved by scipy's Radau at rtol 1e-12 with events at the maximum overlap
(w = 0) and at the separation (δ = 0 falling): the maximum overlap δ_max, the contact
time t_c and the coefficient of restitution e = -w(t_c)/w0.  The ODE reference is
itself checked against the closed forms of the power laws (below) and against a second
integrator (LSODA) for the dissipative cases.

The discrete solver runs at the step :class:`discrete.TimeStep` chooses for ``rtol``
(horizon: three contact times, or thirty times the time of the maximum overlap when
the grains stay in contact that long), recording the overlap maxima and the time
series of both grains (a time-resolved recording: the probe then compares the contact
times too).  Its contact time and restitution are read off the series at the
separation, by the cubic Hermite interpolant of δ and ṙ = v_0 - v_1 between the two
steps around it (error O(h⁴), far below the solver's O(h²)).  The claim checked:
every error is at most the solver's own estimate, ``error_estimate``, and that
estimate is at most rtol — δ_max and t_c relative, e in units of w0 (velocities
relative to the largest speed, as the estimate's).

Parameter ranges: power laws n = 1, 3/2, 2, 5/2 (k scaled so that every law has the
Hertz force at δ = 5 µm); Kuwabara–Kono from lossless (A = 0) to A = 1e3 s (overdamped
by ten orders of magnitude: the grains stick, the overlap creeps back over ~A);
drag β = 1e2 … 1e8 1/s.  Contact time and restitution are checked where the contact
ends within 5e-4 s (A <= 1e-4 s, β <= 1e5 1/s; longer creeps are beyond any run,
the contact lasts ≈ A), the maximum overlap everywhere.
"""

import math

import numpy as np
import pytest
import scipy.special as sp
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import theory
from discrete import (
    HERTZ,
    Chain,
    PowerLaw,
    Recording,
    Section,
    Simulation,
    TimeStep,
    ViscoelasticHertz,
)

MAT = theory.PAPER_MATERIAL
D = 5e-3
_PAIR = Chain.from_sections([Section(2, D, MAT)], delta0=0.0, left_wall=None,
                            right_wall=None)
KH, M = float(_PAIR.k[1]), float(_PAIR.mass[0])
MU = M / 2
W0 = 1.0
LONGEST_CONTACT = 5e-4
"""Contact time and restitution are checked when the contact ends before this, s."""

CASES = {
    **{f"power-{n:g}": (PowerLaw(n), KH * 5e-6 ** (1.5 - n), 0.0)
       for n in (1.0, 1.5, 2.0, 2.5)},
    **{f"kk-{a:g}": (ViscoelasticHertz(a), KH, 0.0)
       for a in (0.0, 1e-9, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-1, 10.0, 1e3)},
    **{f"drag-{b:g}": (HERTZ, KH, b) for b in (1e2, 1e4, 1e5, 1e6, 1e8)},
}


def reference(law, k: float, drag: float, *, method: str = "Radau",
              rtol: float = 1e-12) -> dict:
    """δ_max (m), its time (s) and, if the grains separate within 1 s, t_c (s) and e."""
    def rhs(t, y):
        d, w = y
        f = float(law.force(d, w, k)) if d > 0 else 0.0
        return [w, -f / MU - drag * w]

    def separation(t, y):
        return y[0]

    def peak(t, y):
        return y[1]

    separation.terminal, separation.direction = True, -1
    peak.direction = -1
    a = getattr(law, "damping_time", 0.0)
    sol = solve_ivp(rhs, (0.0, min(1.0, max(30 * a, 1e-3))), [0.0, W0], method=method,
                    rtol=rtol, atol=[1e-24, 1e-18], events=(separation, peak))
    out = {"dmax": float(sol.y_events[1][0][0]), "tmax": float(sol.t_events[1][0])}
    if sol.t_events[0].size:
        out["tc"] = float(sol.t_events[0][0])
        out["e"] = -float(sol.y_events[0][0][1]) / W0
    return out


def solver(law, k: float, drag: float, ref: dict, rtol: float) -> dict:
    """The discrete solver's δ_max, t_c and e at the step chosen for ``rtol``.

    The run records the overlap maxima and the time series of both grains (every step):
    t_c and e are read off the series (what the run records), at the first step where
    the overlap is <= 0, by the cubic Hermite interpolant of δ and ṙ = v_0 - v_1 over
    that step.
    """
    chain = Chain.from_arrays([M, M], [0.0, k, 0.0], 0.0, exponent=law.exponent,
                              diameter=D)
    v = np.array([W0, 0.0])
    ends = "tc" in ref and ref["tc"] < LONGEST_CONTACT
    t_end = 3.0 * ref["tc"] if ends else 30.0 * ref["tmax"]
    rec = Recording(maxima=True, strain_maxima=True, series_grains=(0, 1))
    step = TimeStep.choose(chain, None, v, rtol=rtol, law=law, drag=drag, horizon=t_end,
                           recording=rec)
    sim = Simulation(chain, v=v, dt=step, law=law, drag=drag, record=rec)
    sim.run(t_end, progress=False)
    out = {"step": step, "dmax": float(sim.record.overlap_max[1])}
    a = sim.record.arrays()
    t, series = a["series_t"], a["series"]
    r = series[:, 0, 3]  # grain 0's right contact: contact 1
    w = series[:, 0, 1] - series[:, 1, 1]
    opened = np.flatnonzero((r[1:] <= 0) & (r[:-1] > 0))
    if not ends:  # the reference keeps them in contact that long: so must the solver
        assert opened.size == 0 and r[-1] > 0
        return out
    i = int(opened[0])
    h, (r0, r1), (w0, w1) = t[i + 1] - t[i], r[i:i + 2], w[i:i + 2]

    def hermite(s, deriv=False):
        if deriv:
            return ((6 * s * s - 6 * s) * (r0 - r1) + (3 * s * s - 4 * s + 1) * h * w0
                    + (3 * s * s - 2 * s) * h * w1) / h
        return ((2 * s**3 - 3 * s * s + 1) * r0 + (s**3 - 2 * s * s + s) * h * w0
                + (-2 * s**3 + 3 * s * s) * r1 + (s**3 - s * s) * h * w1)

    x = brentq(hermite, 0.0, 1.0, xtol=1e-15)
    out["tc"] = t[i] + x * h
    out["e"] = -hermite(x, deriv=True) / W0
    return out


@pytest.fixture(scope="module")
def references():
    """The ODE references, computed once per case."""
    return {}


@pytest.mark.parametrize("rtol", [1e-3, 1e-4])
@pytest.mark.parametrize("case", list(CASES))
def test_two_body_meets_rtol(case, rtol, references):
    law, k, drag = CASES[case]
    if case not in references:
        references[case] = reference(law, k, drag)
    ref = references[case]
    got = solver(law, k, drag, ref, rtol)
    est = got["step"].error_estimate
    assert est <= rtol * (1 + 1e-9), (case, est)
    errors = {"dmax": abs(got["dmax"] / ref["dmax"] - 1)}
    if "tc" in got:
        errors["tc"] = abs(got["tc"] / ref["tc"] - 1)
        errors["e"] = abs(got["e"] - ref["e"])
    for name, err in errors.items():
        assert err <= est, (case, rtol, name, err, est, got["step"].dt)


@pytest.mark.parametrize("n", [1.0, 1.5, 2.0, 2.5])
def test_reference_is_exact_for_power_laws(n):
    # Two bodies with F = k δⁿ: energy conservation ½μw0² = kδ_max^{n+1}/(n+1) gives
    # δ_max, and t_c = 2∫0^δmax dδ/w = (2δ_max/w0) √π Γ(1 + 1/(n+1)) / Γ(1/2 + 1/(n+1))
    # (the half-period of the anharmonic oscillator; n = 1: π√(μ/k)); e = 1.
    # Tolerance 1e-10: the reference at rtol 1e-12 must be far below every rtol above.
    law, k, _ = CASES[f"power-{n:g}"]
    ref = reference(law, k, 0.0)
    dmax = ((n + 1) * MU * W0**2 / (2 * k)) ** (1 / (n + 1))
    tc = 2 * dmax / W0 * math.sqrt(math.pi) * sp.gamma(1 + 1 / (n + 1)) \
        / sp.gamma(0.5 + 1 / (n + 1))
    assert ref["dmax"] == pytest.approx(dmax, rel=1e-10)
    assert ref["tc"] == pytest.approx(tc, rel=1e-10)
    assert ref["e"] == pytest.approx(1.0, abs=1e-10)


@pytest.mark.parametrize("case", ["kk-1e-06", "kk-0.0001", "kk-1000", "drag-100000",
                                  "drag-1e+08"])
def test_reference_agrees_with_a_second_integrator(case):
    # The dissipative references (no closed form) against LSODA at rtol 1e-11: they
    # agree to 1e-8 (tolerance), four orders below the smallest rtol checked.
    law, k, drag = CASES[case]
    a, b = reference(law, k, drag), reference(law, k, drag, method="LSODA", rtol=1e-11)
    assert set(a) == set(b)
    for key in ("dmax", "tc"):
        if key in a:
            assert a[key] == pytest.approx(b[key], rel=1e-8), key
    if "e" in a:
        assert a["e"] == pytest.approx(b["e"], abs=1e-8)


@pytest.mark.parametrize(("n", "unit"), [(1.0, "N/m"), (1.5, "N/m^(3/2)"), (2.0, "N/m^2"),
                                         (2.5, "N/m^(5/2)")])
def test_saved_contact_constant_has_the_unit_of_its_law(tmp_path, n, unit):
    # F = k δⁿ (N, m): k is in N/m^n.  The HDF5 file wrote N/m^(3/2) for every exponent.
    import json

    import h5py

    from discrete import save

    law, k, _ = CASES[f"power-{n:g}"]
    chain = Chain.from_arrays([M, M], [0.0, k, 0.0], 0.0, exponent=n, diameter=D)
    sim = Simulation(chain, v=[W0, 0.0], law=law)
    sim.run(max_steps=10, progress=False)
    path = save(tmp_path / "pair.h5", sim)
    with h5py.File(path, "r") as f:
        assert f["chain/k"].attrs["units"] == unit
        assert json.loads(f.attrs["units"])["k"] == unit
