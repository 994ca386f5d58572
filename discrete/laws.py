r"""Contact laws: one definition per law, compiled into the kernels, with its NumPy twin.

A *contact law* gives the force :math:`F(\delta, \dot\delta; k)` (N) that two touching
grains (or a grain and a wall) push each other apart with, at overlap δ (m) and overlap
rate :math:`\dot\delta` (m/s), for the contact constant k of the chain
(:class:`discrete.Chain`, per contact).  The force is never attractive: F ≥ 0, and
F = 0 when δ ≤ 0 (a gap).  Every law is **one class** here that supplies

* its compiled pieces (``make_force``, ``make_elastic``, ``make_energy``,
  ``make_stiffness``): small ``numba.njit(inline="always")`` scalar functions that the
  kernel factory :func:`discrete.kernels.make_kernels` closes over and fuses into its
  passes, the way py-pde compiles its operators into closures;
* their NumPy twins (``force``, ``elastic``, ``energy``, ``stiffness``) for the
  reference integrator (:mod:`discrete.reference`) and the energies
  (:mod:`discrete.energy`);
* what the time step needs (:mod:`discrete.timestep`): the linearised stiffness
  :math:`\partial F/\partial\delta` and the overlap at which the elastic energy reaches
  a given value;
* a ``key`` of everything that changes the compiled code (a new kernel is compiled per
  key and cached on disk) and ``params``, the runtime numbers that do not (changing them
  costs no compilation).

Laws
----
:class:`PowerLaw` (``"power"``)
    :math:`F = k[\delta]_+^{n}`: n = 3/2 is Hertz's law for spheres (paper Eq. 1;
    :data:`HERTZ`, the default), n = 1 a linear spring (cylinders along their axis,
    and the harmonic chain), n = 2 cones; Nesterenko (2001), *Dynamics of
    Heterogeneous Materials*, §1.1.
:class:`ViscoelasticHertz` (``"viscoelastic_hertz"``)
    :math:`F = \max\!\big(0,\; k\,[\delta^{3/2} + A\,\delta^{1/2}\dot\delta]\big)` for
    δ > 0: the dissipative Hertz law of Kuwabara & Kono, Jpn. J. Appl. Phys. 26 (1987)
    1230, derived for viscoelastic spheres by Brilliantov, Spahn, Hertzsch & Pöschel,
    Phys. Rev. E 53 (1996) 5382, Eq. (18), with A (s) the material's dissipative
    constant; γ = kA in the form :math:`k\delta^{3/2} + \gamma\delta^{1/2}\dot\delta`.
    The clip at 0 (no attraction while the contact unloads fast) follows Schwager &
    Pöschel, Phys. Rev. E 57 (1998) 650 and Ramírez et al., Phys. Rev. E 60 (1999) 4465.

Dissipative laws
----------------
A dissipative law is linear in the overlap rate, with a coefficient that depends on the
overlap only, and never pulls:

.. math::
    F(\delta, \dot\delta; k) = \max\!\big(0,\; F_{el}(\delta; k) + c(\delta; k)\,
    \dot\delta\big)\ (\delta > 0),\qquad F = 0\ (\delta \le 0),

with :math:`c \ge 0` (N·s/m) its damping coefficient (``make_damping`` / ``damping``).
The force is assembled from these two pieces here (``make_force``, ``force``), once:
the kernels integrate the elastic part with the symplectic method and the damping in
a dissipative sub-step of their own, whose removed energy is booked exactly
(:mod:`discrete.kernels`, "Dissipation"; docs/physics.md, "Dissipation").

Adding a law
------------
Subclass :class:`ContactLaw`, give it a ``name``, ``exponent`` (of the elastic part),
``key`` and ``params``; a conservative law gives the compiled and NumPy ``force`` (it
gets everything else from its elastic part :math:`k[\delta]_+^n`), a dissipative one
its damping coefficient ``make_damping`` and ``damping`` instead.  Register it in
:data:`LAWS`, and test it against its NumPy twin and the physics it claims
(docs/physics.md, "Contact laws").
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from typing import Any, ClassVar

import numba
import numpy as np

__all__ = ["ContactLaw", "PowerLaw", "ViscoelasticHertz", "HERTZ", "LAWS", "as_law",
           "law_from_dict", "compile_piece", "N_PARAMS"]

N_PARAMS = 2
"""Length of the runtime parameter vector every law hands to the kernels."""

_INLINE = {"inline": "always", "nogil": True, "error_model": "numpy"}


def compile_piece(func):
    """Compile a law's scalar piece (force, energy, …) to be fused into the kernels.

    ``numba.njit(inline="always")``: the kernels inline it into their loops.
    """
    return numba.njit(**_INLINE)(func)


# ----------------------------------------------------------------------- powers
def _make_power(n: float):
    """Compiled r ↦ r^n for r >= 0: exact products (and one √) for n = 1, 3/2, 2, 5/2, 3.

    n = 3/2 is ``r * sqrt(r)`` (one correctly rounded square root; the kernels' Hertz
    arithmetic since the first version), other exponents ``r ** n``.
    """
    if n == 0.5:
        def power(r):
            return np.sqrt(r)
    elif n == 1.0:
        def power(r):
            return r
    elif n == 1.5:
        def power(r):
            return r * np.sqrt(r)
    elif n == 2.0:
        def power(r):
            return r * r
    elif n == 2.5:
        def power(r):
            return r * r * np.sqrt(r)
    elif n == 3.0:
        def power(r):
            return r * r * r
    else:
        def power(r):
            return r**n
    return numba.njit(**_INLINE)(power)


_TINY = float(np.finfo(float).tiny)
"""Smallest normal double: below it U(δ0) has lost its relative precision."""


def _make_scaled_power(n: float):
    """Compiled (x, r) ↦ x r^n for r >= 0, multiplied left to right (x·r·r·√r for 5/2)."""
    if n == 2.5:
        def scaled(x, r):
            return x * r * r * np.sqrt(r)
    elif n == 2.0:
        def scaled(x, r):
            return x * r * r
    elif n == 3.0:
        def scaled(x, r):
            return x * r * r * r
    elif n == 3.5:
        def scaled(x, r):
            return x * r * r * r * np.sqrt(r)
    else:
        power = _make_power(n)

        def scaled(x, r):
            return x * power(r)
    return numba.njit(**_INLINE)(scaled)


def _power_np(r, n: float):
    """NumPy twin of :func:`_make_power`: ``r ** n``.

    Deliberately not the kernels' products, so that the reference tests compare two
    independent roundings.
    """
    return np.asarray(r, dtype=float) ** n


# -------------------------------------------------------------------------- base
class ContactLaw:
    r"""A contact force law (module docstring): its compiled pieces and their NumPy twins.

    Subclasses set :attr:`name`, :attr:`dissipative`, :attr:`exponent` (of the elastic
    part :math:`F_{el} = k[\\delta]_+^n`), and implement :meth:`key`, :meth:`params`,
    and :meth:`make_force` and :meth:`force` (a conservative law) or
    :meth:`make_damping` and :meth:`damping` (a dissipative one).
    """

    name: ClassVar[str] = ""
    dissipative: ClassVar[bool] = False
    """True if the force depends on the overlap rate (the kernels then integrate its
    damping in exact dissipative sub-steps, :mod:`discrete.kernels`, "Dissipation")."""

    exponent: float = 1.5

    # ------------------------------------------------------------ identity
    def key(self) -> tuple:
        """Everything that changes the compiled code (hashable); a new key compiles."""
        raise NotImplementedError

    def params(self) -> np.ndarray:
        """Runtime parameters of the compiled force, a float array of :data:`N_PARAMS`."""
        return np.zeros(N_PARAMS)

    def to_dict(self) -> dict[str, Any]:
        """JSON-able description, read back by :func:`law_from_dict`."""
        raise NotImplementedError

    def describe(self) -> str:
        """One line for file attributes and messages."""
        raise NotImplementedError

    def __eq__(self, other) -> bool:
        return type(other) is type(self) and other.to_dict() == self.to_dict()

    def __hash__(self) -> int:
        return hash(tuple(sorted(self.to_dict().items())))

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "law")
        return f"{type(self).__name__}({args})"

    # --------------------------------------------------- compiled pieces
    def make_force(self):
        r"""Compiled ``F(r, rd, k, p)``, the contact force (N).

        At overlap r (m, any sign), overlap rate rd (m/s), constant k and runtime
        parameters p (:meth:`params`).  A conservative law defines it; for a dissipative
        one it is :math:`\max(0, F_{el}(r) + c(r)\,\dot r)` for r > 0, else 0 (module
        docstring), from :meth:`make_elastic` and :meth:`make_damping`.
        """
        if not self.dissipative:
            raise NotImplementedError
        elastic = self.make_elastic()
        damping = self.make_damping()

        def force(r, rd, k, p):
            if r <= 0.0:
                return 0.0
            return max(elastic(r, k) + damping(r, k, p) * rd, 0.0)

        return numba.njit(**_INLINE)(force)

    def make_damping(self):
        """Compiled damping coefficient ``c(r, k, p) = ∂F/∂δ̇``, N·s/m.

        >= 0; 0 for r <= 0 and for a conservative law.  The dissipative sub-step of the
        kernels integrates it (:mod:`discrete.kernels`, "Dissipation").
        """
        def damping(r, k, p):
            return 0.0

        return numba.njit(**_INLINE)(damping)

    def make_elastic(self):
        """Compiled ``F_el(r, k) = k [r]_+^n`` (N): the conservative part."""
        power = _make_power(self.exponent)

        def elastic(r, k):
            r = max(r, 0.0)
            return k * power(r)

        return numba.njit(**_INLINE)(elastic)

    def make_energy(self):
        r"""Compiled wave potential energy ``e(r, k, d0)`` = U(r) - U(δ0), J.

        :math:`U(r) = k[r]_+^{n+1}/(n+1)` is the elastic energy of the contact (the
        integral of the elastic force); for r > 0 the difference is evaluated as
        :math:`U(\delta_0)\,\mathrm{expm1}((n+1)\,\mathrm{log1p}((r-\delta_0)/\delta_0))`,
        free of cancellation for small waves on a large precompression
        (docs/physics.md §6).  (For Hertz the products are those of the kernels before
        the laws were separated, so energies are bitwise unchanged.)
        """
        n1 = self.exponent + 1.0
        c = 1.0 / n1
        scaled = _make_scaled_power(n1)

        def energy(r, k, d0):
            if r <= 0.0:
                return -scaled(c * k, d0)
            if d0 == 0.0:
                return scaled(c * k, r)
            x = (r - d0) / d0
            u0 = scaled(c * k, d0)
            e = u0 * np.expm1(n1 * np.log1p(x))
            if u0 < _TINY or not np.isfinite(e):
                # U(δ0) below the normal doubles (δ0/d ≲ 1e-120): the product form is
                # 0·inf or 0; r ≫ δ0 there, so the plain difference has no cancellation
                return scaled(c * k, r) - u0
            return e

        return numba.njit(**_INLINE)(energy)

    def make_stiffness(self):
        """Compiled ``K(r, k) = ∂F_el/∂r = n k [r]_+^{n-1}`` (N/m)."""
        n = self.exponent
        power = _make_power(n - 1.0) if n != 1.0 else None
        if power is None:
            def stiffness(r, k):
                return k if r > 0.0 else 0.0
        else:
            def stiffness(r, k):
                r = max(r, 0.0)
                return n * k * power(r)
        return numba.njit(**_INLINE)(stiffness)

    # -------------------------------------------------------- NumPy twins
    def force(self, r, rd, k):
        """NumPy twin of :meth:`make_force`: contact forces, N.

        From overlaps r (m), overlap rates rd (m/s) and constants k (arrays broadcast).
        """
        if not self.dissipative:
            raise NotImplementedError
        r = np.asarray(r, float)
        f = self.elastic(r, k) + self.damping(r, k) * np.asarray(rd, float)
        return np.where(r > 0, np.maximum(f, 0.0), 0.0)

    def elastic(self, r, k):
        """NumPy twin of :meth:`make_elastic`, N."""
        return np.asarray(k, float) * _power_np(np.maximum(r, 0.0), self.exponent)

    def energy(self, r, k, d0):
        """NumPy twin of :meth:`make_energy`: wave potential energy U(r) - U(δ0), J."""
        r, k, d0 = np.broadcast_arrays(np.asarray(r, float), np.asarray(k, float),
                                       np.asarray(d0, float))
        n1 = self.exponent + 1.0
        p0 = _power_np(d0, n1)
        u0 = (1.0 / n1) * k * p0
        out = -u0
        pos = r > 0
        zero = pos & (d0 == 0)
        out = np.where(zero, (1.0 / n1) * k * _power_np(np.maximum(r, 0.0), n1), out)
        pre = pos & (d0 > 0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            x = np.where(pre, (r - d0) / np.where(pre, d0, 1.0), 0.0)
            rel = u0 * np.expm1(n1 * np.log1p(x))
            # U(δ0) subnormal or 0 (δ0/d ≲ 1e-120): the plain difference (as make_energy)
            plain = (1.0 / n1) * k * _power_np(np.maximum(r, 0.0), n1) - u0
            rel = np.where((p0 < _TINY) | (u0 < _TINY) | ~np.isfinite(rel), plain, rel)
            out = np.where(pre, rel, out)
        return out

    def stiffness(self, r, k):
        """NumPy twin of :meth:`make_stiffness`, N/m."""
        n = self.exponent
        r = np.maximum(np.asarray(r, float), 0.0)
        if n == 1.0:
            return np.where(r > 0, np.asarray(k, float), 0.0)
        return n * np.asarray(k, float) * _power_np(r, n - 1.0)

    def damping(self, r, k):
        """NumPy twin of :meth:`make_damping`: ∂F/∂δ̇ at overlap r, N·s/m (0: conservative)."""
        return np.zeros(np.broadcast(np.asarray(r), np.asarray(k)).shape)

    def overlap_with_energy(self, r, e, k):
        """Overlap at which the elastic energy exceeds that at [r]_+ by e (J), m.

        :math:`([r]_+^{n+1} + (n+1) e/k)^{1/(n+1)}` for the energy k δ^{n+1}/(n+1)
        (k = 0: e adds nothing).
        """
        r = np.maximum(np.asarray(r, float), 0.0)
        k = np.asarray(k, float)
        n1 = self.exponent + 1.0
        with np.errstate(divide="ignore"):
            extra = np.where(k > 0, n1 * e / np.where(k > 0, k, 1.0), 0.0)
        return (r**n1 + extra) ** (1.0 / n1)

    def static_forces(self, k, d0):
        """Static forces F(δ0, 0) of the contacts, N, with the kernels' arithmetic.

        The kernels subtract these from every contact force, so that a contact at its
        static overlap exerts exactly zero net force (:mod:`discrete.kernels`).
        """
        from .kernels import make_kernels

        return make_kernels(self).static_forces(np.asarray(k, float), np.asarray(d0, float),
                                                self.params())


# -------------------------------------------------------------------- power law
class PowerLaw(ContactLaw):
    r"""Conservative power law :math:`F = k[\delta]_+^n` (N), n >= 1.

    n = 3/2: Hertz (paper Eq. 1; Johnson, *Contact Mechanics*, 1985, Eq. 4.22), the
    default; n = 1: linear spring; n = 2: cones (Nesterenko 2001, §1.1).  Elastic
    energy :math:`k[\delta]_+^{n+1}/(n+1)` (J).  k is in N/m^n.

    Parameters
    ----------
    exponent : float
        n, in [1, 10].
    """

    name = "power"
    dissipative = False

    def __init__(self, exponent: float = 1.5) -> None:
        try:
            n = float(exponent)
        except (TypeError, ValueError):
            raise ValueError(f"exponent must be a real number in [1, 10] "
                             f"(got {exponent!r})") from None
        if not (math.isfinite(n) and 1.0 <= n <= 10.0):
            raise ValueError(f"exponent must be in [1, 10] (got {exponent!r}); n < 1 "
                             "has an unbounded stiffness at zero overlap")
        self.exponent = n

    def key(self) -> tuple:
        """See :meth:`ContactLaw.key`."""
        return ("power", self.exponent)

    def to_dict(self) -> dict[str, Any]:
        """See :meth:`ContactLaw.to_dict`."""
        return {"law": self.name, "exponent": self.exponent}

    def describe(self) -> str:
        """See :meth:`ContactLaw.describe`."""
        if self.exponent == 1.5:
            return "Hertz F = k [delta]_+^(3/2)"
        return f"power law F = k [delta]_+^{self.exponent:g}"

    def make_force(self):
        """See :meth:`ContactLaw.make_force`."""
        elastic = self.make_elastic()

        def force(r, rd, k, p):
            return elastic(r, k)

        return numba.njit(**_INLINE)(force)

    def force(self, r, rd, k):
        """See :meth:`ContactLaw.force`."""
        return self.elastic(r, k)


# ------------------------------------------------------- viscoelastic Hertz
class ViscoelasticHertz(ContactLaw):
    r"""Dissipative Hertz law of Kuwabara & Kono (1987) / Brilliantov et al. (1996).

    .. math::
        F = \begin{cases} \max\!\big(0,\ k\,[\delta^{3/2} + A\,\delta^{1/2}\dot\delta]
        \big) & \delta > 0 \\ 0 & \delta \le 0 \end{cases}

    (N; δ the overlap, m; :math:`\dot\delta` its rate, m/s; k in N/m^{3/2} as for
    :data:`HERTZ`; A in s).  Brilliantov, Spahn, Hertzsch & Pöschel, Phys. Rev. E 53
    (1996) 5382, Eq. (18), with :math:`A = \tfrac13 (3\eta_2-\eta_1)^2/(3\eta_2+2\eta_1)
    \cdot (1-\nu^2)(1-2\nu)/(Y\nu^2)` for a material of Young's modulus Y, Poisson
    ratio ν and viscous constants η1, η2; γ = kA in the issue's notation
    :math:`F = k\delta^{3/2} + \gamma\delta^{1/2}\dot\delta`.  The force is clipped
    at 0 so that it never pulls (Schwager & Pöschel, Phys. Rev. E 57 (1998) 650).
    Elastic part and energies are Hertz's; the power it dissipates is
    :math:`(F - k\delta^{3/2})\,\dot\delta \ge 0`.

    Parameters
    ----------
    damping_time : float
        A, s (>= 0; 0 is the lossless Hertz law, computed through the dissipative path).
    """

    name = "viscoelastic_hertz"
    dissipative = True
    exponent = 1.5

    def __init__(self, damping_time: float) -> None:
        try:
            a = float(damping_time)
        except (TypeError, ValueError):
            raise ValueError(f"damping_time must be a real number >= 0 s "
                             f"(got {damping_time!r})") from None
        if not (math.isfinite(a) and a >= 0):
            raise ValueError(f"damping_time must be finite and >= 0 s (got {damping_time!r})")
        self.damping_time = a

    def key(self) -> tuple:
        """See :meth:`ContactLaw.key`."""
        return ("viscoelastic_hertz",)

    def params(self) -> np.ndarray:
        """See :meth:`ContactLaw.params`."""
        return np.array([self.damping_time, 0.0])

    def to_dict(self) -> dict[str, Any]:
        """See :meth:`ContactLaw.to_dict`."""
        return {"law": self.name, "damping_time": self.damping_time}

    def describe(self) -> str:
        """See :meth:`ContactLaw.describe`."""
        return (f"viscoelastic Hertz F = max(0, k (delta^(3/2) + A delta^(1/2) "
                f"d(delta)/dt)), A = {self.damping_time:g} s")

    def make_damping(self):
        """See :meth:`ContactLaw.make_damping`: c = k A √δ (N·s/m) for δ > 0."""
        def damping(r, k, p):
            if r <= 0.0:
                return 0.0
            return k * p[0] * np.sqrt(r)

        return numba.njit(**_INLINE)(damping)

    def damping(self, r, k):
        """See :meth:`ContactLaw.damping`: k A √[δ]_+, N·s/m."""
        return np.asarray(k, float) * self.damping_time * np.sqrt(np.maximum(r, 0.0))


HERTZ = PowerLaw(1.5)
"""Hertz's law F = k [δ]_+^{3/2} of the paper (Eq. 1): the default law."""

