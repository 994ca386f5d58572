"""The table of splitting methods (theory.splitting): consistency, symmetry, order,
stability limits, and the one-copy rule (discrete and continuum read it)."""

import numpy as np
import pytest

from theory.splitting import ORDER_METHODS, SPLITTINGS, STABILITY_LIMITS, get_splitting


def _propagator(m, x):
    """One step of ``m`` on the oscillator u'' = -u with ω h = x, as a 2×2 matrix."""
    kick = lambda b: np.array([[1.0, 0.0], [-b * x, 1.0]])  # noqa: E731
    drift = lambda a: np.array([[1.0, a * x], [0.0, 1.0]])  # noqa: E731
    first, second = (m.kick, m.drift) if m.kick_first else (m.drift, m.kick)
    op1, op2 = (kick, drift) if m.kick_first else (drift, kick)
    out = op1(first[0])
    for s in range(len(second)):
        out = op1(first[s + 1]) @ op2(second[s]) @ out
    return out


@pytest.mark.parametrize("name", sorted(SPLITTINGS))
def test_consistent_symmetric_and_stages(name):
    """Each set of coefficients sums to 1 (consistency; to 2 ulp) and is a palindrome
    (time-reversible); S counts the FSAL-merged evaluations of a kick-first method."""
    m = SPLITTINGS[name]
    assert sum(m.drift) == pytest.approx(1.0, abs=4e-16)
    assert sum(m.kick) == pytest.approx(1.0, abs=4e-16)
    assert m.drift == m.drift[::-1] and m.kick == m.kick[::-1]
    assert m.stages == (len(m.drift) if m.kick_first else len(m.kick))
    assert get_splitting(name) is m and get_splitting(m) is m


@pytest.mark.parametrize("name", sorted(SPLITTINGS))
def test_order_on_the_oscillator(name):
    """The one-step error against exp(h A) of the oscillator scales as h^(p+1): the
    measured local order from h = 0.1 and 0.05 is within 0.15 of p + 1 (measured within
    0.02)."""
    m = SPLITTINGS[name]

    def err(x):
        exact = np.array([[np.cos(x), np.sin(x)], [-np.sin(x), np.cos(x)]])
        return np.abs(_propagator(m, x) - exact).max()

    p = np.log(err(0.1) / err(0.05)) / np.log(2.0)
    assert abs(p - (m.order + 1)) < 0.15, p


@pytest.mark.parametrize("name", sorted(SPLITTINGS))
def test_stability_limit(name):
    """|trace| of the oscillator's one-step matrix stays <= 2 (stable) below the
    tabulated ω h and exceeds it within 1e-3 above (Verlet: 2 exactly)."""
    m = SPLITTINGS[name]
    lim = STABILITY_LIMITS[name]
    xs = np.linspace(1e-3, lim, 2000)
    assert all(abs(np.trace(_propagator(m, x))) <= 2 + 1e-12 for x in xs)
    assert abs(np.trace(_propagator(m, lim + 1e-3))) > 2


def test_names_and_the_two_yoshida_roundings():
    """The drift-first entries are the kick-first ones swapped; the two Yoshida-4 w0 are
    the solvers' historical roundings (1 ulp apart), kept for bit-for-bit results."""
    assert ORDER_METHODS == {2: "position_verlet", 4: "position_yoshida4"}
    v, pv = SPLITTINGS["verlet"], SPLITTINGS["position_verlet"]
    assert (pv.drift, pv.kick) == (v.kick, v.drift)
    y, py = SPLITTINGS["yoshida4"], SPLITTINGS["position_yoshida4"]
    c = 2.0 ** (1.0 / 3.0)
    assert y.drift[1] == 1.0 - 2.0 / (2.0 - c) and py.kick[1] == -c / (2.0 - c)
    assert 0 < abs(y.drift[1] - py.kick[1]) <= np.spacing(abs(y.drift[1]))
    with pytest.raises(ValueError, match="unknown splitting method 'rk4'; choose one of"):
        get_splitting("rk4")


def test_one_copy_of_the_coefficients():
    """discrete.integrators registers the table's kick-first methods (the same objects)
    and refuses a drift-first one; the continuum's kernel passes come from it."""
    from continuum.solver import splitting_coefficients
    from discrete.integrators import INTEGRATORS, get_integrator

    assert INTEGRATORS == {n: m for n, m in SPLITTINGS.items() if m.kick_first}
    assert all(INTEGRATORS[n] is SPLITTINGS[n] for n in INTEGRATORS)
    with pytest.raises(ValueError, match="drift first"):
        get_integrator(SPLITTINGS["position_verlet"])
    alpha, beta = splitting_coefficients("blanes_moan4")
    bm = SPLITTINGS["blanes_moan4"]
    assert tuple(alpha) == (0.0, *bm.drift, 0.0) and tuple(beta) == bm.kick
    alpha, beta = splitting_coefficients(4)
    assert tuple(alpha) == SPLITTINGS["position_yoshida4"].drift


