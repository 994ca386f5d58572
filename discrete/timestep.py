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
           "expected_overlaps"]

DT_FRACTION = 0.002
"""Default dt per force evaluation as a fraction of the shortest linearised contact
period (module docstring)."""


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
    """

    dt: float
    source: str
    default: float
    stable: float
    fraction: float
    integrator: str
    delta_expected: np.ndarray

    @classmethod
    def choose(cls, chain: Chain, u=None, v=None, wall_left: float = 0.0,
               wall_right: float = 0.0, *, dt: float | None = None,
               integrator: str | Integrator = "verlet", law: ContactLaw | None = None,
               drag: float = 0.0, fraction: float | None = None,
               check: bool = True) -> TimeStep:
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
        integrator : str or Integrator
            The time stepper (sets S).
        law : ContactLaw, optional
            The contact law (default Hertz).
        drag : float
            On-site drag rate, 1/s.
        fraction : float, optional
            Override the default's fraction of the contact period (> 0).
        check : bool
            Raise ValueError for a dt above the stability bound.

        Raises
        ------
        ValueError
            dt not a finite number > 0, above the stable bound (naming the allowed
            range), or no dt given when nothing is loaded or moves.
        """
        law = as_law(law)
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
                "dt_stable": self.stable, "dt_fraction": self.fraction}


def default_dt(chain: Chain, u=None, v=None, wall_left: float = 0.0, wall_right: float = 0.0,
               *, fraction: float = DT_FRACTION, law: ContactLaw | None = None) -> float:
    """Default step ``fraction``·2π/max ω_j at the expected overlaps, s (:class:`TimeStep`).

    ``fraction`` is the fraction of the shortest contact period (the integrator's is
    :func:`default_fraction`).
    """
    return TimeStep.choose(chain, u, v, wall_left, wall_right, law=law, fraction=fraction,
                           check=False).dt
