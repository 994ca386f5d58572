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
