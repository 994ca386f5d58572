"""Fixtures for the discrete-solver tests."""

import numpy as np
import pytest

from discrete import Chain


def random_composite(rng, n=60, *, delta0=2e-7, exponent=1.5):
    """A random composite chain of steel-like grains (masses ×[0.2, 5], k ×[0.2, 5]).

    ``exponent``: the contact law's n the static overlaps balance (theory.laws).
    """
    m0, k0 = 5.17e-4, 5.0e9
    mass = m0 * np.exp(rng.uniform(np.log(0.2), np.log(5.0), n))
    k = k0 * np.exp(rng.uniform(np.log(0.2), np.log(5.0), n + 1))
    d = 5e-3 * np.ones(n)
    return Chain.from_arrays(mass, k, delta0, diameter=d, section=np.arange(n) // 20,
                             exponent=exponent)


@pytest.fixture
def make_composite():
    """The factory :func:`random_composite` (importlib mode cannot import conftest)."""
    return random_composite
