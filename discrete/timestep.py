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

(:meth:`ContactLaw.overlap_with_energy <discrete.laws.ContactLaw.overlap_with_energy>`).
For a vertical chain (gravity) the present overlap is taken at least at the force of
twice the static weight, :math:`2^{1/n}\delta_0` (a chain released uncompressed falls
onto its static overlaps and overshoots them).

Default time step
-----------------
The linearised stiffness of contact j at overlap δ is :math:`K_j = \partial F/\partial
\delta` (N/m; Hertz: :math:`\tfrac32 k_j\delta^{1/2}`) and its two-body frequency
:math:`\omega_j = \sqrt{K_j (1/m_{j-1} + 1/m_j)}` (rad/s; one mass at a wall).  At the
expected overlaps the default is

.. math:: \Delta t = f\,S\, \frac{2\pi}{\max_j \omega_j},\qquad f = 0.002
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

Velocity-dependent forces (:class:`~discrete.laws.ViscoelasticHertz`, drag) add the
bound :math:`\Delta t \le 2/\lambda_C` with :math:`\lambda_C \le \max_i (2(c_i +
c_{i+1})/m_i + \beta)` (Gershgorin on M⁻¹C, :math:`c_j = \partial F/\partial\dot\delta`
at the expected overlap): the explicit (predicted-velocity) damping term of
:mod:`discrete.kernels` is stable only while h λ_C stays below ~2.  It is a sufficient
rule of thumb, not a proof; the run-time energy-balance monitor catches what it misses.

