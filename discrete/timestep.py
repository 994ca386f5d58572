r"""The time step: one owner of the default dt, the stability bound and the expected overlaps.

Every dt in the package is decided here, by :class:`TimeStep` (or the thin functions
:func:`default_dt`, :func:`stable_dt`, :func:`expected_overlaps` built on the same
code): the :class:`~discrete.Simulation`, the scenario runner and the benchmarks ask
it; nothing else computes a contact frequency.

Expected overlaps
-----------------
The largest overlap contact j is expected to reach: the present overlap with the
largest single-grain kinetic energy :math:`E_1 = \max_i \tfrac12 m_i v_i^2` added to its
elastic energy :math:`U(\delta) = k\delta^{n+1}/(n+1)` (J; for Hertz (2/5) k δ^{5/2}),

.. math:: \hat\delta_j = U^{-1}\big(U([r_j]_+) + E_1\big)

(:meth:`ContactLaw.overlap_with_energy <theory.laws.ContactLaw.overlap_with_energy>`).
For a vertical chain (gravity) the present overlap is taken at least at the force of
twice the static weight, :math:`2^{1/n}\delta_0` (a chain released uncompressed falls
onto its static overlaps and overshoots them).  For a dissipative law it is also at most
the overlap at which the damping alone absorbs the chain's momentum
(:func:`damping_overlaps`; "Dissipative time scales" below).

Default time step
-----------------
The linearised stiffness of contact j at overlap δ is :math:`K_j = \partial F/\partial
\delta` (N/m; Hertz: :math:`\tfrac32 k_j\delta^{1/2}`) and its two-body frequency
:math:`\omega_j = \sqrt{K_j (1/m_{j-1} + 1/m_j)}` (rad/s; one mass at a wall); a
dissipative law or drag adds the rate :math:`\gamma_j` (:func:`contact_rates`; next
section), and :math:`\Omega_j^2 = \omega_j^2 + 2\gamma_j^2` (= ω_j² bitwise without
them).  At the expected overlaps the default is

.. math:: \Delta t = f\,S\, \frac{2\pi}{\max_j \Omega_j},\qquad f = 0.002
   \ (\text{:data:`DT_FRACTION`}),

with S the force evaluations per step of the integrator (:mod:`discrete.integrators`;
the same force evaluations per unit time for every method).  Velocity Verlet is
linearly stable for :math:`\Delta t < 2/\omega_{\rm lat}` with
:math:`\omega_{\rm lat}^2 \le \max_i 2(K_i + K_{i+1})/m_i` (Gershgorin), i.e.
f < 0.225 for a uniform chain.  The dt study (``tests/discrete/test_dt_study.py``):
observables converge at second order (fitted slope ≈ 2).  The most dt-sensitive case
is the impact on a precompressed chain (δ0/d = 1e-3): its settled v̄max/v0 is
0.08241 / 0.08224 / 0.08220 at f = 0.01 / 0.005 / 0.0025 (relative error
≈ 2.9e-3 (f/0.01)²); f = 0.002 makes it ~1e-4.  Without precompression (f = 0.01:
error 7e-5) and for smooth solitary waves (cut or exact waves: energy conserved to
~1e-11 at f = 0.01) much larger steps would do.  For the paper's steel grains
(d = 5 mm, v0 = 1 m/s) f = 0.002 gives dt ≈ 4.4e-8 s, ~40× the paper's dt = 1e-9 s.

Dissipative time scales
-----------------------
Velocity-dependent forces (:class:`~theory.laws.ViscoelasticHertz`, drag) are solved
exactly in dissipative sub-steps between the elastic ones (:mod:`discrete.kernels`,
"Dissipation"): they never raise the kinetic energy, so they add no *stability* bound —
the elastic one above stands.  They bound the step for *accuracy* (docs/physics.md
§20).  Contact j's relative velocity relaxes at :math:`\gamma_j = c_j s_j + \beta`
(1/s; :math:`c_j` the law's damping coefficient ``law.damping`` at the expected
overlap, N·s/m, :math:`s_j = 1/m_{j-1} + 1/m_j`, β the drag).  For one contact, the
damped oscillator :math:`\ddot x + \gamma\dot x + \omega^2 x = 0`, the split step is
velocity Verlet's :math:`(\omega h)^2/24` off in frequency when underdamped; when
overdamped (γ > ω) the overlap creeps back at :math:`\omega^2/\gamma` and the split
step's creep is :math:`(x/2)\coth(x/2)` times that, x = γh — relatively
:math:`x^2/12` off, and x/2 for x ≫ 1 (the step that ignored γ: two grains with
A = 1e-2 s stuck at 1.08e-7 m instead of 3.92e-8 m).  Together about
:math:`(\Omega h)^2/24`, whence the default with :math:`\Omega_j`: the same
6.6e-6 as the lossless default.  An explicit step with :math:`\gamma_{max}\Delta t`
above :data:`DAMPING_STEP_LIMIT` (creep 8.2 % off) is refused (:meth:`TimeStep.check`).

Which overlap: γ grows with the overlap (Kuwabara–Kono: :math:`c = kA\sqrt\delta`), and
a heavily damped contact never reaches the energy bound.  While it closes its force is
at least :math:`c(\delta)\dot\delta`, so an impulse J stops it by :math:`\delta^*`
with :math:`\int_r^{\delta^*} c\,d\delta = J` (:func:`damping_overlaps`; exact for
two bodies with J = μw, Kuwabara–Kono :math:`\delta^* = (3\mu w/2kA)^{2/3}` where
:math:`\gamma = \tfrac32 w/\delta^*`, the inverse approach time); the expected
overlap is the smaller of the two bounds, with J the chain's total |momentum|
:math:`\sum_i m_i|v_i|`.  An overdamped contact also has a slow time, its creep time
:math:`\gamma_j/\omega_j^2` (:func:`creep_time`; Kuwabara–Kono 2A/3): the rtol probe
covers :data:`PROBE_CREEP` of them.

A stated accuracy instead of a dt (``rtol``)
--------------------------------------------
With ``rtol`` (and no explicit dt) the step is chosen so that the recorded quantities
carry a relative error of at most about ``rtol``, from an error that is *measured*, not
assumed (:func:`probe_error`).  A short probe — the run itself from its initial state,
with the run's own recording and kernel, for :data:`PROBE_PERIODS` shortest contact
periods :math:`T_c = 2\pi/\Omega_{max}` and at least :data:`PROBE_CREEP` creep times
of an overdamped contact (at most :data:`PROBE_CREEP_STEPS` steps for these; or to the
run's end if sooner; a whole number of steps, so that every probe run ends at the same
time) — is integrated at the steps :math:`h_k = h_0/2^k`, k = 0, 1, 2, …
(:math:`h_0` = :data:`PROBE_FRACTION` × S × :math:`T_c`).  The compared quantities q
are what the run records, each once it is *settled* — its peak passed (v < v̄max/2) or
grown by less than :data:`SETTLED_GROWTH` of itself over the probe's second half —
and over a scale common to both runs compared (the finer run's: a run's own scale
would hide the error of the maximum that sets it): every grain's running maximum of v
over the largest |v| (the Fig. 2 v̄max/v0, the *refined* maximum
``record.vmax_refined``, interpolated between the steps at the method's order — not the
largest sample ``record.vmax``, which stays O(h²) and is not what rtol bounds), every
loaded contact's (k > 0) running maximum overlap over the largest dynamic one when the
run records strain maxima, every contact's opening (contact) time when the run records
the trajectory (time series, sensors or wall forces) — read back along the free flight
since (drag included) from the probe's end and from its middle, where the two agree —
relative to itself, and the distance travelled by the energy centroid of the wave
(arrival times and speeds), relative.  The differences
:math:`d_k = \|q(h_k) - q(h_{k+1})\|_\infty` bound the error at each probe step
directly (triangle inequality),

.. math:: E_k = d_k + E_{k+1},\qquad E_K = d_{K-1}/(2^p - 1),

so only the error of the finest run is extrapolated, by Richardson's rule (G.
Dahlquist & Å. Björck, *Numerical Methods in Scientific Computing I*, SIAM 2008,
§3.4.2: for :math:`q(h) = q + C h^p + o(h^p)`, :math:`q(h) - q(h/2) = C h^p (1 -
2^{-p})`), with the observed order :math:`p = \log_2(d_{K-2}/d_{K-1})` if it is
*clean* — within :data:`ORDER_SLACK` of 2 (a maximum sampled once per step converges at
second order whatever the method) or of the method's order — and p = 1 (E_K = d_{K-1})
if it is not.  Between the probe steps E(h) is the power law through the neighbouring
points (below the finest, E_K (h/h_K)^p); the step is the largest h with

.. math:: E(h) \le s\,\mathrm{rtol},\qquad s = 0.6\ \text{or}\ 0.5\
   (\text{:func:`rtol_safety`}),

never above :math:`h_0` (no extrapolation beyond the probed steps), half the
stability bound, nor the step at which the probe's energy drift, extrapolated to the
run's length at the rate measured over the probe's second half
(:meth:`ProbeResult.drifts_at`), would reach :data:`RTOL_SAFETY` of the run's drift
tolerance (a fourth-order method at a large step can meet rtol in the maxima and still
fail the run's energy monitor: on the interface test problem, Blanes–Moan 4 at 8× the
default step drifts 1.3e-4 over the run).  Round-off takes its share: E(h) is
joined by the floor F(h) that round-off leaves after the run's N = T/h steps
(:func:`roundoff_floor`: :math:`u\sqrt N` for the velocities, :math:`u(N U +
\delta_0)/Q` for overlaps and contact times, u = 2^-53; docs/physics.md §20), the
step is the largest with :math:`(E(h) + F(h))/s \le` rtol, and that estimate is
written into the result (:attr:`TimeStep.error_estimate`) as estimated — never set to
rtol.  An rtol below F/s at the largest probe step (the fewest steps the run can take)
is refused before any probe run, and one that no step meets after the probe, each
with the achievable floor named (ValueError).  Finer probe steps are
added while the differences do not shrink (not yet asymptotic) or no probe step meets s·rtol, up to
:data:`PROBE_MAX_LEVELS` runs; an unstable probe run is dropped with the coarser ones.
The factor 1/s is needed: a recorded maximum has an error that depends on where the
peak falls within the step, so it is not a smooth function of h and the Richardson
estimate can fall short.  For a maximum sampled once per step (a dissipative run, or
``refined_maxima=False``), the overlap maxima and the contact times, s =
:data:`RTOL_SAFETY` = 0.5: on the test problems (impact, precompressed solitary wave,
interface; every method; rtol 1e-3 … 1e-5) the true error was 0.70–0.86 of E(h), and
1.29 of it once, where the sharper peak of the impacted grain 1 fell badly between two
steps; a run that reports energy ratios (a chain with an interface) keeps it too: they
are bounded through the drift, not compared, and their measurement window moves with
the energy grid's rows.  For the refined maxima (the cubic Hermite interpolant between
the steps,
:mod:`discrete.interpolation`: its error is the method's order, but its constant still
depends on the peak's phase within the step), with the distance travelled, s =
:data:`RTOL_SAFETY_REFINED` = 0.6: on the same problems and methods at rtol 1e-3,
1e-4 and 1e-5, against Blanes–Moan 4 at a 16× smaller step, the true error is
0.71–1.03 of E(h) but 1.41 of it for Blanes–Moan 4 on the impacts at rtol 1e-5 (the
impacted grain's peak again), so the achieved error stays below 0.85 rtol, and is
typically 0.5–0.6 rtol — the estimate reported, (E + F)/s, is within 2× of it.  The
estimate is of the maxima the run keeps (:attr:`TimeStep.maxima`: refined or
sampled; docs/physics.md §23).  ``integrator=None``
probes the methods of :data:`RTOL_CANDIDATES` — velocity Verlet, Yoshida-4 and
Blanes–Moan 4 — and takes the one with the fewest force evaluations per unit time,
S/h; a method's probe stops as soon as its differences show that it cannot beat the
best so far (E_k ≥ d_k + d_{k+1} + … excludes every step above h_k), or once
:data:`PREDICTION_SLACK` × its Richardson-predicted step would cost more; the methods
are probed from the highest order down, so that a fourth-order winner's cost stops the
others early.  Maxima sampled
once per step converge at second order whatever the method (all three would need about
the same h, and velocity Verlet would win); the refined maxima between the steps
converge at the method's order, so the 4th-order methods can win.  The
tests (``tests/discrete/test_rtol.py``) check that the estimate bounds the true error
(against a run at a 16× smaller step) for an impact, a precompressed solitary wave and
an interface run, for every method ``integrator=None`` can pick (there the true
error is 0.4–0.85 of the estimate at rtol 1e-3 … 1e-5 where the step is not capped
by h_0 or the drift), and ``tests/discrete/
test_two_body.py`` that it bounds the error of the maximum overlap, the contact time
and the coefficient of restitution of two grains against the two-body ODE for every
law over its whole range (power laws n = 1 … 5/2, Kuwabara–Kono A = 0 … 1e3 s, drag
1e2 … 1e8 1/s) at rtol 1e-3 and 1e-4.  An explicit dt wins over rtol.

The default is no rtol: the fixed fraction :data:`DT_FRACTION` above, whose error in
the most dt-sensitive recorded quantity of the paper's runs (v̄max/v0 of an impact on
a precompressed chain) is ≈ 1e-4 — the paper's figures are read to 3 digits and the
Table 2 tests compare to 1e-3, so 1e-4 leaves them a factor 10; ``rtol = 1e-4`` states
that accuracy for any problem and, for most problems, takes a larger step.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from theory.laws import ContactLaw, as_law

from .chain import Chain
from .integrators import Integrator, get_integrator
from .recording import Recording
from .reference import overlaps as _overlaps

__all__ = ["DT_FRACTION", "TimeStep", "ProbeResult", "default_fraction", "default_dt",
           "stable_dt", "expected_overlaps", "probe_error", "RTOL_SAFETY", "RTOL_CANDIDATES",
           "PROBE_PERIODS", "PROBE_FRACTION", "PROBE_MAX_LEVELS", "ORDER_SLACK",
           "error_bounds", "contact_rates", "damping_rate", "damping_overlaps",
           "roundoff_floor", "UNIT_ROUNDOFF", "DAMPING_STEP_LIMIT", "creep_time",
           "RTOL_SAFETY_REFINED", "rtol_safety",
           "PROBE_CREEP", "PROBE_CREEP_STEPS", "SETTLED_GROWTH"]

DT_FRACTION = 0.002
"""Default dt per force evaluation as a fraction of the shortest linearised contact
period (module docstring)."""

RTOL_SAFETY = 0.5
"""The step chosen for ``rtol`` aims at this fraction of rtol in the probe's error bound
where a compared quantity is sampled once per step (running maxima without refinement,
overlap maxima; a dissipative run) and for the energy drift; the reported estimate is the
bound / the safety (module docstring)."""

RTOL_SAFETY_REFINED = 0.6
"""The same where every compared quantity is a smooth function of the step: the refined
running maxima (between the steps, :mod:`discrete.interpolation`), arrival times and the
distance travelled (module docstring)."""

RTOL_CANDIDATES = ("verlet", "yoshida4", "blanes_moan4")
"""Methods probed when ``rtol`` is given without an integrator (cheapest first)."""

PROBE_MAX_LEVELS = 7
"""Most probe runs per method: steps h_0 … h_0/64."""

PROBE_RESTARTS = 8
"""Times the probe halves h_0 after an unstable probe run before giving up."""

ORDER_SLACK = 0.5
"""An observed order within this of 2 or of the method's order is "clean"."""

