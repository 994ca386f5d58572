"""Shared pytest configuration, in the manner of py-pde's ``tests/conftest.py``."""

import logging
import os

import matplotlib
import numpy as np
import pytest
from hypothesis import settings

matplotlib.use("agg")

# Property tests draw the same examples in every run (a red CI is the code's, not the
# draw's); HYPOTHESIS_PROFILE=explore draws new ones, to search for failures.
settings.register_profile("repeatable", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


@pytest.fixture(autouse=True)
def _setup_and_teardown():
    """Raise on floating-point errors (except underflow); close figures afterwards."""
    import matplotlib.pyplot as plt

    old = np.seterr(all="raise", under="ignore")
    yield
    np.seterr(**old)
    plt.close("all")


@pytest.fixture(scope="module")
def client():
    """A Dask client on two in-process workers (threads), one per test module: fast to
    start, and point functions need no pickling.  A module needing another cluster
    defines its own ``client``."""
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=":0", silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as c:
        yield c


@pytest.fixture
def rng():
    """A seeded random number generator, so tests are reproducible."""
    return np.random.default_rng(0)


def pytest_addoption(parser):
    parser.addoption("--runslow", action="store_true", default=False,
                     help="also run tests marked slow")


def pytest_collection_modifyitems(config, items):
    if config.getoption("--runslow"):
        return
    skip_slow = pytest.mark.skip(reason="slow: run with --runslow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip_slow)
