r"""The conservative power law :math:`F = k[\delta]_+^n`; Hertz's law (n = 3/2) is the default.

Nesterenko, *Dynamics of Heterogeneous Materials*, Springer 2001, §1.1: n = 3/2 for
spheres (Hertz; paper Eq. 1), n = 1 a linear spring (cylinders along their axis, and
the harmonic chain), n = 2 cones.
"""

from __future__ import annotations

import math
from typing import Any

from .base import ContactLaw, LawParameter, compile_piece

__all__ = ["PowerLaw", "HERTZ"]


class PowerLaw(ContactLaw):
    r"""Conservative power law :math:`F = k[\delta]_+^n` (N), n >= 1.

    n = 3/2: Hertz (paper Eq. 1; Johnson, *Contact Mechanics*, 1985, Eq. 4.22), the
    default; n = 1: linear spring; n = 2: cones (Nesterenko 2001, §1.1).  Elastic
    energy :math:`k[\delta]_+^{n+1}/(n+1)` (J).  k is in N/m^n.  Everything but the
    force (energy, stiffness, static overlap, long waves) is the base class's, which
    derives it from this elastic part.

    Parameters
    ----------
    exponent : float
        n, in [1, 10].
    """

    name = "power"
    dissipative = False
    summary = "F = k δ^n (n = exponent; 3/2 is Hertz, paper Eq. 1)"
    parameters = (LawParameter(
        "exponent", 1.5, "the exponent n (1 linear springs or cylinders, 3/2 spheres, 2 "
        "cones); the static overlaps balance k δ0^n", low=1, low_open=False,
        high=10, high_open=False),)

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
        """See :meth:`ContactLaw.make_force`: the elastic part, compiled."""
        elastic = self.make_elastic()

        def force(r, rd, k, p):
            return elastic(r, k)

        return compile_piece(force)

    def force(self, r, rd, k):
        """See :meth:`ContactLaw.force`: the elastic part k [r]_+^n, N."""
        return self.elastic(r, k)


HERTZ = PowerLaw(1.5)
"""Hertz's law F = k [δ]_+^{3/2} of the paper (Eq. 1): the default law."""