A stated accuracy instead of a dt (``rtol``)
--------------------------------------------
With ``rtol`` (and no explicit dt) the step is chosen so that the recorded quantities
carry a relative error of about ``rtol``, from an error estimate that is *measured*,
not assumed (:func:`probe_error`).  A short probe — the run itself from its initial
state, for :data:`PROBE_PERIODS` shortest contact periods :math:`T_c = 2\pi/\omega_{max}`
(or to the run's end if sooner) — is integrated at three steps :math:`h_0, h_0/2,
h_0/4` (:math:`h_0` = :data:`PROBE_FRACTION` × S × :math:`T_c`).  The compared
quantities q are every grain's running maximum of v over the largest |v| (the Fig. 2
v̄max/v0; sampled at the steps, as the run records them; only grains whose peak has
passed, v < v̄max/2, at the end of the probe) and the distance travelled by
the energy centroid of the wave (arrival times and speeds), relative.  With
:math:`d_1 = \|q(h_0) - q(h_0/2)\|_\infty`, :math:`d_2 = \|q(h_0/2) - q(h_0/4)\|_\infty`
the observed order is :math:`p = \log_2(d_1/d_2)`, used clipped to [1, the method's
order] — a recorded maximum sampled once per step converges at second order whatever
the method, and the observed order says so — and Richardson's estimate of the error
at :math:`h_q = h_0/4` is :math:`e_q = d_2/(2^p - 1)` (G. Dahlquist & Å. Björck,
*Numerical Methods in Scientific Computing I*, SIAM 2008, §3.4.2: for
:math:`q(h) = q + C h^p + o(h^p)`, :math:`q(h) - q(h/2) = C h^p (1 - 2^{-p})`).  The
step is then

.. math:: h = h_q\,\big(s\,\mathrm{rtol}/e_q\big)^{1/p},\qquad s = 0.5
   \ (\text{:data:`RTOL_SAFETY`}),

capped at :math:`h_0` (no extrapolation beyond the probed steps) and at half the
stability bound, and the estimate :math:`e_q (h/h_q)^p / s` (≤ rtol) is written into
the result (:attr:`TimeStep.error_estimate`).  The factor 1/s is not decoration: a
maximum sampled once per step has an error that depends on where the peak falls
within the step, so it is not a smooth function of h and Richardson's value is a
central estimate, not a bound (measured: up to 1.1× it for an impact); 2× it bounded
the true error in every test.  If the probe is not in the asymptotic range
(:math:`d_2 > d_1`, or an instability) it is repeated at half the steps (up to
three times).  ``integrator=None`` probes velocity Verlet and the 4th-order Yoshida
method (:data:`RTOL_CANDIDATES`) and takes the one with fewer force evaluations per
unit time, S/h.  The tests (``tests/discrete/test_rtol.py``) check that the estimate
bounds the true error (against a run at a 16× smaller step) for an impact, a
precompressed solitary wave and an interface run.  An explicit dt wins over rtol.

The default is no rtol: the fixed fraction :data:`DT_FRACTION` above, whose error in
the most dt-sensitive recorded quantity of the paper's runs (v̄max/v0 of an impact on
a precompressed chain) is ≈ 1e-4 — the paper's figures are read to 3 digits and the
Table 2 tests compare to 1e-3, so 1e-4 leaves them a factor 10; ``rtol = 1e-4`` states
that accuracy for any problem and, for most problems, takes a larger step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .chain import Chain
from .integrators import Integrator, get_integrator
from .laws import ContactLaw, as_law
from .reference import overlaps as _overlaps

__all__ = ["DT_FRACTION", "TimeStep", "default_fraction", "default_dt", "stable_dt",
           "expected_overlaps", "probe_error", "RTOL_SAFETY", "RTOL_CANDIDATES",
           "PROBE_PERIODS", "PROBE_FRACTION"]

DT_FRACTION = 0.002
"""Default dt per force evaluation as a fraction of the shortest linearised contact
period (module docstring)."""

RTOL_SAFETY = 0.5
"""The step chosen for ``rtol`` aims at this fraction of rtol in Richardson's estimate;
the reported estimate is Richardson's / RTOL_SAFETY (module docstring)."""

RTOL_CANDIDATES = ("verlet", "yoshida4")
"""Methods probed when ``rtol`` is given without an integrator."""

PROBE_PERIODS = 40.0
"""Length of the rtol probe in shortest contact periods 2π/ω_max."""

PROBE_FRACTION = 0.016
"""Largest probe step per force evaluation as a fraction of the shortest contact period."""


def default_fraction(integrator: str | Integrator = "verlet") -> float:
    """Default dt as a fraction of the shortest contact period: S × :data:`DT_FRACTION`."""
    return get_integrator(integrator).stages * DT_FRACTION


def expected_overlaps(chain: Chain, u=None, v=None, wall_left: float = 0.0,
                      wall_right: float = 0.0, *, law: ContactLaw | None = None) -> np.ndarray:
    """Largest expected overlap of each contact, m (module docstring)."""
    law = as_law(law)
    u = np.zeros(chain.n) if u is None else np.asarray(u, float)
    v = np.zeros(chain.n) if v is None else np.asarray(v, float)
    r = np.maximum(_overlaps(u, chain.delta0, wall_left, wall_right), 0.0)
    if chain.gravity:  # the chain may fall onto its static overlaps: 2 × the weight
        r = np.maximum(r, 2.0 ** (1.0 / law.exponent) * chain.delta0)
    e1 = float(np.max(0.5 * chain.mass * v**2))
    return law.overlap_with_energy(r, e1, chain.k)


def _inv_mass_pairs(chain: Chain) -> np.ndarray:
    """1/m_{j-1} + 1/m_j per contact (one mass at a wall), 1/kg."""
    inv = np.zeros(chain.n + 1)
    inv[:-1] += 1.0 / chain.mass
    inv[1:] += 1.0 / chain.mass
    return inv


def _omega_max(chain: Chain, delta: np.ndarray, law: ContactLaw) -> float:
    """max_j √(K_j (1/m_{j-1} + 1/m_j)), rad/s."""
    kk = law.stiffness(delta, chain.k)
    return float(np.sqrt(np.max(kk * _inv_mass_pairs(chain))))


def stable_dt(chain: Chain, delta, *, law: ContactLaw | None = None,
              drag: float = 0.0) -> float:
    """Largest linearly stable step at overlaps ``delta`` (m), s (module docstring).

    ω_lat² ≤ max_i (K_i + K_{i+1})·2/m_i (Gershgorin bound on M⁻¹K; exact for a
    uniform chain, where ω_lat = 2√(K/m) is the zone-edge frequency), dt ≤ 2/ω_lat; and
    for velocity-dependent forces dt ≤ 2/λ_C.
    """
    law = as_law(law)
    delta = np.maximum(np.asarray(delta, float), 0.0)
    kk = law.stiffness(delta, chain.k)
    w2 = float(np.max(2.0 * (kk[:-1] + kk[1:]) / chain.mass))
    bound = 2.0 / math.sqrt(w2) if w2 > 0 else math.inf
    cc = law.damping(delta, chain.k)
    lam = float(np.max(2.0 * (cc[:-1] + cc[1:]) / chain.mass)) + float(drag)
    if lam > 0:
        bound = min(bound, 2.0 / lam)
    return bound


def _probe_quantities(chain, u, v, wl, wr, law, drag, method, h, t_probe):
    """(q, steps): the probe's compared quantities after ``t_probe`` s at step h."""
    from .recording import Recording
    from .simulation import Simulation

    sim = Simulation(chain, u, v, dt=h, wall_left=wl, wall_right=wr,
                     record=Recording(maxima=True), integrator=method.name, law=law,
                     drag=drag, check_dt=False)
    ek, ep = sim.grain_energy()
    x0 = _centroid(ek + ep)
    sim.run(t_end=sim.t0 + t_probe, progress=False)
    ek, ep = sim.grain_energy()
    vmax = np.asarray(sim.record.vmax, float)
    scale = float(np.max(np.abs(vmax))) or 1.0
    travel = _centroid(ek + ep) - x0
    # a maximum counts once the grain's peak has passed (v below half of it); a grain
    # still rising at the probe's end holds its present v, a phase error, not a maximum
    done = (sim.v < 0.5 * vmax) & (vmax > 0.01 * scale)
    return (vmax / scale, done, travel), sim.steps


def _centroid(e: np.ndarray) -> float:
    """Energy centroid, grains (0 if there is no energy)."""
    tot = float(np.sum(e))
    return float(np.dot(np.arange(e.size), e) / tot) if tot > 0 else 0.0


def probe_error(chain: Chain, u=None, v=None, wall_left: float = 0.0,
                wall_right: float = 0.0, *, integrator: str | Integrator = "verlet",
                law: ContactLaw | None = None, drag: float = 0.0,
                h0: float | None = None, horizon: float | None = None) -> dict:
    """Measure the error constant of the recorded quantities by step doubling (module docstring).

    Parameters
    ----------
    chain, u, v, wall_left, wall_right, law, drag
        The run's chain, initial state (m, m/s), walls (m), contact law and drag (1/s).
    integrator : str or Integrator
        The method probed.
    h0 : float, optional
        Largest probe step, s; default :data:`PROBE_FRACTION` × S × 2π/ω_max.
    horizon : float, optional
        The run's length, s: the probe is never longer.

    Returns
    -------
    dict
        ``h_q`` (s, the smallest probe step), ``error_q`` (Richardson's estimate of the
        relative error there), ``order`` (the observed order, clipped to
        [1, method order]), ``order_observed`` (unclipped; nan if undetermined),
        ``t_probe`` (s), ``probe_steps`` (steps taken in all probe runs), ``h0`` (s).
    """
    from .simulation import InstabilityError

    law = as_law(law)
    method = get_integrator(integrator)
    delta = expected_overlaps(chain, u, v, wall_left, wall_right, law=law)
    w = _omega_max(chain, delta, law)
    if not w > 0:
        raise ValueError("cannot probe the error: no contact is loaded and nothing moves")
    period = 2.0 * math.pi / w
    stable = stable_dt(chain, delta, law=law, drag=drag)
    if h0 is None:
        h0 = min(PROBE_FRACTION * method.stages * period, 0.5 * stable)
    t_probe = PROBE_PERIODS * period
    if horizon is not None and math.isfinite(horizon) and horizon > 0:
        t_probe = min(t_probe, float(horizon))
    steps = 0
    for _attempt in range(4):
        try:
            qs = []
            for level in range(3):
                q, n = _probe_quantities(chain, u, v, wall_left, wall_right, law, drag,
                                         method, h0 / 2**level, t_probe)
                qs.append(q)
                steps += n
        except InstabilityError:
            h0 *= 0.5
            continue
        done = qs[0][1] & qs[1][1] & qs[2][1]
        d1, d2 = (max(float(np.max(np.abs(a[0][done] - b[0][done]), initial=0.0)),
                      abs(a[2] - b[2]) / max(abs(b[2]), 1.0))
                  for a, b in ((qs[0], qs[1]), (qs[1], qs[2])))
        if d2 <= 1e-14:  # at round-off: the quantities do not depend on h
            return {"h_q": h0 / 4, "error_q": d2, "order": float(method.order),
                    "order_observed": math.nan, "t_probe": t_probe,
                    "probe_steps": steps, "h0": h0}
        if d2 < d1 or _attempt == 3:
            p_obs = math.log2(d1 / d2) if d1 > 0 else math.nan
            p = min(max(p_obs, 1.0), float(method.order)) if math.isfinite(p_obs) else 1.0
            return {"h_q": h0 / 4, "error_q": d2 / (2.0**p - 1.0), "order": p,
                    "order_observed": p_obs, "t_probe": t_probe, "probe_steps": steps,
                    "h0": h0}
        h0 *= 0.5
    raise RuntimeError("the rtol probe went unstable at every step tried; give dt")


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
        The estimated relative error of the recorded quantities at :attr:`dt` (from the
        probe, :func:`probe_error`; nan without rtol).
    order : float
        The convergence order the estimate used (observed, clipped; nan without rtol).
    probe_steps : int
        Steps the probe took (0 without rtol).
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

    @classmethod
    def choose(cls, chain: Chain, u=None, v=None, wall_left: float = 0.0,
               wall_right: float = 0.0, *, dt: float | None = None,
               integrator: str | Integrator = "verlet", law: ContactLaw | None = None,
               drag: float = 0.0, fraction: float | None = None,
               check: bool = True, rtol: float | None = None,
               horizon: float | None = None) -> TimeStep:
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
                                        horizon=horizon, check=check)
        if integrator is None:
            if rtol is None:
                raise ValueError("integrator=None (choose the method) needs rtol")
            integrator = "verlet"  # an explicit dt with rtol: the dt wins
        method = get_integrator(integrator)
        frac = default_fraction(method) if fraction is None else float(fraction)
        if not (math.isfinite(frac) and frac > 0):
            raise ValueError(f"fraction must be finite and > 0 (got {fraction!r})")
        delta = expected_overlaps(chain, u, v, wall_left, wall_right, law=law)
        w = _omega_max(chain, delta, law)
        default = frac * 2.0 * math.pi / w if w > 0 else math.inf
        stable = stable_dt(chain, delta, law=law, drag=drag)
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
        step = cls(chosen, source, default, stable, frac, method.name, delta)
        if check:
            step.check()
        return step

    @classmethod
    def _choose_rtol(cls, chain, u, v, wall_left, wall_right, *, rtol, integrator, law,
                     drag, horizon, check) -> TimeStep:
        """The step (and method) meeting ``rtol`` from :func:`probe_error` (module docstring)."""
        names = RTOL_CANDIDATES if integrator is None else (get_integrator(integrator).name,)
        if law.dissipative or drag > 0:  # velocity-dependent forces: Verlet only (kernels)
            names = ("verlet",)
        best = None
        steps = 0
        for name in names:
            method = get_integrator(name)
            pr = probe_error(chain, u, v, wall_left, wall_right, integrator=method, law=law,
                             drag=drag, horizon=horizon)
            steps += pr["probe_steps"]
            p, hq, eq = pr["order"], pr["h_q"], pr["error_q"]
            base = cls.choose(chain, u, v, wall_left, wall_right, integrator=method,
                              law=law, drag=drag, check=False)
            cap = min(pr["h0"], 0.5 * base.stable)
            h = cap if eq <= 0 else min(cap, hq * (RTOL_SAFETY * rtol / eq) ** (1.0 / p))
            # Below the cap e_q (h/h_q)^p / s = rtol by construction; evaluating it again
            # returned rtol (1 + 2e-16) on some CPUs, a promise (estimate <= rtol) broken
            # by round-off alone.
            est = rtol if h < cap else eq * (h / hq) ** p / RTOL_SAFETY
            cost = method.stages / h
            if best is None or cost < best[0]:
                best = (cost, method, h, est, p, base)
        _, method, h, est, p, base = best
        step = cls(h, "rtol", base.default, base.stable, base.fraction, method.name,
                   base.delta_expected, rtol, est, p, steps)
        if check:
            step.check()
        return step

    def check(self) -> None:
        """ValueError if :attr:`dt` is above :attr:`stable` (naming the allowed range)."""
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
                "rtol_probe_steps": self.probe_steps}


def default_dt(chain: Chain, u=None, v=None, wall_left: float = 0.0, wall_right: float = 0.0,
               *, fraction: float = DT_FRACTION, law: ContactLaw | None = None) -> float:
    """Default step ``fraction``·2π/max ω_j at the expected overlaps, s (:class:`TimeStep`).

    ``fraction`` is the fraction of the shortest contact period (the integrator's is
    :func:`default_fraction`).
    """
    return TimeStep.choose(chain, u, v, wall_left, wall_right, law=law, fraction=fraction,
                           check=False).dt
