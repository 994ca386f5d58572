"""The strongly nonlinear interface theory against the discrete chain (docs/physics.md §16).

Runs the discrete chain (paper Eq. 2) through the validity map's path — the scenario of
:func:`hertzchain.reproduce.validity.amplitude_row` (the exact discrete solitary wave,
its chain and run length), compared by :func:`hertzchain.compare.analyse` — and measures,
with the map's definition (``hertzchain/sweeps/model_validity.toml``), the error of

* ``linear``: today's theory (Nesterenko speeds, the linear-acoustic interface, paper
  Eqs. 9–13), the map's ``theory_error`` of the same run;
* ``new``: :func:`theory.strong_interface.predict_strong` (``theory = "auto"``), and
  each of its theories alone (``qp``: the quasi-particle theory, ``lat``: lattice
  acoustics),

error = max(|ΔE_T|, |ΔE_R| over the incident energy, relative transmitted front speed),
the predicted speed being ``speed_ratio`` times the exact incident wave's speed.

Two sets of points:

* ``grid``: the map's 5 × 5 interfaces (α_ρ, α_kn log-spaced in [1/4, 4]) at the
  strongly nonlinear amplitudes strain/δ0 = 9, 100 and the sonic vacuum (``--all``: all
  seven of the map's amplitudes, 175 points);
* ``off``: interfaces off that grid, log-uniform in [1/4, 4]² from a fixed seed, at
  strain/δ0 = 1, 1.5, 2, 2.5, 3, 4, 6, 9, 30, 100 and the sonic vacuum.  The crossover of the
  quasi-particle and lattice-acoustic theories' median errors on this set is
  :data:`theory.strong_interface.STRONG_THRESHOLD` (printed: "crossover").

A point costs well under a second of CPU (chains of 160-3,400 grains); numba compiles
the kernel first (tens of seconds).  The script lowers its own priority (``os.nice``).

    python benchmarks/strong_interface.py               # grid (75) + off-grid (24 x 11)
    python benchmarks/strong_interface.py --all         # the whole 175-point map too
    python benchmarks/strong_interface.py --off 8 --no-grid   # quick look
    python benchmarks/strong_interface.py --json out.json
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

GRID = tuple(float(x) for x in np.logspace(np.log10(0.25), np.log10(4.0), 5))
STRONG = (9.0, 100.0, math.inf)
OFF_AMPLITUDES = (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0, 9.0, 30.0, 100.0, math.inf)


def row_for(eps: float) -> dict:
    """The map's chain and wave for strain/δ0 = eps (its own rows where it has them)."""
    from hertzchain.reproduce.validity import AMPLITUDES, amplitude_row

    for amp, d0 in AMPLITUDES:
        if amp == eps:
            return amplitude_row(amp, d0)
    # as the map's rule: δ0/d = 1e-3 up to strain/δ0 = 1, smaller above (strain ≤ 1e-3)
    return amplitude_row(eps, 1e-3 if eps <= 1 else 1e-3 / eps)


def measure(alpha_rho: float, alpha_kn: float, eps: float) -> dict:
    """Run the discrete chain at one point; the discrete numbers and the theories' errors."""
    from hertzchain.compare import analyse
    from hertzchain.models import run
    from hertzchain.scenario import parse_scenario
    from theory.strong_interface import predict_strong

    row = row_for(eps)
    sc = parse_scenario({
        "name": "strong-interface-point",
        "chain": {"delta0_over_d": row["delta0_over_d"],
                  "sections": [{"n": row["n_left"]},
                               {"n": row["n_right"], "alpha_rho": alpha_rho,
                                "alpha_kn": alpha_kn}]},
        "initial": {"kind": "exact_wave", "center": row["center"],
                    "strain_max": row["strain_max"]},
        "run": {"t_end": row["t_end"]},
        "models": {"continuum": False, "samples": 60}})
    cmp = analyse(run(sc, samples=True))
    disc = cmp.series["discrete"]
    ratios = disc.ratios_at(cmp.i_compare)
    out = {"alpha_rho": alpha_rho, "alpha_kn": alpha_kn, "strain_over_delta0": eps,
           "Et_tr": ratios["Et_tr"], "Et_re": ratios["Et_re"],
           "speed_tr": disc.speeds["transmitted"], "speed_in_exact": row["speed"],
           "linear": cmp.errors["theory"]["error"], "note": cmp.notes.get("theory", "")}
    for key, which in (("new", "auto"), ("qp", "quasi-particle"), ("lat", "lattice acoustics")):
        if which == "lattice acoustics" and math.isinf(eps):
            out[key] = math.nan
            continue
        p = predict_strong(alpha_rho, alpha_kn, eps, theory=which)
        energy = max(abs(p.energy_transmission - out["Et_tr"]),
                     abs(p.energy_reflection - out["Et_re"]))
        speed = abs(p.speed_ratio * row["speed"] / out["speed_tr"] - 1.0)
        out[key] = max(energy, speed) if math.isfinite(out["speed_tr"]) else math.nan
        if key == "new":
            out.update(theory=p.theory, new_Et_tr=p.energy_transmission,
                       new_energy=energy, new_speed=speed)
    return out


