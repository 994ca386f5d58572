r"""The contact-law base class: compiled pieces, their NumPy twins, the law's long waves.

A *contact law* gives the force :math:`F(\delta, \dot\delta; k)` (N) that two touching
grains (or a grain and a wall) push each other apart with, at overlap δ (m) and overlap
rate :math:`\dot\delta` (m/s), for the contact constant k of the chain (per contact).
The force is never attractive: F ≥ 0, and F = 0 when δ ≤ 0 (a gap).  Every law is
**one class** (one file of :mod:`theory.laws`) that supplies

* its compiled pieces (``make_force``, ``make_elastic``, ``make_energy``,
  ``make_stiffness``, ``make_damping``): small ``numba.njit(inline="always")`` scalar
  functions that the kernel factory of the discrete solver (``discrete.kernels``)
  closes over and fuses into its passes, the way py-pde compiles its operators into
  closures;
* their NumPy twins (``force``, ``elastic``, ``energy``, ``stiffness``, ``damping``)
  for the reference integrator and the energies, and for the continuum and the theory;
* what a time step needs: the linearised stiffness :math:`\partial F/\partial\delta`
  and the overlap at which the elastic energy reaches a given value;
* the physics of a chain of such contacts (NumPy only): the static overlap under a
  load (:meth:`ContactLaw.static_overlap`) and the coefficients of the long-wave
  equations (:meth:`ContactLaw.long_wave`, a :class:`LongWave`);
* a ``key`` of everything that changes the compiled code (the discrete solver compiles
  a new kernel per key and caches it on disk) and ``params``, the runtime numbers that
  do not (changing them costs no compilation).

numba is imported only when a compiled piece is made: the NumPy side of a law (the
continuum's and the theory's) costs no numba import.

Dissipative laws
----------------
A dissipative law is linear in the overlap rate, with a coefficient that depends on the
overlap only, and never pulls:

.. math::
    F(\delta, \dot\delta; k) = \max\!\big(0,\; F_{el}(\delta; k) + c(\delta; k)\,
    \dot\delta\big)\ (\delta > 0),\qquad F = 0\ (\delta \le 0),

with :math:`c \ge 0` (N·s/m) its damping coefficient (``make_damping`` / ``damping``).
The force is assembled from these two pieces here (``make_force``, ``force``), once:
the discrete kernels integrate the elastic part with the symplectic method and the
damping in a dissipative sub-step of their own, whose removed energy is booked exactly
(docs/physics.md, "Dissipation").

Adding a law
------------
Subclass :class:`ContactLaw` in a file of its own, give it a ``name``, ``exponent`` (of
the elastic part), ``key``, ``params``, ``to_dict`` and ``describe``; a conservative law
gives the compiled and NumPy ``force`` (it gets everything else from its elastic part
:math:`k[\delta]_+^n`), a dissipative one its damping coefficient ``make_damping`` and
``damping`` instead.  A law whose elastic part is not :math:`k[\delta]_+^n` overrides
all the elastic pieces (:data:`ELASTIC_PIECES`: a class that overrides some but not all
is refused when it is defined), and :meth:`~ContactLaw.long_wave` raises for it unless
it overrides that too.  Register it with
:func:`theory.laws.register_law` (one line), and test it against its NumPy twin and the
physics it claims (docs/guide/laws_and_chains.md, "Adding a law").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

__all__ = ["ContactLaw", "LawParameter", "LongWave", "compile_piece", "N_PARAMS",
           "ELASTIC_PIECES"]

N_PARAMS = 2
"""Length of the runtime parameter vector every law hands to the kernels."""

_INLINE = {"inline": "always", "nogil": True, "error_model": "numpy"}

ELASTIC_PIECES = ("make_elastic", "elastic", "make_energy", "energy", "make_stiffness",
                  "stiffness", "overlap_with_energy", "static_overlap")
"""The methods the base class derives from the elastic part k[δ]_+^n: a law overrides
none of them or all."""


def compile_piece(func):
    """Compile a law's scalar piece (force, energy, …) to be fused into the kernels.

    ``numba.njit(inline="always")``: the kernels inline it into their loops.  numba is
    imported here, on first use, so that the NumPy side of the laws does not need it.
    """
    import numba

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
    return compile_piece(power)


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
    return compile_piece(scaled)


def _power_np(r, n: float):
    """NumPy twin of :func:`_make_power`: ``r ** n``.

    Deliberately not the kernels' products, so that the reference tests compare two
    independent roundings.
    """
    return np.asarray(r, dtype=float) ** n


# ------------------------------------------------------------------ long waves
@dataclass(frozen=True)
class LongWave:
    r"""Long-wave coefficients of a chain of identical grains with one contact law.

    For the elastic part :math:`F_{el} = k[\delta]_+^n` the chain's long-wave equation
    is (Nesterenko, *Dynamics of Heterogeneous Materials*, 2001, §1.2; docs/physics.md,
    "Long waves for a power-law contact")

    .. math::
        u_{tt} = -c^2\,\partial_x\!\left[\xi^n + a\,\xi^{(n-1)/2}\,\partial_{xx}
        \xi^{(n+1)/2} + A\,\xi^{n-1}\xi_t\right],\qquad c^2 = \frac{k d^{n+1}}{m},
        \qquad a = \frac{n d^2}{6(n+1)},

    with ξ = −u_x the strain (here the total one, ξ0 + dynamic), u (m), x (m), t (s);
    the last term is the viscoelastic damping :math:`k A \delta^{n-1}\dot\delta` of
    Kuwabara & Kono for n = 3/2 (A = 0 for a conservative law).  n = 3/2 gives the
    corrected paper Eq. 7 (a = d²/10, ξ^{1/4}, ξ^{5/4}; docs/physics.md §3).
    Linearised about the static strain ξ0 = δ0/d it is the wave equation with
    :math:`c_0^2 = n c^2 \xi_0^{n-1} = n k \delta_0^{n-1} d^2/m`.

    Attributes
    ----------
    exponent : float
        n of the elastic part.
    k, mass, d, delta0 : float
        Contact constant (N/m^n), grain mass (kg), diameter (m), static overlap (m).
    c : float
        Nonlinear speed :math:`\sqrt{k d^{n+1}/m}`, m/s (c_mat of paper Eq. 7 for
        n = 3/2; :func:`theory.speeds.c_mat`).
    c0 : float
        Linear sound speed at δ0, m/s (0 without precompression;
        :func:`theory.speeds.c0`).
    dispersion : float
        a = n d²/(6(n+1)), m² (:func:`theory.speeds.long_wave_dispersion`).
    damping_time : float
        A, s: the damping term's coefficient (0 for a conservative law).
    """

    exponent: float
    k: float
    mass: float
    d: float
    delta0: float
    c: float
    c0: float
    dispersion: float
    damping_time: float = 0.0

    @property
    def xi0(self) -> float:
        """Static strain ξ0 = δ0/d."""
        return self.delta0 / self.d

    @property
    def compacton_width(self) -> float:
        """Support width of the compacton (:func:`theory.profiles.compacton_width`), m."""
        from ..profiles import compacton_width

        return compacton_width(self.d, self.exponent)

    def compacton_speed(self, xi_max):
        r"""Speed of the compacton of peak strain ξ_max without precompression, m/s.

        :math:`V = c\sqrt{2/(n+1)}\,\xi_{max}^{(n-1)/2}`
        (:func:`theory.speeds.sonic_vacuum_speed`; paper Eq. 8 for n = 3/2).
        """
        from ..speeds import sonic_vacuum_speed

        return sonic_vacuum_speed(self.c, xi_max, exponent=self.exponent)

    def solitary_speed(self, xi_max):
        r"""Speed of the solitary wave of dynamic peak strain ξ_max on top of ξ0, m/s.

        :math:`V^2 = c_0^2\,\frac{2}{n(n+1)}\,\frac{\xi_r^{n+1} - 1 - (n+1)(\xi_r - 1)}
        {(\xi_r - 1)^2}`, ξr = (ξ0 + ξ_max)/ξ0 (:func:`theory.speeds.nesterenko_speed`;
        Nesterenko 2001, Eq. 1.4.28 for n = 3/2); the compacton's at δ0 = 0.
        """
        from ..speeds import nesterenko_speed

        return nesterenko_speed(self.c, self.xi0, xi_max, exponent=self.exponent)


# ------------------------------------------------------------------- parameters
@dataclass(frozen=True)
class LawParameter:
    """One parameter of a contact law, as the scenario key ``[chain] <name>`` offers it.

    A law lists its parameters in :attr:`ContactLaw.parameters`; scenario files,
    ``hertzchain`` validation (range, did-you-mean) and the scenario reference are built
    from them (:mod:`hertzchain.scenario`), and :meth:`ContactLaw.from_params` receives
    them by name.  Plain data (no NumPy): the scenario schema reads it.

    Parameters
    ----------
    name : str
        Keyword argument of the law's constructor and the scenario key.
    default : float
        Value when the key is absent.
    doc : str
        One line of help (the scenario reference is generated from it).
    unit : str
        Unit ("" if dimensionless).
    low, high : float, optional
        Bounds; ``low_open``/``high_open`` exclude them.
    """

    name: str
    default: float
    doc: str
    unit: str = ""
    low: float | None = None
    high: float | None = None
    low_open: bool = True
    high_open: bool = True


# -------------------------------------------------------------------------- base
class ContactLaw:
    r"""A contact force law (module docstring): its compiled pieces and their NumPy twins.

    Subclasses set :attr:`name`, :attr:`dissipative`, :attr:`exponent` (of the elastic
    part :math:`F_{el} = k[\delta]_+^n`), and implement :meth:`key`, :meth:`params`,
    :meth:`to_dict`, :meth:`describe`, and :meth:`make_force` and :meth:`force` (a
    conservative law) or :meth:`make_damping` and :meth:`damping` (a dissipative one).
    """

    name: ClassVar[str] = ""
    dissipative: ClassVar[bool] = False
    """True if the force depends on the overlap rate (the discrete kernels then
    integrate its damping in exact dissipative sub-steps)."""

    exponent: float = 1.5

    summary: ClassVar[str] = ""
    """The force in one line for the scenario reference and ``[chain] law``'s help
    (default: the first line of the class docstring)."""

    parameters: ClassVar[tuple[LawParameter, ...]] = ()
    """The law's parameters (:class:`LawParameter`): the scenario keys of ``[chain]``
    that :meth:`from_params` takes."""

    @classmethod
    def from_params(cls, **params: float) -> ContactLaw:
        """The law for the values of its :attr:`parameters` (the constructor's keywords).

        The one way scenarios build a law (:meth:`hertzchain.scenario.ChainSpec.contact_law`);
        a law whose constructor takes other arguments overrides it.
        """
        return cls(**params)

    @classmethod
    def help_text(cls) -> str:
        """:attr:`summary`, or the first line of the class docstring."""
        return cls.summary or (cls.__doc__ or cls.__name__).strip().splitlines()[0]

    def __init_subclass__(cls, **kwargs) -> None:
        """Refuse a class that overrides some of :data:`ELASTIC_PIECES` but not all."""
        super().__init_subclass__(**kwargs)
        own = [p for p in ELASTIC_PIECES if getattr(cls, p) is not getattr(ContactLaw, p)]
        if own and len(own) < len(ELASTIC_PIECES):
            missing = [p for p in ELASTIC_PIECES if p not in own]
            raise TypeError(f"{cls.__name__} overrides {', '.join(own)} of the elastic part "
                            f"but not {', '.join(missing)}: the base class derives those "
                            "from k [delta]_+^n, which would then be a different force")

    def _power_elastic(self) -> bool:
        """True if the elastic part is the base class's k[δ]_+^n."""
        return type(self).elastic is ContactLaw.elastic

    # ------------------------------------------------------------ identity
    def key(self) -> tuple:
        """Everything that changes the compiled code (hashable); a new key compiles."""
        raise NotImplementedError

    def params(self) -> np.ndarray:
        """Runtime parameters of the compiled force, a float array of :data:`N_PARAMS`."""
        return np.zeros(N_PARAMS)

    def to_dict(self) -> dict[str, Any]:
        """JSON-able description, read back by :func:`theory.laws.law_from_dict`."""
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

        return compile_piece(force)

    def make_damping(self):
        """Compiled damping coefficient ``c(r, k, p) = ∂F/∂δ̇``, N·s/m.

        >= 0; 0 for r <= 0 and for a conservative law.  The dissipative sub-step of the
        discrete kernels integrates it.
        """
        def damping(r, k, p):
            return 0.0

        return compile_piece(damping)

    def make_elastic(self):
        """Compiled ``F_el(r, k) = k [r]_+^n`` (N): the conservative part."""
        power = _make_power(self.exponent)

        def elastic(r, k):
            r = max(r, 0.0)
            return k * power(r)

        return compile_piece(elastic)

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

        return compile_piece(energy)

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
        return compile_piece(stiffness)

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
        """NumPy twin of :meth:`make_stiffness`: ∂F_el/∂δ = n k [r]_+^{n-1}, N/m.

        At the static overlap δ0 it is the linear stiffness of the precompressed
        contact (paper Eq. 4 for Hertz: (3/2) k δ0^{1/2}; :func:`theory.linear_stiffness`).
        """
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

    # ------------------------------------------------------------- physics
    def static_overlap(self, force, k):
        r"""Static overlap δ0 solving :math:`F_{el}(\delta_0; k) = F`, m.

        :math:`\delta_0 = (F/k)^{1/n}` for the elastic part :math:`k\delta^n` (paper
        Eq. 1 inverted for Hertz; :func:`theory.precompression.static_overlap`).  A
        contact at rest carries no damping force, so this holds for a dissipative law
        too.  Its linear stiffness there is :meth:`stiffness` (N/m).

        Parameters
        ----------
        force : float or array
            Static contact force F, N (>= 0).
        k : float or array
            Contact constant, N/m^n (> 0).
        """
        from ..precompression import static_overlap

        return static_overlap(force, k, exponent=self.exponent)

    def long_wave_damping_time(self) -> float:
        r"""Coefficient A (s) of the long-wave damping term :math:`A\xi^{n-1}\xi_t`.

        0 for a conservative law; a dissipative law whose damping coefficient is
        :math:`c(\delta; k) = kA\delta^{n-1}` returns its A, any other raises
        NotImplementedError (its long-wave damping is not of this form).
        """
        if self.dissipative:
            raise NotImplementedError(f"{type(self).__name__} has no long-wave damping "
                                      "coefficient of the form A xi^(n-1) xi_t")
        return 0.0

    def long_wave(self, k: float, mass: float, d: float, delta0: float = 0.0) -> LongWave:
        r"""Coefficients of the long-wave equation of a chain with this law (:class:`LongWave`).

        For identical grains of ``mass`` (kg) and diameter ``d`` (m) in contact through
        this law with constant ``k`` (N/m^n), precompressed to the static overlap
        ``delta0`` (m, >= 0): :math:`c = \sqrt{k d^{n+1}/m}`, :math:`c_0 = \sqrt{n k
        \delta_0^{n-1}/m}\,d`, a = n d²/(6(n+1)) (Nesterenko 2001, §1.2; docs/physics.md,
        "Long waves for a power-law contact"), and the damping coefficient of
        :meth:`long_wave_damping_time`.  Valid for the elastic part :math:`k\delta^n`; a
        law with another elastic part overrides it.
        """
        from .._validate import check_nonnegative, check_positive
        from ..speeds import c0, c_mat, long_wave_dispersion

        if not self._power_elastic():
            raise NotImplementedError(f"{type(self).__name__} has its own elastic part: "
                                      "its long-wave coefficients are not k d^n's")

        k, mass, d = (float(check_positive(n_, v)) for n_, v in
                      (("k", k), ("mass", mass), ("d", d)))
        delta0 = float(check_nonnegative("delta0", delta0))
        n = self.exponent
        return LongWave(exponent=n, k=k, mass=mass, d=d, delta0=delta0,
                        c=float(c_mat(k, mass, d, exponent=n)),
                        c0=float(c0(k, mass, d, delta0, exponent=n)) if delta0 > 0 else 0.0,
                        dispersion=float(long_wave_dispersion(d, n)),
                        damping_time=float(self.long_wave_damping_time()))
