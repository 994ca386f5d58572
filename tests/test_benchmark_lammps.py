"""The pure parts of ``benchmarks/lammps.py``: the Hertz table, the log parser, the peak.

LAMMPS itself is never run here; the script is skipped where the benchmarks folder is
absent (an installed package without the repository).
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parent.parent / "benchmarks"


@pytest.fixture(scope="module")
def lmpbench():
    path = BENCH / "lammps.py"
    if not path.is_file():
        pytest.skip("benchmarks/lammps.py not present")
    sys.path.insert(0, str(BENCH))  # its own helpers (_machine)
    try:
        spec = importlib.util.spec_from_file_location("hc_bench_lammps", path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
    finally:
        sys.path.remove(str(BENCH))
    return mod


def _rows(text: str) -> np.ndarray:
    lines = text.splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("N ")) + 1
    return np.array([[float(x) for x in ln.split()] for ln in lines[start:] if ln.strip()])


def test_hertz_table_values_and_header(lmpbench):
    k, d, span, n = 5.0e9, 5e-3, 2e-5, 401
    text = lmpbench.hertz_table(k, d, span, n)
    lines = text.splitlines()
    assert "HERTZ" in lines
    header = next(ln for ln in lines if ln.startswith("N "))
    assert header.split()[:3] == ["N", str(n), "FPRIME"]
    # dF/dr at both ends of d − r: −(3/2) k span^{1/2} and 0
    assert float(header.split()[3]) == pytest.approx(-1.5 * k * math.sqrt(span), rel=1e-15)
    assert float(header.split()[4]) == 0.0
    t = _rows(text)
    assert t.shape == (n, 4)
    np.testing.assert_array_equal(t[:, 0], np.arange(1, n + 1))
    assert t[0, 1] == pytest.approx(d - span, rel=1e-15) and t[-1, 1] == d
    delta = d - t[:, 1]
    # Hertz: F = k δ^{3/2}, E = (2/5) k δ^{5/2}; zero at contact (r = d)
    np.testing.assert_allclose(t[:, 3], k * np.maximum(delta, 0) ** 1.5, rtol=1e-12, atol=0)
    np.testing.assert_allclose(t[:, 2], 0.4 * k * np.maximum(delta, 0) ** 2.5, rtol=1e-12,
                               atol=0)
    assert t[-1, 2] == 0.0 and t[-1, 3] == 0.0


def test_hertz_table_force_is_minus_energy_gradient(lmpbench):
    # an independent check of the pair: central differences of E against F, which LAMMPS
    # also checks (an inconsistent table would give a different force and energy)
    t = _rows(lmpbench.hertz_table(5.0e9, 5e-3, 2e-5, 2001))
    r, e, f = t[:, 1], t[:, 2], t[:, 3]
    fd = -(e[2:] - e[:-2]) / (r[2:] - r[:-2])
    # error of the central difference (h²/6) E''' relative to F: ~(h/δ)², h = 1e-8 m;
    # compared where δ ≥ 1e-6 m (≥ 100 h): ≤ 1e-4 · (1/8) ≈ 1e-5
    sel = (5e-3 - r[1:-1]) >= 1e-6
    np.testing.assert_allclose(fd[sel], f[1:-1][sel], rtol=2e-5)


@pytest.mark.parametrize("kw", [dict(k=0.0), dict(k=math.nan), dict(d=-1.0),
                                dict(span=0.0), dict(span=6e-3), dict(points=1)])
def test_hertz_table_rejects_bad_input(lmpbench, kw):
    args = dict(k=5e9, d=5e-3, span=1e-5, points=10) | kw
    name = next(iter(kw))
    with pytest.raises(ValueError, match=name):
        lmpbench.hertz_table(**args)


def test_collision_overlap_energy_balance(lmpbench):
    k, m, v = 5.0e9, 5.17e-4, 1.0
    dc = lmpbench.collision_overlap(k, m, v)
    # (1/2)(m/2) v² = (2/5) k δ_c^{5/2}
    assert 0.4 * k * dc ** 2.5 == pytest.approx(0.25 * m * v * v, rel=1e-13)


LOG = """LAMMPS (22 Jul 2025 - Update 4)
Setting up Verlet run ...
Per MPI rank memory allocation (min/avg/max) = 4.2 | 4.2 | 4.2 Mbytes
Loop time of 2.3456 on 1 procs for 76069 steps with 2000 atoms

Performance: 0.420 ns/day, 57.139 hours/ns, 32432.101 timesteps/s, 64.864 Matom-step/s
87.5% CPU use with 1 MPI tasks x 1 OpenMP threads
"""


def test_parse_log(lmpbench):
    got = lmpbench.parse_log(LOG)
    assert got["loop"] == 2.3456 and got["steps"] == 76069 and got["atoms"] == 2000
    assert got["cpu_percent"] == 87.5
    assert got["loop_cpu"] == pytest.approx(2.3456 * 0.875, rel=1e-15)
    empty = lmpbench.parse_log("ERROR: nothing ran")
    assert math.isnan(empty["loop"]) and math.isnan(empty["loop_cpu"]) and empty["steps"] == -1


def test_parabola_peak_exact_for_a_parabola(lmpbench):
    x = np.arange(40.0)
    i, v = lmpbench.parabola_peak(3.0 - 0.5 * (x - 17.3) ** 2)
    assert i == pytest.approx(17.3, abs=1e-12) and v == pytest.approx(3.0, abs=1e-12)
    # a sampled cosine peak: vertex error O(h^2) of the peak's curvature scale
    t = np.arange(0, 200) * 0.01
    i, v = lmpbench.parabola_peak(np.cos(3.0 * (t - 1.23456)))
    assert i * 0.01 == pytest.approx(1.23456, abs=1e-6)
    # at an end: the sample itself
    assert lmpbench.parabola_peak(np.array([3.0, 2.0, 1.0])) == (0.0, 3.0)


def test_write_lammps_files(lmpbench, tmp_path):
    for style, cols in (("table", 5), ("granular", 7)):
        inp = lmpbench.write_lammps(tmp_path, 7, 1e-7, 10, style=style, watch=None)
        text = inp.read_text()
        assert "fix 1 all nve" in text and "run 10" in text and "timestep 1e-07" in text
        data = (tmp_path / f"chain_{style}.data").read_text().splitlines()
        i = data.index(next(ln for ln in data if ln.startswith("Atoms")))
        atoms = [ln.split() for ln in data[i + 2:i + 9]]
        assert all(len(a) == cols for a in atoms)
        # grains touching along x, d apart
        x = [float(a[-3]) for a in atoms]
        np.testing.assert_allclose(np.diff(x), lmpbench.D, rtol=1e-12)
    assert "pair_style table linear" in (tmp_path / "in.table").read_text()
    assert "atom_style atomic" in (tmp_path / "in.table").read_text()
    with pytest.raises(ValueError, match="style"):
        lmpbench.write_lammps(tmp_path, 7, 1e-7, 10, style="lj", watch=None)