def off_grid(count: int, seed: int = 7) -> list[tuple[float, float]]:
    """``count`` interfaces log-uniform in [1/4, 4]², none on the map's grid values."""
    rng = np.random.default_rng(seed)
    pts = np.exp(rng.uniform(math.log(0.25), math.log(4.0), size=(count, 2)))
    return [(round(float(a), 3), round(float(b), 3)) for a, b in pts]


def summary(rows: list[dict], key: str) -> tuple:
    e = np.array([r[key] for r in rows], dtype=float)
    ok = np.isfinite(e)
    if not ok.any():
        return 0, 0, 0, math.nan, math.nan
    return (int(ok.sum()), int(np.sum(e[ok] <= 0.01)), int(np.sum(e[ok] <= 0.10)),
            float(np.max(e[ok])), float(np.median(e[ok])))


def amp_label(eps: float) -> str:
    return "sonic vacuum" if math.isinf(eps) else f"{eps:g}"


def print_table(title: str, rows: list[dict], keys: tuple[str, ...]) -> None:
    print(f"\n{title}")
    print(f"{'strain/δ0':>13} | " + " | ".join(f"{k:^27}" for k in keys))
    print(f"{'':>13} | " + " | ".join(f"{'n  ≤1%  ≤10%   max   med':^27}" for _ in keys))
    for eps in sorted({r["strain_over_delta0"] for r in rows}):
        sel = [r for r in rows if r["strain_over_delta0"] == eps]
        cells = []
        for k in keys:
            n, w1, w10, mx, med = summary(sel, k)
            cells.append(f"{n:3d} {w1:3d} {w10:4d} {100 * mx:5.1f}% {100 * med:5.2f}%")
        print(f"{amp_label(eps):>13} | " + " | ".join(cells))


def crossover(rows: list[dict]) -> float:
    """strain/δ0 where the median errors of ``qp`` and ``lat`` cross (log-linear)."""
    amps = sorted({r["strain_over_delta0"] for r in rows if math.isfinite(r["lat"])})
    diff = []
    for eps in amps:
        sel = [r for r in rows if r["strain_over_delta0"] == eps]
        diff.append(summary(sel, "qp")[4] - summary(sel, "lat")[4])
    for (a0, d0), (a1, d1) in zip(zip(amps, diff, strict=True), zip(amps[1:], diff[1:],
                                                                    strict=True), strict=False):
        if d0 > 0 >= d1:
            return float(math.exp(math.log(a0) + (math.log(a1) - math.log(a0)) * d0 / (d0 - d1)))
    return math.nan


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--all", action="store_true", help="the map's seven amplitudes on the grid")
    ap.add_argument("--no-grid", action="store_true", help="skip the map's grid")
    ap.add_argument("--off", type=int, default=24, help="off-grid interfaces (default 24)")
    ap.add_argument("--seed", type=int, default=7, help="seed of the off-grid interfaces")
    ap.add_argument("--json", help="write every point to this file")
    args = ap.parse_args(argv)
    os.nice(10)
    t0 = time.perf_counter()
    measure(1.0, 1.0, math.inf)  # warm-up: numba compiles, the family table is built
    from hertzchain.reproduce.validity import AMPLITUDES

    grid_amps = tuple(a for a, _ in AMPLITUDES) if args.all else STRONG
    grid = [] if args.no_grid else [measure(a, k, e) for e in grid_amps for a in GRID
                                    for k in GRID]
    off = [measure(a, k, e) for e in OFF_AMPLITUDES for a, k in off_grid(args.off, args.seed)]
    print(f"load average {os.getloadavg()[0]:.1f}; {len(grid) + len(off)} points in "
          f"{time.perf_counter() - t0:.0f} s (wall)")
    keys = ("linear", "new", "qp", "lat")
    if grid:
        print_table("The map's 5 x 5 grid (error: max of |ΔE_T|, |ΔE_R|, relative "
                    "transmitted speed)", grid, keys)
        worst = max(grid, key=lambda r: r["new"] if math.isfinite(r["new"]) else -1)
        print(f"worst new: (α_ρ, α_kn) = ({worst['alpha_rho']:.3g}, {worst['alpha_kn']:.3g}) "
              f"at strain/δ0 = {amp_label(worst['strain_over_delta0'])}: "
              f"{100 * worst['new']:.1f}% ({worst['theory']}; E_T chain "
              f"{worst['Et_tr']:.4f}, theory {worst['new_Et_tr']:.4f})")
    if off:
        print_table(f"Off-grid: {args.off} interfaces, log-uniform in [1/4, 4]^2, seed "
                    f"{args.seed}", off, keys)
        print(f"crossover of the median errors of qp and lat (off-grid): strain/δ0 = "
              f"{crossover(off):.3g}")
        worst = max(off, key=lambda r: r["new"] if math.isfinite(r["new"]) else -1)
        print(f"worst new: (α_ρ, α_kn) = ({worst['alpha_rho']:.3g}, {worst['alpha_kn']:.3g}) "
              f"at strain/δ0 = {amp_label(worst['strain_over_delta0'])}: "
              f"{100 * worst['new']:.1f}% ({worst['theory']})")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"grid": grid, "off": off}, fh, indent=1,
                      default=lambda x: None if isinstance(x, float) and not math.isfinite(x)
                      else x)
    return 0


if __name__ == "__main__":
    sys.exit(main())