PROBE_PERIODS = 40.0
"""Length of the rtol probe in shortest contact periods 2π/ω_max."""

PROBE_FRACTION = 0.016
"""Largest probe step per force evaluation as a fraction of the shortest contact period."""

PROBE_CREEP = 4.0
"""The rtol probe covers at least this many creep times of the slowest overdamped contact
(:func:`creep_time`): an overdamped contact's overlap maximum, its opening and its
restitution are final only after its creep (two bodies, Kuwabara–Kono: the contact
ends after ≈ 1.6 creep times), and only a final quantity is compared."""

PROBE_CREEP_STEPS = 200_000
"""At most this many steps of h_0 for the creep (a slower creep is not probed: its
quantities are not final within the probe, so the estimate does not cover them)."""

SETTLED_GROWTH = 1e-3
"""A running maximum counts as settled in a probe run when it grew by less than this
fraction of itself over the probe's second half (module docstring)."""

DAMPING_STEP_LIMIT = 1.0
"""Largest γ_max Δt an explicit step may have (:meth:`TimeStep.check`): there the split
step's relaxation rate of an overdamped contact, (x/2) coth(x/2) times the exact one
with x = γΔt, is 8.2 % off (module docstring, "Dissipative time scales")."""


def default_fraction(integrator: str | Integrator = "verlet") -> float:
    """Default dt as a fraction of the shortest contact period: S × :data:`DT_FRACTION`."""
    return get_integrator(integrator).stages * DT_FRACTION


def expected_overlaps(chain: Chain, u=None, v=None, wall_left: float = 0.0,
                      wall_right: float = 0.0, *, law: ContactLaw | None = None) -> np.ndarray:
    r"""Largest expected overlap of each contact, m (module docstring).

    The energy bound :math:`U^{-1}(U([r]_+) + E_1)`; for a dissipative law also at most
    the overlap at which the damping alone has absorbed the impulse
    :math:`J = \sum_i m_i|v_i|` (:func:`damping_overlaps`; module docstring,
    "Dissipative time scales").
    """
    law = as_law(law)
    u = np.zeros(chain.n) if u is None else np.asarray(u, float)
    v = np.zeros(chain.n) if v is None else np.asarray(v, float)
    r = np.maximum(_overlaps(u, chain.delta0, wall_left, wall_right), 0.0)
    if chain.gravity:  # the chain may fall onto its static overlaps: 2 × the weight
        r = np.maximum(r, 2.0 ** (1.0 / law.exponent) * chain.delta0)
    e1 = float(np.max(0.5 * chain.mass * v**2))
    delta = law.overlap_with_energy(r, e1, chain.k)
    if law.dissipative:
        impulse = float(np.sum(chain.mass * np.abs(v)))
        delta = damping_overlaps(chain, r, delta, impulse, law=law)
    return delta


