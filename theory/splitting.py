r"""Symplectic splitting methods for u_t = v, v_t = a(u): the one table of coefficients.

A method is a symmetric composition of *kicks* (:math:`v \mathrel{+}= b_s h\,a(u)`) and
*drifts* (:math:`u \mathrel{+}= a_s h\,v`), h the time step (s).  Two forms:

* **kick first** ("BAB", velocity form), S drifts and S + 1 kicks,

  .. math::
      v \mathrel{+}= b_1 h\,a,\ u \mathrel{+}= a_1 h\,v,\ v \mathrel{+}= b_2 h\,a,\ \dots,\
      u \mathrel{+}= a_S h\,v,\ v \mathrel{+}= b_{S+1} h\,a ;

  the last kick of a step and the first of the next act on the same u and share one
  force evaluation ("first same as last", FSAL), so a run of n steps costs n S + 1
  evaluations;
* **drift first** ("ABA", position form), S + 1 drifts and S kicks (S evaluations per
  step; the last drift of a step and the first of the next merge).

Each drift-first entry here is a kick-first one with the roles of drift and kick
exchanged (:meth:`Splitting.swapped`); the 4th-order order conditions of symmetric
methods are symmetric in the two operators, so the order is kept (the error constants
are not).  All are symplectic and time-reversible.

======================  =====  ==  =====  =================================================
name                    order  S   form   reference
======================  =====  ==  =====  =================================================
``verlet``              2      1   BAB    velocity Verlet / Störmer; Swope et al., J. Chem.
                                          Phys. 76 (1982) 637, Eq. 7
``yoshida4``            4      3   BAB    triple jump, H. Yoshida, Phys. Lett. A 150 (1990)
                                          262, Eq. 5.19 (w1 = 1/(2 - 2^{1/3}), w0 = 1 - 2 w1)
``blanes_moan4``        4      6   BAB    SRKN_6^b, S. Blanes & P. C. Moan, J. Comput. Appl.
                                          Math. 142 (2002) 313, Table 3
``position_verlet``     2      1   ABA    ``verlet`` swapped (drift ½, kick 1, drift ½)
``position_yoshida4``   4      3   ABA    ``yoshida4`` swapped, with w0 = -2^{1/3}/(2 - 2^{1/3})
======================  =====  ==  =====  =================================================

The two Yoshida entries round w0 differently (1 ulp apart: -1.7024143839193155 for
1 - 2 w1, -1.7024143839193153 for Eq. 5.19's quotient); each is the value its solver
has always used (``discrete`` kick-first, ``continuum`` drift-first), kept so that stored
results are reproduced bit for bit.

Stability on the harmonic oscillator v_t = -ω² u (the limit of ω h; per evaluation in
brackets): Verlet 2 (2), Yoshida-4 1.573 (0.524), Blanes–Moan-4 3.163 (0.527).
:data:`STABILITY_LIMITS` holds them; a solver's stable step for its fastest mode ω_max
is ``fraction × limit / ω_max``.

Pure numbers (no numpy arrays kept): the solvers (:mod:`discrete.integrators`,
:mod:`continuum.solver`) turn them into the arrays of their kernels.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Splitting", "SPLITTINGS", "STABILITY_LIMITS", "ORDER_METHODS", "get_splitting"]


@dataclass(frozen=True)
class Splitting:
    """A symmetric splitting method: drift coefficients ``drift`` and kick ``kick``.

    Kick first (BAB) when ``len(kick) == len(drift) + 1``, drift first (ABA) when
    ``len(drift) == len(kick) + 1`` (module docstring).  Coefficients are fractions of
    the step (dimensionless); each set sums to 1.  ``stability``: the largest stable
    ω h on the harmonic oscillator (:data:`STABILITY_LIMITS`; swapping drift and kick
    keeps it).
    """

    name: str
    order: int
    drift: tuple[float, ...]
    kick: tuple[float, ...]
    reference: str
    stability: float

    def __post_init__(self) -> None:
        if abs(len(self.kick) - len(self.drift)) != 1:
            raise ValueError(f"{self.name}: a symmetric splitting has one more kick than "
                             f"drifts or one more drift than kicks (got {len(self.drift)} "
                             f"drifts, {len(self.kick)} kicks)")

    @property
    def kick_first(self) -> bool:
        """True for the BAB (velocity) form, False for ABA (position)."""
        return len(self.kick) == len(self.drift) + 1

    @property
    def stages(self) -> int:
        """Force evaluations per step S (kick first: with the FSAL merge)."""
        return len(self.drift) if self.kick_first else len(self.kick)

    def coefficients(self, dt: float):
        """(a_s·dt, b_s·dt) as float arrays (s)."""
        import numpy as np

        return (np.array(self.drift, dtype=float) * dt, np.array(self.kick, dtype=float) * dt)

    def swapped(self, name: str, reference: str) -> Splitting:
        """The method with the roles of drift and kick exchanged (same order)."""
        return Splitting(name, self.order, self.kick, self.drift, reference, self.stability)


_CBRT2 = 2.0 ** (1.0 / 3.0)
_W1 = 1.0 / (2.0 - _CBRT2)
_YOSHIDA_REF = "H. Yoshida, Phys. Lett. A 150 (1990) 262, Eq. 5.19"


def _yoshida4(w0: float, name: str, reference: str) -> Splitting:
    return Splitting(name, 4, (_W1, w0, _W1),
                     (0.5 * _W1, 0.5 * (w0 + _W1), 0.5 * (w0 + _W1), 0.5 * _W1), reference,
                     1.573)


def _blanes_moan4() -> Splitting:
    b1, b2, b3 = 0.0829844064174052, 0.396309801498368, -0.0390563049223486
    a1, a2 = 0.245298957184271, 0.604872665711080
    a3 = 0.5 - (a1 + a2)
    b4 = 1.0 - 2.0 * (b1 + b2 + b3)
    return Splitting("blanes_moan4", 4, (a1, a2, a3, a3, a2, a1),
                     (b1, b2, b3, b4, b3, b2, b1),
                     "S. Blanes & P. C. Moan, J. Comput. Appl. Math. 142 (2002) 313, "
                     "Table 3 (SRKN_6^b)", 3.163)


_VERLET = Splitting("verlet", 2, (1.0,), (0.5, 0.5),
                    "W. C. Swope et al., J. Chem. Phys. 76 (1982) 637, Eq. 7", 2.0)

SPLITTINGS: dict[str, Splitting] = {
    "verlet": _VERLET,
    "yoshida4": _yoshida4(1.0 - 2.0 * _W1, "yoshida4", _YOSHIDA_REF),
    "blanes_moan4": _blanes_moan4(),
    "position_verlet": _VERLET.swapped(
        "position_verlet", "position Verlet (drift-kick-drift); Swope et al. (1982)"),
    "position_yoshida4": _yoshida4(-_CBRT2 / (2.0 - _CBRT2), "position_yoshida4",
                                   "").swapped("position_yoshida4",
                                               _YOSHIDA_REF + " (drift first)"),
}
"""The methods by name (module docstring's table)."""

STABILITY_LIMITS: dict[str, float] = {n: m.stability for n, m in SPLITTINGS.items()}
"""Each method's ``stability`` by name: the largest stable ω h on the harmonic oscillator
v_t = -ω² u (dimensionless; Verlet: 2 exactly; the 4th-order ones: the stability
polynomial's first |trace| = 2 crossing, 3 digits, rounded down)."""


ORDER_METHODS: dict[int, str] = {2: "position_verlet", 4: "position_yoshida4"}
"""The method an order names (the continuum's ``order=`` and ``[models] order``: the
drift-first methods it has always stepped with)."""


def get_splitting(name: str | Splitting, table: dict[str, Splitting] | None = None,
                  what: str = "splitting method") -> Splitting:
    """The method called ``name`` in ``table`` (default :data:`SPLITTINGS`).

    A :class:`Splitting` is returned as it is; an unknown name is a ValueError naming
    ``what`` and listing the table's choices.
    """
    if isinstance(name, Splitting):
        return name
    table = SPLITTINGS if table is None else table
    try:
        return table[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown {what} {name!r}; choose one of {sorted(table)}") from None
