r"""Static precompression of a chain of Hertz (or power-law) contacts.

In static equilibrium every contact of a one-dimensional chain between two walls
carries the same force F0 (no body forces).  With F = k_j δ_j^{3/2} this gives

.. math:: \delta_j = (F_0 / k_j)^{2/3},

i.e. the paper's relation k_n^L (δ0^L)^{3/2} = k_n^R (δ0^R)^{3/2} (below Eq. 9),
extended to any number of contacts (including the wall contacts); for the power law
F = k δ^n (``exponent`` n), δ_j = (F0/k_j)^{1/n}.
"""

from __future__ import annotations

import numpy as np

from ._validate import check_exponent, check_nonnegative, check_positive

__all__ = ["static_force", "static_overlap", "static_overlaps", "static_energy",
           "wave_contact_energy"]


def static_force(k, delta0, exponent=1.5):
    """Static contact force F0 = k δ0^n, N (paper Eq. 1 for Hertz, n = 3/2).

    Parameters
    ----------
    k : float or array
        Contact constant, N/m^n (Hertz: N/m^{3/2}; > 0).
    delta0 : float or array
        Static overlap, m (>= 0).
    exponent : float
        n of the law F = k δ^n, in [1, 10].
    """
    k = check_positive("k", k)
    delta0 = check_nonnegative("delta0", delta0)
    out = k * delta0 ** check_exponent(exponent)
    return out if out.ndim else float(out)


def static_overlap(force, k, exponent=1.5):
    """Static overlap δ0 = (F/k)^{1/n} of a contact carrying the force F, m.

    The inverse of :func:`static_force` (paper Eq. 1 for Hertz: (F/k)^{2/3}).

    Parameters
    ----------
    force : float or array
        Static contact force, N (>= 0).
    k : float or array
        Contact constant, N/m^n (> 0).
    exponent : float
        n of the law F = k δ^n, in [1, 10].
    """
    force = check_nonnegative("force", force)
    k = check_positive("k", k)
    out = np.asarray((force / k) ** (1.0 / check_exponent(exponent)), dtype=float)
    return out if out.ndim else float(out)


def static_overlaps(k_contacts, *, delta0=None, force=None, reference: int = 0,
                    exponent=1.5):
    """Static overlap of every contact from force equilibrium, m.

    Exactly one of ``delta0`` (the overlap of contact ``reference``, by default the
    first, i.e. the left section's δ0^L of the paper) or ``force`` (the wall force F0,
    N) must be given.  Returns δ_j = (F0/k_j)^{1/n}: (F0/k_j)^{2/3} for Hertz (paper,
    below Eq. 9).

    Parameters
    ----------
    k_contacts : array
        Contact constants, N/m^n (Hertz: N/m^{3/2}; > 0).
    delta0 : float, optional
        Static overlap of contact ``reference``, m (>= 0).
    force : float, optional
        Static contact force, N (>= 0).
    reference : int
        Index of the contact whose overlap is ``delta0``.
    exponent : float
        n of the law F = k δ^n, in [1, 10].
    """
    k = check_positive("k_contacts", np.atleast_1d(k_contacts))
    if (delta0 is None) == (force is None):
        raise ValueError("give exactly one of delta0 (m, >= 0) or force (N, >= 0)")
    n = check_exponent(exponent)
    if delta0 is not None:
        delta0 = float(check_nonnegative("delta0", delta0))
        if not -k.size <= reference < k.size:
            raise ValueError(f"reference must lie in [0, {k.size}) (got {reference})")
        f0 = k[reference] * delta0**n
    else:
        f0 = float(check_nonnegative("force", force))
    return (f0 / k) ** (1.0 / n)


def static_energy(k, delta, exponent=1.5):
    """Elastic energy stored in a contact, k δ^{n+1}/(n+1), J: (2/5) k δ^{5/2} for Hertz.

    The integral of F = k δ^n (paper Eq. 1 for n = 3/2); ``exponent`` n in [1, 10].
    """
    k = check_positive("k", k)
    delta = check_nonnegative("delta", delta)
    n = check_exponent(exponent)
    out = 0.4 * k * delta**2.5 if n == 1.5 else k * delta ** (n + 1.0) / (n + 1.0)
    return out if out.ndim else float(out)


def wave_contact_energy(r, k, delta0):
    """Wave potential energy of a Hertz contact, (2/5) k ([r]_+^{5/2} - δ0^{5/2}), J.

    (Any law: :meth:`theory.laws.ContactLaw.energy`.)

    The integral of the Hertz force (paper Eq. 1) minus the static energy of the same
    contact (docs/physics.md §6): negative when the contact is less compressed than at rest.
    Evaluated as δ0^{5/2} expm1((5/2) log1p((r - δ0)/δ0)), without the cancellation of
    r^{5/2} - δ0^{5/2} for a small wave on a large precompression (and as that plain
    difference where δ0^{5/2} is not a normal double, δ0 ≲ 1e-123 m).  Broadcasts; no
    validation (hot diagnostic path).

    Parameters
    ----------
    r : array_like
        Overlaps, m (negative: gap).
    k : array_like
        Hertz constants, N/m^{3/2}.
    delta0 : array_like
        Static overlaps, m (>= 0).
    """
    r = np.asarray(r, dtype=float)
    d0 = np.asarray(delta0, dtype=float)
    s = d0 * d0 * np.sqrt(d0)
    pos = d0 > 0
    safe = np.where(pos, d0, 1.0)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        x = np.maximum(np.where(pos, (r - d0) / safe, 0.0), -1.0)
        rel = s * np.expm1(2.5 * np.log1p(x))
        # δ0^{5/2} below the normal doubles (δ0 ≲ 1e-123 m): 0·inf or 0 in the product
        # form; there r ≫ δ0 and the plain difference has no cancellation
        rp_ = np.maximum(r, 0.0)
        plain = rp_ * rp_ * np.sqrt(rp_) - s
        rel = np.where((s < np.finfo(float).tiny) | ~np.isfinite(rel), plain, rel)
    rp = np.maximum(r, 0.0)
    out = np.where(pos, np.where(r > 0, rel, -s), rp * rp * np.sqrt(rp))
    return 0.4 * np.asarray(k, dtype=float) * out