_GAUSS = np.polynomial.legendre.leggauss(16)
"""16-point Gauss–Legendre nodes and weights on [-1, 1] (the damping integrals)."""


def damping_overlaps(chain: Chain, r, upper, impulse: float, *,
                     law: ContactLaw) -> np.ndarray:
    r"""Overlap at which a contact's damping alone has absorbed ``impulse`` (N·s), m.

    While a contact closes (:math:`\dot\delta > 0`) its force is at least its damping
    force, :math:`F = \max(0, F_{el} + c\,\dot\delta) \ge c(\delta)\,\dot\delta`
    (:mod:`theory.laws`, "Dissipative laws"), so the impulse it transmits while
    closing from r to δ is at least :math:`\int_r^\delta c(x)\,dx`.  The overlap
    therefore stops growing before :math:`\delta^*` with
    :math:`\int_r^{\delta^*} c(x;k)\,dx = J` — exactly so for two bodies (J = μ w, the
    reduced mass times the approach speed; for Kuwabara–Kono
    :math:`\delta^* = (3\mu w/(2kA))^{2/3}`).  Solved per contact by Newton's method
    (the integral's derivative is c) kept inside a bisection bracket in [r, ``upper``],
    with a 16-point Gauss–Legendre rule for the integral of the law's NumPy twin
    ``law.damping``; ``upper`` where the integral over [r, upper] stays below J (weak
    damping: the energy bound ``upper`` is the tighter one).

    Parameters
    ----------
    chain : Chain
        The contact constants k.
    r, upper : (N+1,) arrays
        Present overlaps (m, >= 0) and the energy bound (m, >= r).
    impulse : float
        J, N·s (the chain's total |momentum| Σ m|v| for :func:`expected_overlaps`).
    law : ContactLaw
        A dissipative law (its ``damping`` twin, N·s/m).
    """
    r = np.asarray(r, float)
    upper = np.maximum(np.asarray(upper, float), r)
    k = np.broadcast_to(np.asarray(chain.k, float), r.shape)
    rows = np.unique(np.stack([r, upper, k], axis=1), axis=0, return_inverse=True)
    (ur, uu, uk), inverse = rows[0].T, np.ravel(rows[1])
    x, wq = _GAUSS

    def absorbed(lo, d, kk):  # ∫_lo^d c(x; k) dx per row, N·s
        half = 0.5 * (d - lo)
        nodes = (lo + half)[:, None] + half[:, None] * x[None, :]
        return half * (law.damping(nodes, kk[:, None]) @ wq)

    out = uu.copy()
    reach = absorbed(ur, uu, uk) > impulse  # else the energy bound stands
    r0, kk = ur[reach], uk[reach]
    lo, hi = r0.copy(), uu[reach]
    d = 0.5 * (lo + hi)
    for _ in range(24):  # Newton on ∫ c = J (its derivative: c), kept in the bracket
        g = absorbed(r0, d, kk) - impulse
        if not np.any(np.abs(g) > 1e-12 * impulse):
            break
        hi = np.where(g > 0, d, hi)
        lo = np.where(g > 0, lo, d)
        c = law.damping(d, kk)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = d - g / c
        inside = (c > 0) & (newton > lo) & (newton < hi)
        d = np.where(inside, newton, 0.5 * (lo + hi))
    out[reach] = d
    return out[inverse]


def _inv_mass_pairs(chain: Chain) -> np.ndarray:
    """1/m_{j-1} + 1/m_j per contact (one mass at a wall), 1/kg."""
    inv = np.zeros(chain.n + 1)
    inv[:-1] += 1.0 / chain.mass
    inv[1:] += 1.0 / chain.mass
    return inv