LAWS: dict[str, type[ContactLaw]] = {PowerLaw.name: PowerLaw,
                                     ViscoelasticHertz.name: ViscoelasticHertz}
"""The registered laws by name (:func:`law_from_dict`)."""


def law_from_dict(d: dict[str, Any]) -> ContactLaw:
    """The law described by ``d`` (:meth:`ContactLaw.to_dict`); ValueError if unknown."""
    if not isinstance(d, dict) or "law" not in d:
        raise ValueError(f"a contact law description needs a 'law' key (got {d!r})")
    d = dict(d)
    name = d.pop("law")
    if name not in LAWS:
        raise ValueError(f"unknown contact law {name!r}; choose one of {sorted(LAWS)}")
    return LAWS[name](**d)


def as_law(law: ContactLaw | dict | None) -> ContactLaw:
    """``law`` as a :class:`ContactLaw` (None: :data:`HERTZ`; a dict: :func:`law_from_dict`)."""
    if law is None:
        return HERTZ
    if isinstance(law, ContactLaw):
        return law
    if isinstance(law, dict):
        return law_from_dict(law)
    raise ValueError(f"law must be a ContactLaw, a dict or None (got {type(law).__name__})")


def source_digest() -> str:
    """SHA-256 of the sources the compiled kernels are made of.

    This module and :mod:`discrete.kernels`: part of every kernel's cache key.
    """
    global _DIGEST
    if _DIGEST is None:
        h = hashlib.sha256()
        here = Path(__file__).resolve().parent
        for name in ("laws.py", "kernels.py"):
            h.update((here / name).read_bytes())
        _DIGEST = h.hexdigest()
    return _DIGEST


_DIGEST: str | None = None
