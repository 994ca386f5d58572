"""The memory measures of ``hertzchain reproduce`` (issue 13) that are not about numbers.

The numbers they must leave unchanged are checked elsewhere (the items' JSON in
``test_reproduce.py`` and ``test_reproduce_parallel.py``, the Table 2 point file in
``test_reproduce_table2_store.py``, ``Record.energy_grids`` in
``tests/discrete/test_recording_grids.py``); the peak RSS is measured by
``benchmarks/reproduce.py``, not here.
"""

import platform

import pytest

from hertzchain.reproduce import FIRST, ITEMS, LANES, lanes
from hertzchain.reproduce.common import MMAP_THRESHOLD, map_large_arrays
from hertzchain.reproduce.table2 import POINTS, RUN_ORDER, in_run_order


def test_points_run_largest_first_and_keep_their_order_otherwise():
    assert sorted(RUN_ORDER) == sorted(POINTS) and RUN_ORDER[0] == "Q"
    assert in_run_order(POINTS) == list(RUN_ORDER)
    assert in_run_order(["P", "M"]) == ["M", "P"]
    assert in_run_order(["x", "Q", "y"]) == ["Q", "x", "y"]  # others after, in order


def test_fig8_and_table2_first_in_every_layout():
    # one process: first; two: first after Fig. 3, on which the worker is forked
    assert lanes(list(ITEMS), 1)[0][:2] == list(FIRST)
    assert LANES[1][0] == "fig3" and LANES[1][1:1 + len(FIRST)] == FIRST


def test_map_large_arrays_checks_its_threshold():
    for bad in (0, 4095, 32 * 2**20 + 1, 2**20 + 0.5, -1):
        with pytest.raises(ValueError, match="threshold"):
            map_large_arrays(bad)
    ok = map_large_arrays(MMAP_THRESHOLD)  # (process-wide; reproduce sets the same)
    assert ok is (platform.libc_ver()[0] == "glibc")