def contact_rates(chain: Chain, delta, *, law: ContactLaw | None = None,
                  drag: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    r"""Each contact's elastic frequency ω_j (rad/s) and dissipative rate γ_j (1/s).

    At overlaps ``delta`` (m), with :math:`s_j = 1/m_{j-1} + 1/m_j` (1/kg; one mass at a
    wall): :math:`\omega_j = \sqrt{K_j s_j}`, :math:`K_j = \partial F_{el}/\partial
    \delta` (``law.stiffness``, N/m), and :math:`\gamma_j = c_j s_j + \beta`, with
    :math:`c_j` the damping coefficient (``law.damping``, N·s/m) and β the drag rate
    (1/s): the rate at which the relative velocity of the contact's two grains relaxes
    (module docstring, "Dissipative time scales").  γ = 0 for a conservative law
    without drag.
    """
    law = as_law(law)
    delta = np.maximum(np.asarray(delta, float), 0.0)
    inv = _inv_mass_pairs(chain)
    omega = np.sqrt(law.stiffness(delta, chain.k) * inv)
    gamma = law.damping(delta, chain.k) * inv + float(drag)
    return omega, gamma


def _rate_max(chain: Chain, delta: np.ndarray, law: ContactLaw, drag: float = 0.0) -> float:
    """max_j Ω_j, Ω_j² = ω_j² + 2γ_j² (rad/s; module docstring): ω_max without damping."""
    kk = law.stiffness(delta, chain.k)
    w2 = kk * _inv_mass_pairs(chain)
    if law.dissipative or drag > 0:
        _, gamma = contact_rates(chain, delta, law=law, drag=drag)
        w2 = w2 + 2.0 * gamma**2
    return float(np.sqrt(np.max(w2)))


def damping_rate(chain: Chain, delta, *, law: ContactLaw | None = None,
                 drag: float = 0.0) -> float:
    """max_j γ_j at overlaps ``delta`` (m), 1/s (:func:`contact_rates`; 0: conservative)."""
    law = as_law(law)
    if not (law.dissipative or drag > 0):
        return 0.0
    return float(np.max(contact_rates(chain, delta, law=law, drag=drag)[1]))


def creep_time(chain: Chain, delta, *, law: ContactLaw | None = None,
               drag: float = 0.0) -> float:
    r"""The slowest relaxation time of the overdamped contacts at overlaps ``delta``, s.

    An overdamped contact (:math:`\gamma_j > \omega_j`, :func:`contact_rates`) relaxes
    in two stages: its relative velocity within 1/γ_j, then its overlap creeps back at
    the rate :math:`\omega_j^2/\gamma_j` (the slow root of :math:`\lambda^2 + \gamma
    \lambda + \omega^2 = 0`); for Kuwabara–Kono :math:`\gamma_j/\omega_j^2 = c/K =
    2A/3` whatever the overlap.  max_j γ_j/ω_j² over the loaded overdamped contacts; 0
    if there is none.
    """
    law = as_law(law)
    if not (law.dissipative or drag > 0):
        return 0.0
    omega, gamma = contact_rates(chain, delta, law=law, drag=drag)
    over = (omega > 0) & (gamma > omega)
    return float(np.max(gamma[over] / omega[over] ** 2, initial=0.0))


def stable_dt(chain: Chain, delta, *, law: ContactLaw | None = None,
              drag: float = 0.0) -> float:
    """Largest linearly stable step at overlaps ``delta`` (m), s (module docstring).

    ω_lat² ≤ max_i (K_i + K_{i+1})·2/m_i (Gershgorin bound on M⁻¹K; exact for a
    uniform chain, where ω_lat = 2√(K/m) is the zone-edge frequency), dt ≤ 2/ω_lat.
    Damping and ``drag`` add no *stability* bound: their sub-steps are exact flows that
    never raise the kinetic energy (module docstring, "Dissipative time scales"); they
    bound the step for accuracy instead (:func:`damping_rate`, :meth:`TimeStep.check`).
    ``drag`` is accepted for the callers' uniformity.
    """
    law = as_law(law)
    delta = np.maximum(np.asarray(delta, float), 0.0)
    kk = law.stiffness(delta, chain.k)
    w2 = float(np.max(2.0 * (kk[:-1] + kk[1:]) / chain.mass))
    return 2.0 / math.sqrt(w2) if w2 > 0 else math.inf


def refined_maxima(recording, velocity_dependent: bool = False) -> bool:
    """Whether an rtol run keeps (and its probe compares) refined running maxima.

    :class:`discrete.Simulation`'s rule for a step chosen for rtol: yes unless the
    recording says ``refined_maxima=False`` or the forces depend on the velocities (a
    dissipative law or drag: the split step stores the elastic acceleration, not dv/dt,
    so the Hermite interpolant of (v, a) is not the velocity between the steps).
    """
    return not velocity_dependent and (recording is None
                                       or recording.refined_maxima is not False)


def rtol_safety(recording, velocity_dependent: bool = False,
                energy_ratios: bool = False) -> float:
    """The safety factor s of the step rule (E(h) + F(h) <= s·rtol) for a run's recording.

    :data:`RTOL_SAFETY_REFINED` where every quantity the probe compares is smooth in the
    step — refined running maxima (:func:`refined_maxima`), no overlap maxima (sampled
    once per step), no contact opening times — and the run reports no energy ratios,
    else :data:`RTOL_SAFETY` (module docstring).  Energy ratios (``energy_ratios``) are
    not among the compared quantities: rtol bounds them through the energy drift, and
    their measurement window moves with the rows of the energy grid, so their error is
    not smooth in the step either.
    """
    timing = recording is not None and bool(recording.series_grains or recording.sensors
                                            or recording.wall_forces)
    strain = recording is not None and bool(recording.strain_maxima)
    smooth = (refined_maxima(recording, velocity_dependent)
              and not (timing or strain or energy_ratios))
    return RTOL_SAFETY_REFINED if smooth else RTOL_SAFETY


def _probe_recording(recording, velocity_dependent: bool = False) -> Recording:
    """The probe's recording: the run's own, without what only costs time in a probe.

    Same kernel variant and maxima as the run (refined maxima: an rtol run keeps them,
    unless its recording says ``refined_maxima=False``, or its forces depend on the
    velocities — a dissipative law or drag, where :class:`discrete.Simulation` keeps
    sampled maxima only); no events, series, sensors, energy grid.
    """
    refined = refined_maxima(recording, velocity_dependent)
    if recording is None:
        return Recording(maxima=True, refined_maxima=refined)
    return dataclasses.replace(recording, snapshots=(), series_grains=(), energy_every=None,
                               sensors=(), wall_forces=False, maxima=True,
                               refined_maxima=refined)


class _ProbeRun:
    """One probe run at step h: the compared quantities of the run's recording."""

    def __init__(self, chain, u, v, wl, wr, law, drag, method, h, nsteps, recording,
                 delta_expected, timing: bool = True):
        from .simulation import Simulation

        sim = Simulation(chain, u, v, dt=h, wall_left=wl, wall_right=wr, record=recording,
                         integrator=method.name, law=law, drag=drag, check_dt=False)
        x0 = _centroid(sim)
        rec = sim.record
        # every level ends at the same time; in two halves, so that the drift's growth
        # over the second half is measured (ProbeResult.drifts_at), and the maxima that
        # no longer changed over it are known (settled)
        first = sim.run(max_steps=nsteps // 2, progress=False)
        vmax_mid = np.array(rec.vmax if rec.vmax_refined is None else rec.vmax_refined,
                            float)
        omax_mid = None if rec.overlap_max is None else np.array(rec.overlap_max, float)
        self.umax_mid = float(np.max(np.abs(sim.u), initial=0.0))
        topen_mid = _opening_times(sim, drag)
        late = sim.run(max_steps=nsteps - nsteps // 2, progress=False)

        def measure(info):  # the energy monitor's (Verlet's modified energy, else E)
            return float(info.shadow_drift if method.name == "verlet" else info.energy_drift)

        self.drift_late = measure(late)
        self.drift = measure(first) + self.drift_late  # >= the drift over the probe
        # the refined maxima (between the steps, at the method's order), not the samples
        vmax = np.asarray(rec.vmax if rec.vmax_refined is None else rec.vmax_refined, float)
        scale = float(np.max(np.abs(vmax))) or 1.0
        self.steps = sim.steps
        self.umax = float(np.max(np.abs(sim.u), initial=0.0))
        self.travel = _centroid(sim) - x0
        self.vmax, self.vscale = vmax, scale
        # a maximum counts once it is final: the grain's peak has passed (v below half
        # of it) or the running maximum did not change over the probe's second half; a
        # grain still rising at the probe's end holds its present v, a phase error
        settled = vmax - vmax_mid <= SETTLED_GROWTH * np.abs(vmax)
        self.done = ((sim.v < 0.5 * vmax) | settled) & (np.abs(vmax) > 0.01 * scale)
        # (a time-resolved recording) the contacts that opened for good, their grains in
        # free flight since: the opening time read back along the free flight from the
        # end state and from the mid-probe state agree (to SETTLED_GROWTH), with a gap
        # of at least 1 % of the expected dynamic overlap: their contact times
        r = sim.overlaps()
        self.topen = _opening_times(sim, drag)
        with np.errstate(invalid="ignore"):
            self.tdone = (timing & (chain.k > 0)
                          & (-r > 0.01 * (delta_expected - chain.delta0))
                          & (np.abs(self.topen - topen_mid)
                             <= SETTLED_GROWTH * np.abs(self.topen))
                          & (self.topen > 0))
        self.omax = self.odone = None
        self.oscale = 0.0
        if rec.overlap_max is not None:  # strain maxima: the dynamic part, relative
            # only contacts that carry a force (k > 0): a free end's "overlap" is the end
            # grain's displacement, no strain
            loaded = chain.k > 0
            omax = np.asarray(rec.overlap_max, float)
            dyn = omax - chain.delta0
            self.oscale = float(np.max(np.abs(dyn[loaded]), initial=0.0))
            self.omax = dyn
            now = sim.overlaps() - chain.delta0
            settled = omax - omax_mid <= SETTLED_GROWTH * np.abs(dyn)
            self.odone = (loaded & ((now < 0.5 * dyn) | settled)
                          & (np.abs(dyn) > 0.01 * self.oscale))

    def difference(self, other: _ProbeRun, done: np.ndarray,
                   odone: np.ndarray | None, tdone: np.ndarray | None = None) -> float:
        """max-norm of the differences of the compared quantities, relative.

        Both runs' maxima over the *same* scale, ``other``'s (the finer run's) largest
        |v| and largest dynamic overlap: a run's own scale would hide the error of the
        maximum that sets it (a single contact compared with itself, 1 = 1).
        """
        d = float(np.max(np.abs(self.vmax[done] - other.vmax[done]), initial=0.0)) \
            / other.vscale
        if odone is not None and self.omax is not None and other.omax is not None:
            d = max(d, float(np.max(np.abs(self.omax[odone] - other.omax[odone]),
                                    initial=0.0)) / (other.oscale or 1.0))
        if tdone is not None and np.any(tdone):  # contact times, relative
            d = max(d, float(np.max(np.abs(self.topen[tdone] - other.topen[tdone])
                                    / other.topen[tdone])))
        return max(d, abs(self.travel - other.travel) / max(abs(other.travel), 1.0))


def _opening_times(sim, drag: float) -> np.ndarray:
    r"""When each open, opening contact opened, if its grains flew freely since, s.

    A contact with gap r < 0 opening at :math:`\dot r = v_{j-1} - v_j < 0` (a wall at
    rest: v = 0), both grains in free flight under the drag β since it opened at
    :math:`t_o`: :math:`\dot r(t) = \dot r_o e^{-\beta(t - t_o)}`, :math:`r = (\dot r_o
    / \beta)(1 - e^{-\beta(t - t_o)})`, so :math:`t - t_o = \ln(1 + \beta r/\dot r)/\beta`
    (β → 0: r/ṙ).  nan where the contact is closed or closing.
    """
    r = sim.overlaps()
    v = np.r_[0.0, sim.v, 0.0]
    rd = v[:-1] - v[1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        x = r / rd
        back = np.log1p(drag * x) / drag if drag > 0 else x
        return np.where((r < 0) & (rd < 0), sim.t - back, np.nan)


def _centroid(sim) -> float:
    """Energy centroid of a simulation's active window, grains (0 if it holds no energy)."""
    lo, hi = sim.window
    if lo < 0:
        return 0.0
    ek, ep = sim.grain_energy()
    e = ek[lo:hi + 1] + ep[lo:hi + 1]
    tot = float(np.sum(e))
    return lo + float(np.dot(np.arange(e.size, dtype=float), e) / tot) if tot > 0 else 0.0


UNIT_ROUNDOFF = 2.0**-53
"""Unit round-off u of IEEE 754 double precision (round to nearest), relative."""


def roundoff_floor(steps: int, *, displacement: float = 0.0, strain: float = 0.0,
                   delta0: float = 0.0) -> float:
    r"""The relative error round-off alone leaves in the compared quantities after N steps.

    Every step rounds every stored u and v once (relative error at most u =
    :data:`UNIT_ROUNDOFF`).  The velocity increments h·a change from step to step, so
    their roundings behave as independent and accumulate as a random walk (Henrici's
    statistical law of round-off propagation, P. Henrici, *Discrete Variable Methods
    in Ordinary Differential Equations*, Wiley 1962; Brouwer's law for the energy,
    Hairer, McLachlan & Razakarivony, BIT 48 (2008) 231): a velocity maximum, relative
    to the largest speed, carries :math:`u\sqrt N` (0.3–1.3 of it on an impact,
    ``tests/discrete/test_rtol.py``).  A displacement increment h·v repeats itself in
    free flight and is then rounded the same way step after step: the rounding of u, at
    most :math:`u\,U` per step (U the largest displacement, m), accumulates linearly,
    :math:`u\,N\,U` (the worst case; a pair flying apart reaches 1/10 of it, 10 times
    the random walk).  An overlap :math:`\delta_{0,j} + u_{j-1} - u_j` and a contact
    time (its gap over its opening speed) carry that over the dynamic overlap scale Q
    (m), plus one rounding of :math:`\delta_0`: :math:`u(N U + \delta_0)/Q` — large when
    the grains travel far compared with their overlaps (a pair flying apart) or a small
    wave rides on a large precompression.

    Parameters
    ----------
    steps : int
        N, the run's number of steps.
    displacement : float
        U, m.
    strain : float
        Q, m; 0: velocities only.
    delta0 : float
        The largest static overlap, m.

    Returns
    -------
    float
        :math:`\max(u\sqrt N,\ u(N U + \delta_0)/Q)`, relative.
    """
    n = max(int(steps), 1)
    floor = UNIT_ROUNDOFF * math.sqrt(n)
    if strain > 0:
        floor = max(floor, UNIT_ROUNDOFF * (n * abs(displacement) + abs(delta0)) / strain)
    return floor


@dataclass(frozen=True)
class ProbeResult:
    """The measured error of a method's recorded quantities as a function of the step.

    Built by :func:`probe_error`; :meth:`error_at` and :meth:`step_for` read it (module
    docstring, "A stated accuracy").

    Attributes
    ----------
    method : str
        The integrator probed.
    h : tuple of float
        The probe steps h_0 > h_1 > ... (h_k = h_0 / 2^k), s.
    errors : tuple of float
        The error bound E_k at each probe step (relative, before the safety factor).
    differences : tuple of float
        d_k = ||q(h_k) - q(h_{k+1})||_∞, relative.
    order_observed : float
        log2(d_{K-2}/d_{K-1}) of the two finest differences (nan if undetermined).
    order : float
        The order used below the finest step (the observed one clipped to [1, method
        order] if it is clean, else 1).
    clean : bool
        The observed order is within :data:`ORDER_SLACK` of 2 (a quantity sampled once
        per step) or of the method's order.
    t_probe : float
        Length of each probe run, s.
    probe_steps : int
        Steps taken in all probe runs.
    compared : int
        Grains whose maxima were compared.
    complete : bool
        False if the probe stopped early because the method could not beat ``max_cost``.
    drifts : tuple
        Relative energy drift of each probe run (the run's energy monitor's measure,
        a bound: the first half's plus the second half's), for :meth:`step_for_drift`.
    drifts_late : tuple
        The drift of each probe run over its second half alone (from the state at
        t_probe/2): the growth rate :meth:`drifts_at` extrapolates with.
    compared_contacts : int
        Contacts whose overlap maxima were compared (0 without strain maxima).
    displacement, displacement_late : float
        max_i |u_i| at the finest probe run's end, and its growth over the probe's
        second half, m (:meth:`roundoff_at` extrapolates the displacements with it).
    strain_scale : float
        The largest dynamic overlap max_j (δ_max,j - δ0_j) of the loaded contacts in the
        finest probe run (the expected one, :func:`expected_overlaps`, without strain
        maxima), m: the scale of the overlaps and contact times (:meth:`roundoff_at`).
    delta0_max : float
        The largest static overlap, m (its rounding enters every overlap).
    """

    method: str
    h: tuple
    errors: tuple
    differences: tuple
    order_observed: float
    order: float
    clean: bool
    t_probe: float
    probe_steps: int
    compared: int
    complete: bool = True
    drifts: tuple = ()
    drifts_late: tuple = ()
    compared_contacts: int = 0
    displacement: float = 0.0
    displacement_late: float = 0.0
    strain_scale: float = 0.0
    delta0_max: float = 0.0

    def roundoff_at(self, h: float, horizon: float | None = None) -> float:
        """The round-off floor of the compared quantities at step h over ``horizon``, relative.

        :func:`roundoff_floor` with N = horizon/h steps (the probe's length when no
        horizon is given) and the displacements grown to the horizon at the rate the
        probe measured over its second half (as :meth:`drifts_at` grows the drifts).
        """
        t = self.t_probe
        if horizon is not None and math.isfinite(horizon) and horizon > t:
            t = float(horizon)
        grow = max(self.displacement_late, 0.0) * 2.0 * max(t - self.t_probe, 0.0) \
            / self.t_probe if self.t_probe > 0 else 0.0
        return roundoff_floor(math.ceil(t / h), displacement=self.displacement + grow,
                              strain=self.strain_scale, delta0=self.delta0_max)

    def drifts_at(self, horizon: float | None) -> tuple:
        """Each probe run's drift extrapolated to a run of length ``horizon`` (s).

        D(T) = D(t_p) + (T - t_p) · D_late / (t_p / 2): the drift keeps growing at the
        rate the probe measured over its second half (t_p the probe's length, D_late
        the drift from t_p/2 to t_p; the first half holds the wave's formation).  A
        drift that accumulates steadily (contacts closing one after another) is
        extrapolated linearly; one that has settled (a solitary wave's modified energy
        error is bounded, Hairer, Lubich & Wanner 2006, §IX) is not inflated by the
        run's length.  On the impact of ``benchmarks/rtol.py`` (velocity Verlet,
        default step) the run's drift is 2.70e-6 at 600, 2,000 and 5,000
        grains, the same at 8 times the length, which a linear scaling of the
        whole drift (T / t_p) would overestimate by T / t_p.  ``drifts``
        for a horizon of None, not finite, or not beyond t_p.
        """
        if (horizon is None or not math.isfinite(horizon) or horizon <= self.t_probe
                or len(self.drifts_late) != len(self.drifts)):
            return self.drifts
        grow = 2.0 * (float(horizon) - self.t_probe) / self.t_probe
        return tuple(d + grow * dl for d, dl in zip(self.drifts, self.drifts_late,
                                                       strict=True))

    @property
    def h0(self) -> float:
        """The largest probe step, s (no step above it is ever chosen)."""
        return self.h[0]

    def error_at(self, h: float) -> float:
        """The estimated relative error at step h <= h_0 (before the safety factor).

        Piecewise power law through the probe points (h_k, E_k); below the finest step
        E_K (h/h_K)^order; inf above h_0 (no extrapolation beyond the probe).
        """
        hs, es = self.h, self.errors
        if h > hs[0] * (1 + 1e-12):
            return math.inf
        if h <= hs[-1]:
            return es[-1] * (h / hs[-1]) ** self.order
        k = next(i for i in range(1, len(hs)) if h >= hs[i])
        lo, hi = es[k], es[k - 1]
        if lo <= 0 or hi <= lo:
            return hi if h > hs[k] else lo
        return lo * (h / hs[k]) ** (math.log(hi / lo) / math.log(hs[k - 1] / hs[k]))

    def step_for(self, target: float) -> float:
        """The largest step h <= h_0 whose estimated error is <= ``target``, s."""
        hs, es = self.h, self.errors
        if es[0] <= target:
            return hs[0]
        k = next((i for i in range(len(hs)) if es[i] <= target), None)
        if k is None:  # below the finest probe step: its power law
            if es[-1] <= 0:
                return hs[-1]
            return hs[-1] * (target / es[-1]) ** (1.0 / self.order)
        lo, hi = es[k], es[k - 1]
        if lo <= 0:
            return hs[k]
        q = math.log(hi / lo) / math.log(hs[k - 1] / hs[k])
        return min(hs[k - 1], hs[k] * (target / lo) ** (1.0 / q))

    def drift_at(self, h: float, horizon: float | None = None) -> float:
        """The drift expected at step h over a run of length ``horizon`` (relative).

        The power law through the neighbouring probe steps' extrapolated drifts
        (:meth:`drifts_at`), below the finest ∝ h² (as :meth:`step_for_drift` reads
        them); inf above h_0, 0 without drifts.
        """
        if not self.drifts:
            return 0.0
        ds = self.drifts_at(horizon)
        hs = self.h[:len(ds)]
        if h > hs[0] * (1 + 1e-12):
            return math.inf
        if h <= hs[-1]:
            return ds[-1] * (h / hs[-1]) ** 2
        k = next(i for i in range(1, len(hs)) if h >= hs[i])
        lo, hi = ds[k], ds[k - 1]
        if lo <= 0 or hi <= lo:
            return max(lo, hi)
        return lo * (h / hs[k]) ** (math.log(hi / lo) / math.log(hs[k - 1] / hs[k]))

    def step_for_drift(self, cap: float, horizon: float | None = None) -> float:
        """The largest step the probe's energy drifts allow: drift <= ``cap``, s.

        The drifts are those extrapolated to a run of length ``horizon``
        (:meth:`drifts_at`; None: the probe's own).

        Between two probe steps the power law through their measured drifts (as
        :meth:`step_for` reads the errors: a drift that grows like h^q, q the local
        slope; was the coarser probe step that met the cap, which threw away up to a
        factor 2 of the step — on the 2,000-grain impact Blanes–Moan 4's drifts
        8.3e-5 and 4.8e-6 at h_0 and h_0/2 allowed only h_0/2 for a cap of 5e-5, the
        power law 0.89 h_0); below the finest, its drift scaled as h² (every method
        here is at least second order in the energy, so the true drift at the smaller
        step is no larger).  inf without drifts.
        """
        if not self.drifts:
            return math.inf
        ds = self.drifts_at(horizon)
        hs = self.h[:len(ds)]
        if ds[0] <= cap:
            return hs[0]
        for k in range(1, len(ds)):
            if ds[k] <= cap:
                lo, hi = ds[k], ds[k - 1]
                if lo <= 0:
                    return hs[k]
                q = math.log(hi / lo) / math.log(hs[k - 1] / hs[k])  # hi > cap >= lo
                return min(hs[k - 1], hs[k] * (cap / lo) ** (1.0 / q))
        return hs[-1] * math.sqrt(cap / ds[-1])

    def to_dict(self) -> dict:
        """JSON-able scalars and tuples."""
        return dataclasses.asdict(self)


def probe_error(chain: Chain, u=None, v=None, wall_left: float = 0.0,
                wall_right: float = 0.0, *, integrator: str | Integrator = "verlet",
                law: ContactLaw | None = None, drag: float = 0.0,
                h0: float | None = None, horizon: float | None = None,
                recording=None, target: float | None = None,
                max_cost: float = math.inf) -> ProbeResult:
    """Measure the error of the recorded quantities against the step (module docstring).

    Parameters
    ----------
    chain, u, v, wall_left, wall_right, law, drag
        The run's chain, initial state (m, m/s), walls (m), contact law and drag (1/s).
    integrator : str or Integrator
        The method probed.
    h0 : float, optional
        Largest probe step, s; default :data:`PROBE_FRACTION` × S × 2π/ω_max (at most
        half the stability bound).
    horizon : float, optional
        The run's length, s: the probe is never longer.
    recording : Recording, optional
        The run's recording: the probe records (and compares) what it records, through
        the same kernel (its events, series, sensors and energy grid are left out).
    target : float, optional
        The error wanted (relative, after the safety factor): finer probe steps are
        added (up to :data:`PROBE_MAX_LEVELS`) until one meets it.
    max_cost : float
        Force evaluations per second of the best method so far: the probe stops
        (``complete=False``) as soon as this method is known to need more.

    Returns
    -------
    ProbeResult
    """
    from .simulation import InstabilityError

    law = as_law(law)
    method = get_integrator(integrator)
    delta = expected_overlaps(chain, u, v, wall_left, wall_right, law=law)
    w = _rate_max(chain, delta, law, drag)
    if not w > 0:
        raise ValueError("cannot probe the error: no contact is loaded and nothing moves")
    period = 2.0 * math.pi / w
    stable = stable_dt(chain, delta, law=law, drag=drag)
    if h0 is None:
        h0 = min(PROBE_FRACTION * method.stages * period, 0.5 * stable)
    # at least PROBE_PERIODS shortest periods, and PROBE_CREEP creep times of an
    # overdamped contact (at most PROBE_CREEP_STEPS steps of h0), never beyond the run
    t_probe = max(PROBE_PERIODS * period,
                  min(PROBE_CREEP * creep_time(chain, delta, law=law, drag=drag),
                      PROBE_CREEP_STEPS * h0))
    if horizon is not None and math.isfinite(horizon) and horizon > 0:
        t_probe = min(t_probe, float(horizon))
    rec = _probe_recording(recording, bool(law.dissipative or drag))
    # a time-resolved recording (series, sensors, wall forces) records the trajectory:
    # its timing — when each contact opened — is compared too
    timing = recording is not None and bool(recording.series_grains or recording.sensors
                                            or recording.wall_forces)
    stages = method.stages
    # whole steps at h0: every probe run ends at the same time (a probe run that ended
    # up to a step later would carry a first-order "error" in the travelled distance)
    bounded = horizon is not None and math.isfinite(horizon) and horizon > 0
    n0 = max(1, math.floor(t_probe / h0) if bounded else math.ceil(t_probe / h0))
    t_probe = n0 * h0
    runs: list[_ProbeRun] = []
    steps = 0

    loaded = chain.k > 0
    delta0_max = float(np.max(chain.delta0[loaded], initial=0.0))
    q_expected = float(np.max((delta - chain.delta0)[loaded], initial=0.0))

    def result(complete: bool = True) -> ProbeResult:
        done = np.logical_and.reduce([r.done for r in runs])
        odone = (None if runs[0].odone is None
                 else np.logical_and.reduce([r.odone for r in runs]))
        tdone = np.logical_and.reduce([r.tdone for r in runs])
        d = [runs[k].difference(runs[k + 1], done, odone, tdone)
             for k in range(len(runs) - 1)]
        hs = tuple(h0 / 2.0**k for k in range(len(runs)))
        e, p_obs, p, clean = error_bounds(d, method.order)
        fine = runs[-1]
        return ProbeResult(method.name, hs, e, tuple(d), p_obs, p, clean, t_probe, steps,
                           int(np.count_nonzero(done)), complete,
                           tuple(r.drift for r in runs), tuple(r.drift_late for r in runs),
                           0 if odone is None else int(np.count_nonzero(odone)),
                           fine.umax, fine.umax - fine.umax_mid,
                           q_expected if odone is None else fine.oscale, delta0_max)

    restarts = 0
    while True:
        # even its largest step cannot beat the best so far (checked again after an
        # unstable h_0 was halved: otherwise a method unstable at its largest probe steps,
        # e.g. Yoshida-4 on a 2,000-grain impact, goes on to finer levels it cannot win at)
        if not runs and stages / h0 >= max_cost:
            return ProbeResult(method.name, (h0,), (math.inf,), (), math.nan, 1.0, False,
                               t_probe, steps, 0, False)
        h = h0 / 2.0**len(runs)
        try:
            run = _ProbeRun(chain, u, v, wall_left, wall_right, law, drag, method, h,
                            n0 * 2 ** len(runs), rec, delta, timing)
        except InstabilityError:  # too coarse: drop it (and any coarser) and go finer
            restarts += 1
            if restarts > PROBE_RESTARTS:
                raise RuntimeError("the rtol probe went unstable at every step tried; "
                                   "give dt") from None
            n0 *= 2 ** (len(runs) + 1)
            h0, runs = h / 2.0, []
            continue
        runs.append(run)
        steps += run.steps
        if len(runs) < 2:
            continue
        pr = result()
        if stages / _upper_step(pr, target) >= max_cost:
            return dataclasses.replace(pr, complete=False)  # cannot beat the best so far
        if stages / (PREDICTION_SLACK * _predicted_step(pr, target, method.order)) \
                >= max_cost:
            return dataclasses.replace(pr, complete=False)  # will not beat it
        if len(runs) < 3:
            continue
        # finer while the differences do not shrink (not yet asymptotic) or no probe step
        # meets the target; never more than PROBE_MAX_LEVELS runs
        # or the differences reached the round-off floor of the probe runs (two runs'
        # round-off: finer probe steps only measure more of it)
        converging = pr.differences[-1] < pr.differences[-2]
        at_floor = pr.differences[-1] <= 2.0 * pr.roundoff_at(pr.h[-1])
        meets = target is None or pr.errors[-1] <= target
        if (converging and meets) or at_floor or len(runs) >= PROBE_MAX_LEVELS:
            return pr


def error_bounds(differences, method_order: int) -> tuple[tuple, float, float, bool]:
    """(E_k, observed order, order used, clean) from the differences d_k (module docstring).

    ``differences`` are d_k = ||q(h_k) - q(h_{k+1})|| for h_k = h_0/2^k (at least one);
    E_k = d_k + E_{k+1} and E_K = d_{K-1}/(2^p - 1) with p the observed order
    log2(d_{K-2}/d_{K-1}) clipped to [1, method order] if it lies within
    :data:`ORDER_SLACK` of 2 or of the method's order, else p = 1.
    """
    d = [float(x) for x in differences]
    if not d:
        raise ValueError("error_bounds needs at least one difference (two probe runs)")
    p_obs = math.nan
    if len(d) >= 2 and d[-1] > 0 and d[-2] > 0:
        p_obs = math.log2(d[-2] / d[-1])
    clean = math.isfinite(p_obs) and any(abs(p_obs - q) <= ORDER_SLACK
                                         for q in {2.0, float(method_order)})
    p = min(max(p_obs, 1.0), float(method_order)) if clean else 1.0
    e = [d[-1] / (2.0**p - 1.0)]
    for dk in reversed(d):
        e.append(dk + e[-1])
    return tuple(reversed(e)), p_obs, p, clean


def _refuse_below_floor(chain, u, v, wall_left, wall_right, *, rtol, law, drag, horizon,
                        stages, safety: float = RTOL_SAFETY) -> None:
    """ValueError, before any probe run, if round-off alone exceeds ``safety`` × rtol.

    The fewest steps the run can take are its length (``horizon``, else the probe's,
    :data:`PROBE_PERIODS` shortest contact periods) over the largest probe step
    (:data:`PROBE_FRACTION` × S × 2π/Ω_max, at most half the stability bound); the
    displacements are at least the initial ones and the dynamic overlaps at most the
    expected ones (:func:`expected_overlaps`), so :func:`roundoff_floor` of these is a
    lower bound of the run's round-off floor.  The step chosen for rtol keeps the
    truncation error plus the floor within s × rtol (:func:`_rtol_step`, s the run's
    :func:`rtol_safety`), so an rtol below floor / s cannot be met whatever the step.
    """
    delta = expected_overlaps(chain, u, v, wall_left, wall_right, law=law)
    w = _rate_max(chain, delta, law, drag)
    if not w > 0:
        return  # probe_error names it
    period = 2.0 * math.pi / w
    h_max = min(PROBE_FRACTION * stages * period,
                0.5 * stable_dt(chain, delta, law=law, drag=drag))
    t = PROBE_PERIODS * period
    if horizon is not None and math.isfinite(horizon) and horizon > 0:
        t = float(horizon)
    loaded = chain.k > 0
    strain = float(np.max((delta - chain.delta0)[loaded], initial=0.0))
    u0 = 0.0 if u is None else float(np.max(np.abs(u), initial=0.0))
    floor = roundoff_floor(math.ceil(t / h_max), displacement=u0, strain=strain,
                           delta0=float(np.max(chain.delta0[loaded], initial=0.0)))
    if floor > safety * rtol:
        least = floor / safety
        raise ValueError(
            f"rtol = {rtol:g} is below what float64 can deliver for this run: round-off "
            f"alone, accumulated over its at least {math.ceil(t / h_max):,} steps "
            f"(discrete.timestep.roundoff_floor: u·√N for the velocities, u·(N·U + δ0)/Q "
            f"for the overlaps and contact times, u = 2^-53), is at least {floor:.2g}, so "
            f"the smallest error the run can state is {least:.2g}; allowed rtol in "
            f"[{least:.2g}, 1)")


def _rtol_step(pr: ProbeResult, rtol: float, h_max: float, horizon: float | None,
               safety: float = RTOL_SAFETY) -> tuple[float | None, float]:
    """The largest step h <= h_max whose estimate (E(h) + F(h)) / s <= rtol (s: ``safety``).

    E(h) the probe's truncation error (:meth:`ProbeResult.error_at`, increasing in h),
    F(h) the round-off floor over the run (:meth:`ProbeResult.roundoff_at`, growing as
    h falls): the steps that meet rtol form an interval below h_max.  From the step
    where E alone meets it (F is then usually a small part: a few steps below it meet
    rtol), else from h_max, scanned down in factors 2^(1/16) over 40 octaves; the first
    step that meets rtol refined by bisection against the one above it.  Returns (h,
    estimate), or (None, the smallest estimate of the scan) when no step meets rtol.
    """
    def estimate(h):
        return (pr.error_at(h) + pr.roundoff_at(h, horizon)) / safety

    h = min(h_max, pr.step_for(safety * rtol))  # where E alone meets it
    est = estimate(h)
    if est <= rtol:
        if h >= h_max:
            return h, est
        above = min(h_max, h * 2.0 ** (1.0 / 16.0))
    else:  # the floor takes part of the budget: scan down (no larger step meets rtol:
        # E alone exceeds s·rtol above h)
        grid = h * 2.0 ** (-np.arange(16 * 40 + 1) / 16.0)
        ests: list[float] = []
        while len(ests) < grid.size and (not ests or ests[-1] > rtol):
            ests.append(estimate(float(grid[len(ests)])))
        if ests[-1] > rtol:
            return None, min(ests)
        i = len(ests) - 1  # >= 1: the estimate at grid[0] = h exceeds rtol
        h, est = float(grid[i]), ests[-1]
        above = float(grid[i - 1])
    if estimate(above) <= rtol:
        return above, estimate(above)
    lo, hi = h, above
    for _ in range(40):
        mid = math.sqrt(hi * lo)
        if estimate(mid) <= rtol:
            lo = mid
        else:
            hi = mid
    return lo, estimate(lo)


PREDICTION_SLACK = 1.25
"""A method's probe stops once even this multiple of its predicted step
(:func:`_predicted_step`) costs more force evaluations per unit time than the best
method so far.  This spares a finer probe level of a method that will lose (on a
2,000-grain impact at rtol 1e-4: velocity Verlet's third level, 10,000 of the
probe's 20,412 steps, predicted step 1.54e-7 against the 1.50e-7 it would take); it
costs no accuracy (the chosen method's own probe is complete), at worst a method
25 % cheaper than the one chosen is missed."""


def _predicted_step(pr: ProbeResult, target: float | None, order: int) -> float:
    """The step a method's probe will end at, predicted from its finest difference.

    Richardson (module docstring): E(h_K) ≈ d_{K-1}/(2^p - 1) with the method's order p,
    then h = h_K (target/E)^{1/p}, at most h_0.  A prediction, not a bound: it only
    decides when a losing method's probe may stop (:data:`PREDICTION_SLACK`).
    """
    if target is None or not pr.differences or pr.differences[-1] <= 0:
        return pr.h[0]
    err = pr.differences[-1] / (2.0**order - 1.0)
    return min(pr.h[0], pr.h[len(pr.differences)] * (target / err) ** (1.0 / order))


def _upper_step(pr: ProbeResult, target: float | None) -> float:
    """An upper bound of the step :meth:`ProbeResult.step_for` can give for ``target``.

    E_k >= d_k + d_{k+1} + ... for the differences measured so far, so no step above
    h_k meets the target once that partial sum exceeds it.
    """
    if target is None:
        return pr.h[0]
    tail = 0.0
    upper = pr.h[0]
    for k in range(len(pr.differences) - 1, -1, -1):
        tail += pr.differences[k]
        if tail > target:
            return pr.h[k]
    return upper


@dataclass(frozen=True)
class TimeStep:
    """The time step of a run: what was chosen, why, and the bounds it was checked against.

    Build it with :meth:`choose`.

    Attributes
    ----------
    dt : float
        The step, s.
    source : str
        ``"explicit"`` (given by the caller) or ``"default"`` (:data:`DT_FRACTION` × S of
        the shortest contact period).
    default : float
        The default step for this chain, state and integrator, s (inf if nothing is
        loaded or moves).
    stable : float
        The largest linearly stable step at the expected overlaps, s.
    fraction : float
        The default's fraction of the shortest contact period (S × :data:`DT_FRACTION`).
    integrator : str
        The method's name.
    delta_expected : (N+1,) array
        The expected overlaps of the initial state, m.
    rtol : float or None
        The accuracy asked for (``source == "rtol"``), relative.
    error_estimate : float
        The estimated relative error of the recorded quantities at :attr:`dt`: the
        probe's truncation error (:func:`probe_error`) plus the round-off floor over
        the run (:meth:`ProbeResult.roundoff_at`), over :data:`RTOL_SAFETY` — estimated
        from the probe, never set to rtol (nan without rtol).
    order : float
        The order that extrapolated the finest probe run of the chosen method (the
        observed one, clipped to [1, method order], if clean, else 1; nan without rtol).
    probe_steps : int
        Steps the probe took (0 without rtol).
    damping_rate : float
        The largest dissipative rate γ_max at the expected overlaps, 1/s
        (:func:`damping_rate`; 0 for a conservative law without drag).
    maxima : {"refined", "sampled"} or None
        The running maxima of v that :attr:`error_estimate` is about, those the run
        keeps: ``"refined"`` — between the steps, the cubic Hermite interpolant's
        maximum (``record.vmax_refined``, :mod:`discrete.interpolation`) — or
        ``"sampled"`` — the largest value at the step ends (``record.vmax``: a dissipative
        law or drag, or ``refined_maxima=False``; :func:`refined_maxima`).  None without
        rtol.
    """

    dt: float
    source: str
    default: float
    stable: float
    fraction: float
    integrator: str
    delta_expected: np.ndarray
    rtol: float | None = None
    error_estimate: float = math.nan
    order: float = math.nan
    probe_steps: int = 0
    damping_rate: float = 0.0
    maxima: str | None = None

    @classmethod
    def choose(cls, chain: Chain, u=None, v=None, wall_left: float = 0.0,
               wall_right: float = 0.0, *, dt: float | None = None,
               integrator: str | Integrator = "verlet", law: ContactLaw | None = None,
               drag: float = 0.0, fraction: float | None = None,
               check: bool = True, rtol: float | None = None,
               horizon: float | None = None,
               recording: Recording | None = None,
               drift_tolerance: float = 1e-4, energy_ratios: bool = False) -> TimeStep:
        """Choose the step for ``chain`` in the state (u, v, walls).

        Parameters
        ----------
        chain : Chain
        u, v : (N,) arrays, optional
            Displacements (m) and velocities (m/s); zero.
        wall_left, wall_right : float
            Wall displacements, m.
        dt : float, optional
            An explicit step, s (> 0): it wins (checked against :attr:`stable` if
            ``check``).  None: the default.
        integrator : str, Integrator or None
            The time stepper (sets S).  None (only with ``rtol``): the cheapest of
            :data:`RTOL_CANDIDATES` for that accuracy.
        law : ContactLaw, optional
            The contact law (default Hertz).
        drag : float
            On-site drag rate, 1/s.
        fraction : float, optional
            Override the default's fraction of the contact period (> 0).
        check : bool
            Raise ValueError for a dt above the stability bound.
        rtol : float, optional
            Relative accuracy of the recorded quantities (0 < rtol < 1): the step (and
            with ``integrator=None`` the method) is chosen from a probe (module
            docstring).  Ignored when ``dt`` is given (an explicit dt wins).
        horizon : float, optional
            The run's length, s (the probe is never longer).
        recording : Recording, optional
            The run's recording: with ``rtol`` the probe records and compares what the
            run records, through the same kernel (default: the running maxima).
        drift_tolerance : float
            The run's energy-drift tolerance (:class:`~discrete.Simulation`): with
            ``rtol`` the step also keeps the probe's measured drift, extrapolated to the
            run's length (``horizon``, :meth:`ProbeResult.drifts_at`), within
            :data:`RTOL_SAFETY` of it (:meth:`ProbeResult.step_for_drift`).
        energy_ratios : bool
            With ``rtol``: the run reports energy ratios (energies over the initial
            energy, Table 2).  Their error is the energy error: an absolute one, in
            units of the initial energy, that rtol then bounds too — the drift is kept
            within :data:`RTOL_SAFETY` of min(``drift_tolerance``, rtol), and the
            error estimate is the larger of the maxima's and the drift's
            (:meth:`ProbeResult.drift_at` / :data:`RTOL_SAFETY`, at most rtol).

        Raises
        ------
        ValueError
            dt not a finite number > 0, above the stable bound (naming the allowed
            range), or no dt given when nothing is loaded or moves.
        """
        law = as_law(law)
        if rtol is not None:
            if (isinstance(rtol, bool) or not isinstance(rtol, int | float | np.floating)
                    or not 0 < float(rtol) < 1):
                raise ValueError(f"rtol must be a number in (0, 1) (got {rtol!r})")
            rtol = float(rtol)
            if dt is None:
                return cls._choose_rtol(chain, u, v, wall_left, wall_right, rtol=rtol,
                                        integrator=integrator, law=law, drag=drag,
                                        horizon=horizon, check=check, recording=recording,
                                        drift_tolerance=drift_tolerance,
                                        energy_ratios=energy_ratios)
        if integrator is None:
            if rtol is None:
                raise ValueError("integrator=None (choose the method) needs rtol")
            integrator = "verlet"  # an explicit dt with rtol: the dt wins
        method = get_integrator(integrator)
        frac = default_fraction(method) if fraction is None else float(fraction)
        if not (math.isfinite(frac) and frac > 0):
            raise ValueError(f"fraction must be finite and > 0 (got {fraction!r})")
        delta = expected_overlaps(chain, u, v, wall_left, wall_right, law=law)
        w = _rate_max(chain, delta, law, drag)
        default = frac * 2.0 * math.pi / w if w > 0 else math.inf
        stable = stable_dt(chain, delta, law=law, drag=drag)
        gamma = damping_rate(chain, delta, law=law, drag=drag)
        if dt is None:
            if not math.isfinite(default):
                raise ValueError("cannot choose dt: no contact is loaded and nothing "
                                 "moves; give dt")
            chosen, source = default, "default"
        else:
            chosen = float(dt) if isinstance(dt, int | float | np.floating) else dt
            if (not isinstance(chosen, float) or isinstance(dt, bool)
                    or not math.isfinite(chosen) or chosen <= 0):
                raise ValueError(f"dt must be a finite number > 0 s (got {dt!r})")
            source = "explicit"
        step = cls(chosen, source, default, stable, frac, method.name, delta,
                   damping_rate=gamma)
        if check:
            step.check()
        return step

    @classmethod
    def _choose_rtol(cls, chain, u, v, wall_left, wall_right, *, rtol, integrator, law,
                     drag, horizon, check, recording=None,
                     drift_tolerance: float = 1e-4, energy_ratios: bool = False
                     ) -> TimeStep:
        """The step (and method) meeting ``rtol`` from :func:`probe_error` (module docstring)."""
        # probed from the highest order down: at the accuracies asked for (rtol <= 1e-3)
        # a fourth-order method usually wins, and the best cost found first lets the
        # others' probes stop early (_predicted_step)
        names = (tuple(reversed(RTOL_CANDIDATES)) if integrator is None
                 else (get_integrator(integrator).name,))
        if law.dissipative or drag > 0:  # velocity-dependent forces: Verlet only (kernels)
            names = ("verlet",)
        velocity_dependent = bool(law.dissipative or drag > 0)
        safety = rtol_safety(recording, velocity_dependent, energy_ratios)
        _refuse_below_floor(chain, u, v, wall_left, wall_right, rtol=rtol, law=law,
                            drag=drag, horizon=horizon, safety=safety,
                            stages=max(get_integrator(n).stages for n in names))
        target = safety * rtol
        best = None
        floors = []
        steps = 0
        for name in names:
            method = get_integrator(name)
            pr = probe_error(chain, u, v, wall_left, wall_right, integrator=method, law=law,
                             drag=drag, horizon=horizon, recording=recording,
                             target=target, max_cost=math.inf if best is None else best[0])
            steps += pr.probe_steps
            if not pr.complete:
                continue
            if pr.compared == 0 and pr.compared_contacts == 0:
                raise ValueError(
                    f"rtol = {rtol:g}: no recorded maximum settled within the probe "
                    f"({pr.t_probe:.3g} s; a maximum counts once its peak has passed or "
                    "it no longer changes), so there is nothing to measure the error on; "
                    "give dt")
            base = cls.choose(chain, u, v, wall_left, wall_right, integrator=method,
                              law=law, drag=drag, check=False)
            h_max = min(pr.h0, 0.5 * base.stable)
            # the run must also pass its energy monitor: the probe's drift, extrapolated
            # to the run's length at the rate measured over the probe's second half
            cap = min(drift_tolerance, rtol) if energy_ratios else drift_tolerance
            h_max = min(h_max, pr.step_for_drift(RTOL_SAFETY * cap, horizon))
            h, est = _rtol_step(pr, rtol, h_max, horizon, safety)
            if h is None:  # round-off and truncation together never get below rtol
                floors.append(est)
                continue
            if energy_ratios:  # the energy ratios' absolute error: the run's drift
                est = max(est, pr.drift_at(h, horizon) / RTOL_SAFETY)
            cost = method.stages / h
            if best is None or cost < best[0]:
                best = (cost, method, h, est, pr, base)
        if best is None:
            raise ValueError(
                f"rtol = {rtol:g} is below what float64 can deliver for this run: the "
                f"probe's truncation error and the round-off accumulated over the run's "
                f"steps (discrete.timestep.roundoff_floor) add up to at least "
                f"{min(floors):.2g} of the recorded quantities at every step; allowed "
                f"rtol in [{min(floors):.2g}, 1)")
        _, method, h, est, pr, base = best
        step = cls(h, "rtol", base.default, base.stable, base.fraction, method.name,
                   base.delta_expected, rtol, est, pr.order, steps, base.damping_rate,
                   "refined" if refined_maxima(recording, velocity_dependent)
                   else "sampled")
        if check:
            step.check()
        return step

    def check(self) -> None:
        r"""ValueError if :attr:`dt` is above :attr:`stable` or the damping bound.

        The damping bound :math:`\gamma_{max}\,\Delta t \le` :data:`DAMPING_STEP_LIMIT`
        is one of accuracy, not stability (module docstring, "Dissipative time
        scales"): beyond it the split step's relaxation of an overdamped contact is off
        by more than 8 %, a wrong result that no monitor sees.
        """
        if self.damping_rate * self.dt > DAMPING_STEP_LIMIT:
            limit = DAMPING_STEP_LIMIT / self.damping_rate
            raise ValueError(
                f"dt = {self.dt:.4g} s is above the damping bound {limit:.4g} s: the "
                f"fastest dissipative rate at the expected overlaps is γ_max = "
                f"{self.damping_rate:.4g} 1/s (damping coefficient × inverse reduced "
                f"mass, plus the drag rate), and the split dissipative step is accurate "
                f"only for γ_max dt <= {DAMPING_STEP_LIMIT:g}; allowed range (0, "
                f"{min(limit, self.stable):.4g}] s, default {self.default:.4g} s "
                f"(check_dt=False skips this check)")
        if self.dt > self.stable:
            raise ValueError(
                f"dt = {self.dt:.4g} s is above the largest linearly stable time step "
                f"{self.stable:.4g} s at the expected overlaps (Gershgorin bound 2/ω_lat "
                f"of velocity Verlet); allowed range (0, {self.stable:.4g}] s, default "
                f"{self.default:.4g} s (check_dt=False skips this check)")

    def explain(self) -> str:
        """A sentence for instability messages: the bound and the default."""
        return (f"The largest linearly stable dt at the expected overlaps is about "
                f"{self.stable:.4g} s (Gershgorin bound 2/ω_lat, velocity Verlet); the "
                f"default {self.fraction:g}·2π/ω_max is {self.default:.4g} s")

    def to_dict(self) -> dict:
        """Scalars for file attributes and summaries (without the overlaps)."""
        return {"dt": self.dt, "dt_source": self.source, "dt_default": self.default,
                "dt_stable": self.stable, "dt_fraction": self.fraction,
                "rtol": math.nan if self.rtol is None else self.rtol,
                "rtol_estimate": self.error_estimate, "rtol_order": self.order,
                "rtol_probe_steps": self.probe_steps,
                "rtol_maxima": "" if self.maxima is None else self.maxima}


def default_dt(chain: Chain, u=None, v=None, wall_left: float = 0.0, wall_right: float = 0.0,
               *, fraction: float = DT_FRACTION, law: ContactLaw | None = None) -> float:
    """Default step ``fraction``·2π/max ω_j at the expected overlaps, s (:class:`TimeStep`).

    ``fraction`` is the fraction of the shortest contact period (the integrator's is
    :func:`default_fraction`).
    """
    return TimeStep.choose(chain, u, v, wall_left, wall_right, law=law, fraction=fraction,
                           check=False).dt
