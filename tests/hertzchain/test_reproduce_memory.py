"""The memory measures of ``hertzchain reproduce`` that are not about numbers.

The numbers they must leave unchanged are checked elsewhere (the items' JSON in
``test_reproduce.py`` and ``test_reproduce_parallel.py``, the Table 2 point file in
``test_reproduce_table2_store.py``, ``Record.energy_grids`` in
``tests/discrete/test_recording_grids.py``); the peak RSS is measured by
``benchmarks/reproduce.py``, not here.
"""

from hertzchain.reproduce.table2 import POINTS, RUN_ORDER, in_run_order


def test_points_run_largest_first_and_keep_their_order_otherwise():
    assert sorted(RUN_ORDER) == sorted(POINTS) and RUN_ORDER[0] == "Q"
    assert in_run_order(POINTS) == list(RUN_ORDER)
    assert in_run_order(["P", "M"]) == ["M", "P"]
    assert in_run_order(["x", "Q", "y"]) == ["Q", "x", "y"]  # others after, in order
