"""Shared helpers for the continuum tests (peak tracking, shape comparison)."""

import numpy as np
from scipy.optimize import minimize_scalar


def peak_position(x, f):
    """Position of the maximum of samples f(x), by a parabola through three points."""
    i = int(np.argmax(f))
    a, b, c = f[i - 1], f[i], f[i + 1]
    return x[i] + 0.5 * (x[1] - x[0]) * (a - c) / (a - 2 * b + c)


def shape_change(x, f, profile, guess, window=None):
    """min over shifts X of ||f - profile(x - X)|| / ||profile(x - X)|| (optionally windowed).

    ``profile`` is a callable of the distance from the wave centre; ``window`` limits the
    norm to |x - X| <= window.
    """
    def err(xc):
        ref = profile(x - xc)
        m = np.ones_like(x, bool) if window is None else np.abs(x - xc) <= window
        return np.linalg.norm((f - ref)[m]) / np.linalg.norm(ref[m])

    res = minimize_scalar(err, bounds=(guess - 1.0, guess + 1.0), method="bounded",
                          options={"xatol": 1e-6})
    return float(res.fun), float(res.x)


def two_section(n_left, n_right, delta0, alpha_rho=1.0, alpha_kn=1.0, *, law=None, drag=0.0):
    """The paper's two-section chain (static overlap ``delta0`` m on the left) as a medium.

    Built once, by the discrete chain's builder (``discrete.Chain.two_section``), and
    handed over with :meth:`discrete.Chain.medium`.
    """
    import discrete
    import theory

    exponent = 1.5 if law is None else law.exponent
    d = theory.PAPER_DIAMETER
    secs = [discrete.Section(int(n_left), d, theory.PAPER_MATERIAL)]
    if n_right:
        secs.append(discrete.Section(int(n_right), d,
                                     theory.PAPER_MATERIAL.scaled(alpha_rho, alpha_kn)))
    chain = discrete.Chain.from_sections(secs, delta0=delta0, exponent=exponent)
    return chain.medium(law, drag)


def from_arrays(mass, k, delta0, *, law=None, drag=0.0):
    """A medium from per-grain masses and per-contact constants, δ0 of contact 1 (m).

    The other overlaps balance the same static force (``discrete.Chain.from_arrays``).
    """
    import discrete

    exponent = 1.5 if law is None else law.exponent
    return discrete.Chain.from_arrays(mass, k, delta0, exponent=exponent).medium(law, drag)