def test_scenario_names_every_method_and_its_limit():
    """hertzchain.scenario writes the table's names out (its import stays NumPy-free):
    the same names, and each method's stability limit is the derived table's."""
    from hertzchain.scenario import CONTINUUM_INTEGRATORS, INTEGRATORS
    from theory.splitting import STABILITY_LIMITS

    assert CONTINUUM_INTEGRATORS == tuple(SPLITTINGS)
    assert INTEGRATORS == tuple(n for n, m in SPLITTINGS.items() if m.kick_first)
    assert STABILITY_LIMITS == {n: m.stability for n, m in SPLITTINGS.items()}
    assert all(SPLITTINGS["position_" + n].stability == SPLITTINGS[n].stability
               for n in ("verlet", "yoshida4"))


# ------------------------------------------------------------- order conditions (BCH)
def _log_of_method(m, degree):
    """log of the composition ∏ exp(c X) in the free algebra of X ∈ {drift A, kick B},
    truncated at ``degree``: a list of arrays, level n of shape (2,)*n (the coefficient
    of each word of n letters, 0 = A, 1 = B).  A palindromic composition's log is the
    same read either way, so the product order does not matter here."""
    import math

    def exp(c, g):
        out = [np.ones(())]
        for n in range(1, degree + 1):
            a = np.zeros((2,) * n)
            a[(g,) * n] = c ** n / math.factorial(n)
            out.append(a)
        return out

    def mul(x, y):
        return [sum(np.multiply.outer(x[i], y[n - i]) for i in range(n + 1))
                for n in range(degree + 1)]

    first, second = ((m.kick, 1), (m.drift, 0)) if m.kick_first else ((m.drift, 0), (m.kick, 1))
    x = exp(first[0][0], first[1])
    for s in range(len(second[0])):
        x = mul(mul(x, exp(second[0][s], second[1])), exp(first[0][s + 1], first[1]))
    y = [np.zeros(())] + x[1:]
    out, p = [np.zeros((2,) * n) for n in range(degree + 1)], y
    for k in range(1, degree + 1):  # log(1 + y) = y - y²/2 + y³/3 - ...
        out = [o + (-1) ** (k + 1) / k * q for o, q in zip(out, p, strict=True)]
        p = mul(p, y)
    return out


@pytest.mark.parametrize("name", sorted(SPLITTINGS))
def test_order_conditions_in_the_free_lie_algebra(name):
    """The log of the composition (BCH, truncated at degree 4) is h(A + B) + O(h^(p+1)):
    degree 1 = A + B (consistency), degree 2 = 0 (symmetry gives every even degree),
    and for p = 4 the two degree-3 coefficients, of the words AAB and BBA (those of
    [A,[A,B]] and [B,[B,A]]), vanish: the 4th-order conditions of a symmetric
    splitting for the NONLINEAR problem u'' = a(u) (Hairer, Lubich & Wanner, Geometric
    Numerical Integration, 2006, §III.3 and §V.3; Blanes & Moan 2002, Sect. 2).  The
    degree-3 coefficients are polynomials of the coefficients; 1e-14 is ~50 ulp of
    sums of a dozen terms of size ≤ 2."""
    m = SPLITTINGS[name]
    L = _log_of_method(m, 4)
    assert L[1] == pytest.approx([1.0, 1.0], abs=1e-15)
    assert np.abs(L[2]).max() < 1e-15 and np.abs(L[4]).max() < 1e-14
    c3 = (L[3][0, 0, 1], L[3][1, 1, 0])
    if m.order == 4:
        assert np.abs(c3).max() < 1e-14, c3
    else:  # Verlet: the conditions fail, so the check can fail
        assert np.abs(c3).min() > 1e-2, c3


def _anharmonic_error(m, h, t_end=3.0):
    """Global error at t_end of u'' = -u - u³ (u(0) = 1, v(0) = 0), step h, against the
    method at h/8 (its own error 8^p times smaller)."""
    def run(hh):
        n = round(t_end / hh)
        u, v = 1.0, 0.0
        a_of = lambda u: -u - u ** 3  # noqa: E731
        for _ in range(n):
            if m.kick_first:
                v += m.kick[0] * hh * a_of(u)
                for s, a in enumerate(m.drift):
                    u += a * hh * v
                    v += m.kick[s + 1] * hh * a_of(u)
            else:
                u += m.drift[0] * hh * v
                for s, b in enumerate(m.kick):
                    v += b * hh * a_of(u)
                    u += m.drift[s + 1] * hh * v
        return np.array([u, v])
    return np.abs(run(h) - run(h / 8)).max()


@pytest.mark.parametrize("name", sorted(SPLITTINGS))
def test_order_on_a_nonlinear_problem(name):
    """Global order on the anharmonic oscillator u'' = -u - u³ (the nonlinear order
    conditions; the oscillator test alone checks only the linear ones): the fitted
    order from h = 0.1 and 0.05 at t = 3 (in the asymptotic range for every method, the
    largest ω h ≈ 0.17) is within 0.1 of p (measured 2.004 for both Verlets, 3.994 to
    4.024 for the 4th-order methods)."""
    m = SPLITTINGS[name]
    p = np.log2(_anharmonic_error(m, 0.1) / _anharmonic_error(m, 0.05))
    assert abs(p - m.order) < 0.1, p
