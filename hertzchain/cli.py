"""The ``hertzchain`` command-line tool.

Each sub-command lives in its own function ``cmd_<name>`` and is registered in
:func:`build_parser`; ``main`` returns the process exit status.
"""

from __future__ import annotations

import argparse
import errno
import gc
import json
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from ._argtypes import (
    add_checkpoint_argument,
    add_progress_argument,
    add_threads_argument,
    positive_float,
    print_json,
    progress_wanted,
    scenario_number,
)
from .faults import FailedWrites, is_disk_full, is_disk_full_text

__all__ = ["main", "build_parser", "run_command", "print_json", "resolve_run_out",
           "progress_wanted", "is_disk_full_text"]


def cmd_theory(args: argparse.Namespace) -> int:
    """Print the linear-acoustic interface predictions for (α_ρ, α_kn) or two materials.

    ``--left``/``--right`` name materials (:data:`theory.MATERIALS`); their ratios are
    :func:`theory.material_ratios` (equal diameters).  ``--delta0-over-d`` adds the sound
    speeds c0 of both sections (paper Eq. 5) for the left material and ``--diameter``.
    """
    import theory

    def material(flag: str, name: str | None):
        try:
            return None if name is None else theory.get_material(name)
        except ValueError as exc:
            raise ValueError(f"{flag}: {exc}") from None

    left = material("--left", args.left) or theory.PAPER_MATERIAL
    right = material("--right", args.right)
    if right is not None:
        if args.alpha_rho is not None or args.alpha_kn is not None:
            raise ValueError("give --right MATERIAL or --alpha-rho/--alpha-kn, not both (the "
                             "materials set the ratios)")
        alpha_rho, alpha_kn = theory.material_ratios(left, right)
    elif args.alpha_rho is None or args.alpha_kn is None:
        raise ValueError("give --alpha-rho and --alpha-kn (the ratios rho_R/rho_L and "
                         "k_n^R/k_n^L, > 0), or --right MATERIAL (and --left MATERIAL; "
                         "`hertzchain materials` lists them)")
    else:
        alpha_rho, alpha_kn = args.alpha_rho, args.alpha_kn
    pred = theory.predict(alpha_rho, alpha_kn)
    out = pred.to_dict()
    if right is not None:
        out = {"material_left": args.left or "paper", "material_right": args.right,
               "alpha_rho": alpha_rho, "alpha_kn": alpha_kn,
               **{k: v for k, v in out.items() if k not in ("alpha_rho", "alpha_kn")}}
    if args.delta0_over_d is not None and args.delta0_over_d > 0:
        d = args.diameter
        m = theory.grain_mass(d, left.density)
        k = theory.hertz_constant(d, left)
        c0l = theory.c0(k, m, d, args.delta0_over_d * d)
        out["delta0_over_d_left"] = args.delta0_over_d
        out["delta0_over_d_right"] = args.delta0_over_d * pred.delta0_ratio
        out["c0_left_m_per_s"] = c0l
        out["c0_right_m_per_s"] = c0l * pred.gamma_c0
        out.setdefault("material_left", left.name)
    if args.json:
        print_json(out)
        return 0
    width = max(len(k) for k in out)
    print("Interface predictions (paper Eqs. 9, 12, 13; linear acoustics)")
    for key, value in out.items():
        print(f"  {key:<{width}}  {_text(value)}")
    return 0


def cmd_materials(args: argparse.Namespace) -> int:
    """Print the material library (:data:`theory.MATERIALS`): values, units, sources."""
    from theory import MATERIALS

    rows = [m.to_dict() for m in MATERIALS.values()]
    if args.json:
        print_json(rows)
        return 0
    print("Materials (use a name in a scenario: material = \"brass\"; or in "
          "`hertzchain theory --left steel --right brass`)")
    head = f"  {'name':<20} {'density kg/m³':>13} {'E GPa':>8} {'ν':>6}  aliases"
    print(head)
    for r in rows:
        print(f"  {r['name']:<20} {r['density']:>13.0f} {r['youngs_modulus'] / 1e9:>8.4g} "
              f"{r['poisson_ratio']:>6.3g}  {', '.join(r['aliases']) or '—'}")
    print("Sources:")
    for r in rows:
        print(f"  {r['name']}: {r['description']}; {r['source']}")
    return 0


def _text(value) -> str:
    """A value for a person: floats to 6 digits, NaN/None as "n/a"."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)



def _with_rtol(scenario, rtol: float | None):
    """The scenario with ``[run] rtol`` set from ``--rtol`` (None: unchanged)."""
    return scenario if rtol is None else scenario.with_values({"run.rtol": rtol})


def add_rtol_argument(p: argparse.ArgumentParser) -> None:
    """``--rtol``: the relative accuracy of the discrete run (``[run] rtol``)."""
    p.add_argument("--rtol", type=positive_float, default=None, metavar="R",
                   help="relative accuracy of the recorded quantities, in (0, 1): dt chosen "
                   "from a step-doubling probe (overrides [run] rtol; an explicit [run] dt "
                   "wins)")



def add_force_argument(p: argparse.ArgumentParser, what: str) -> None:
    """``--force``: recompute, discarding what is cached or checkpointed."""
    p.add_argument("--force", action="store_true", help=what)


RESULT_SUFFIXES = (".h5", ".hdf5")
"""Suffixes that make ``run --out`` a file name; any other ``--out`` is a directory."""


def resolve_run_out(out, scenario_arg: str, name: str) -> Path | None:
    """The HDF5 file ``hertzchain run --out OUT`` writes (docs/guide/cli.md, ``--out``).

    ``OUT`` ending in ``.h5``/``.hdf5`` is that file; any other ``OUT`` is a directory
    (created if absent) and the file is ``OUT/<scenario name>.h5``.  Refused (OSError
    naming ``--out``): an existing file that is not an HDF5 result (the scenario itself:
    ``run s.toml --out s.toml`` replaced it), and the scenario file as output.
    """
    if out is None:
        return None
    out = Path(out)
    src = Path(scenario_arg)
    if src.exists() and out.exists() and os.path.samefile(out, src):
        raise FileExistsError(errno.EEXIST, f"--out {out} is the scenario file itself; "
                              "refusing to overwrite it with the run (give a directory "
                              "or a .h5 name)")
    if out.suffix.lower() in RESULT_SUFFIXES:
        return out
    if out.exists() and not out.is_dir():
        raise FileExistsError(errno.EEXIST, f"--out {out} is an existing file that is not "
                              "an HDF5 result (.h5); refusing to overwrite it. Give a "
                              "directory (the run is written there as <scenario>.h5) or "
                              "a file name ending in .h5")
    stem = "".join(c if c.isalnum() or c in "-_." else "_" for c in (name or "run"))
    return out / f"{stem.strip('.') or 'run'}.h5"


def cmd_run(args: argparse.Namespace) -> int:
    """Run every model of a scenario (:func:`hertzchain.models.run`), print a summary.

    With ``--out`` the discrete run is written (:func:`resolve_run_out`: a ``.h5`` file,
    or ``DIR/<scenario>.h5``), checkpointed to ``<file>.ckpt`` every
    ``--checkpoint-interval`` seconds of wall time (rerunning the same command resumes
    from it, bit for bit; ``--force`` discards it), and a continuum beside it (the
    suffix ``.continuum.h5``).

    Exit status 0 when every model completed; 2 on an error (invalid scenario,
    unreachable stop, instability, I/O); :data:`EXIT_INCOMPLETE` (3) when a run ended
    before the stop the scenario asked for (``completed`` false: ``max_steps`` came
    first, a snapshot was never taken, or the continuum failed);
    :data:`EXIT_NOT_VERIFIED` (4) when it completed but its kinetic/potential split is
    not verified to the rtol asked for (``split_meets_rtol`` false) — the summary is
    printed and written all the same.
    """
    from .checkpoint import OutputWriteError
    from .files import check_output
    from .models import run
    from .scenario import load_scenario

    scenario = _with_rtol(load_scenario(args.scenario), args.rtol)
    out = resolve_run_out(args.out, args.scenario, scenario.name)
    if out is not None:  # a read-only place or a directory: refused before the run
        check_output(out, "file")
        if scenario.models.continuum:  # written beside it
            check_output(Path(out).with_suffix(".continuum.h5"), "file")

    def log(message: str) -> None:
        print(f"hertzchain: {message}", file=sys.stderr, flush=True)

    try:
        result = run(scenario, out=out, progress=progress_wanted(args),
                     checkpoint_interval=args.checkpoint_interval, resume=not args.force,
                     threads=args.threads, log=log)
    except OutputWriteError as exc:  # finished, but the file failed: show what was found
        _print_summary(scenario, args, exc.summary)
        raise
    summary = result.summary()
    _print_summary(scenario, args, summary)
    if not args.json:
        for path in (out, getattr(result.continuum, "path", None)):
            if path:
                print(f"written: {path}")
    status = _incomplete_status(summary, out)
    from .measure import unverified

    if summary.get("split_meets_rtol") is False:
        print(f"hertzchain: error: the kinetic/potential split Ek_*/Ep_* is not verified "
              f"to rtol = {summary['rtol']:g} (its estimated error split_estimate = "
              f"{summary['split_estimate']:.2g}); Et_* and the other quantities are "
              "(the split's windows need the waves separated and away from the chain's "
              "ends: docs/physics.md §6)",
              file=sys.stderr)
    if unverified(summary):
        status = status or EXIT_NOT_VERIFIED
        print(f"hertzchain: error: not verified to rtol = {summary['rtol']:g}: "
              f"{', '.join(unverified(summary))} false", file=sys.stderr)
    failed = [m for m in result.models if m.name != "discrete" and not m.completed]
    for m in failed:
        print(f"hertzchain: error: the {m.name} model did not complete: {m.stopped_by}",
              file=sys.stderr)
    return EXIT_INCOMPLETE if failed else status



INTERFACE_KEYS = ("Ek_tr", "Ek_re", "Ep_tr", "Ep_re", "Et_tr", "Et_re", "front_speed_re",
                  "front_speed_tr_over_c0L", "transmitted", "reflected",
                  "n_transmitted_pulses", "separated", "separation_fraction",
                  "split_estimate", "split_meets_rtol")
"""Summary quantities of the interface (:func:`hertzchain.runner.summarise`): a chain of
one section has none, and ``hertzchain run`` says so instead of printing them empty."""


def _print_summary(scenario, args: argparse.Namespace, summary: dict) -> None:
    """The summary of ``hertzchain run``: one strict JSON object, or a table."""
    if args.json:
        print_json(summary)
        return
    n_sections = len(scenario.chain.sections)
    print(f"scenario {scenario.name or args.scenario}: {scenario.chain.n} grains in "
          f"{n_sections} section{'s' if n_sections > 1 else ''}; models: "
          f"{', '.join(scenario.models.names)}")
    from .measure import TRAIN_KEYS

    for key, value in summary.items():
        if (n_sections == 1 and key in INTERFACE_KEYS) or key in TRAIN_KEYS \
                or key in ("train_waves", "train_note"):
            continue
        print(f"  {key:<26} {_text(value)}")
    if n_sections == 1:
        print(f"  {'interface':<26} none (one section: no transmitted or reflected wave)")
    if "train_waves" in summary:
        for line in train_lines(summary):
            print(f"  {line}")


def train_lines(summary: dict) -> list[str]:
    """The wave train of a run summary as text: "none (why)", or a table of its waves.

    (:func:`hertzchain.measure.train_summary`'s keys; the lists run front first.)
    """
    count = summary.get("train_waves")
    if not count:
        return [f"{'train':<26} none ({summary.get('train_note') or 'not measured'})"]
    lines = [f"{'train':<26} {count} solitary wave{'s' if count > 1 else ''}, front first:",
             f"    {'wave':>4} {'grain':>9} {'v_max (m/s)':>12} {'amplitude (m)':>14} "
             f"{'speed (m/s)':>12} {'energy (J)':>11}"]
    cols = [summary[k] for k in ("train_position", "train_velocity_max", "train_amplitude",
                                 "train_speed", "train_energy")]
    for j, (x, vm, a, c, e) in enumerate(zip(*cols, strict=True), start=1):
        lines.append(f"    {j:>4} {x:>9.2f} {vm:>12.5g} {a:>14.4g} {_text(c):>12} "
                     f"{e:>11.4g}")
    return lines


def cmd_compare(args: argparse.Namespace) -> int:
    """Run every model of a scenario and compare them (:mod:`hertzchain.compare`).

    Writes ``OUT/compare.h5``, the figures and ``OUT/report.md``/``.html`` (the runs are
    cached in ``OUT/runs``); prints the verdict and the differences, or with ``--json``
    every number.  Exit status :data:`EXIT_INCOMPLETE` (3) if a model did not complete
    (it is not compared).
    """
    from .compare import compare
    from .files import check_output
    from .scenario import load_scenario

    scenario = _with_rtol(load_scenario(args.scenario), args.rtol)
    check_output(args.out, "dir")  # before the runs, not after them
    _clean_caches(Path(args.out) / "runs", args.force)
    if args.continuum is not None:
        scenario = scenario.with_values(
            {"models.continuum": False if args.continuum == "off" else args.continuum})

    def log(message: str) -> None:
        print(f"hertzchain: {message}", file=sys.stderr, flush=True)

    cmp = compare(scenario, out=args.out, force=args.force, progress=progress_wanted(args),
                  checkpoint_interval=args.checkpoint_interval, threads=args.threads,
                  log=log)
    if args.json:
        print_json(cmp.to_dict())
    else:
        from .compare_output import difference_rows

        print(cmp.verdict())
        for row in difference_rows(cmp):
            print("  " + " | ".join(row))
        print(f"written: {args.out}/compare.h5, figures, report.md, report.html")
    failed = [m for m in cmp.run.models if not m.completed]
    for m in failed:
        print(f"hertzchain: error: the {m.name} model did not complete ({m.stopped_by}); "
              "it is not compared", file=sys.stderr)
    if cmp.unverified:  # the one exit-status contract (docs/guide/exit_status.md)
        print(f"hertzchain: error: the discrete run is not verified to rtol "
              f"({', '.join(cmp.unverified)} false)", file=sys.stderr)
    return EXIT_INCOMPLETE if failed else EXIT_NOT_VERIFIED if cmp.unverified else 0


EXIT_INCOMPLETE = 3
"""Exit status of a run that ended before the stop the scenario asked for."""

EXIT_NOT_VERIFIED = 4
"""Exit status of a run that reached its stop but whose kinetic/potential split is not
verified to the ``rtol`` it asked for (summary ``split_meets_rtol`` false)."""


def _incomplete_status(summary: dict, out) -> int:
    """0, or :data:`EXIT_INCOMPLETE` with a message if the run did not complete."""
    if summary.get("completed", True):
        return 0
    kept = f"; its results are in {out} (completed = false)" if out else ""
    print(f"hertzchain: error: incomplete run: {summary['incomplete_reason']}{kept}. Raise "
          "[run] max_steps or t_end, or move the stop or snapshots within reach",
          file=sys.stderr)
    return EXIT_INCOMPLETE


def file_info(path) -> dict:
    """What ``hertzchain info`` shows: the file's attributes (JSON ones decoded) and datasets.

    The file is first verified as :func:`hertzchain.files.describe` does (seal, readable
    objects, a discrete run's datasets): ValueError naming the file otherwise.
    """
    import h5py
    import numpy as np

    from .files import describe, open_result

    describe(path)  # the checks (ValueError naming the file)

    def value(v):
        if isinstance(v, bytes):
            v = v.decode()
        if isinstance(v, str) and v[:1] in "{[":
            try:
                return json.loads(v)
            except json.JSONDecodeError:
                return v
        if isinstance(v, np.ndarray):
            return v.tolist()
        return v.item() if isinstance(v, np.generic) else v

    datasets: dict = {}
    with open_result(path) as f:
        attrs = {k: value(f.attrs[k]) for k in sorted(f.attrs)}

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                datasets[name] = {"shape": list(obj.shape), "dtype": str(obj.dtype)}

        f.visititems(visit)
    return {"file": str(path), "attributes": attrs, "datasets": datasets}


def _info_lines(obj, indent: str = "  ") -> list[str]:
    """Nested attributes as indented ``key: value`` lines (no Python reprs)."""
    lines = []
    for key, val in obj.items():
        if isinstance(val, dict):
            lines.append(f"{indent}{key}:" + ("" if val else " (empty)"))
            lines += _info_lines(val, indent + "  ")
        elif isinstance(val, list) and val and all(isinstance(v, dict) for v in val):
            lines.append(f"{indent}{key}: ({len(val)})")
            for i, v in enumerate(val):
                lines.append(f"{indent}  [{i}]")
                lines += _info_lines(v, indent + "    ")
        elif isinstance(val, list):
            lines.append(f"{indent}{key}: " + (", ".join(_text(v) for v in val)
                                               if val else "(none)"))
        else:
            lines.append(f"{indent}{key}: {_text(val)}")
    return lines


def cmd_info(args: argparse.Namespace) -> int:
    """Describe an HDF5 file written by either solver: readable text, or ``--json``."""
    info = file_info(args.file)
    if args.json:
        print_json(info)
        return 0
    attrs = info["attributes"]
    print(f"{args.file}: {attrs.get('format', 'hertzchain result')}")
    print("attributes:")
    print("\n".join(_info_lines(attrs)))
    print("datasets:")
    for name, d in info["datasets"].items():
        print(f"  {name}  {' x '.join(map(str, d['shape'])) or 'scalar'}  {d['dtype']}")
    return 0


def cmd_plot(args: argparse.Namespace) -> int:
    """Plot an HDF5 result file to PNG (``--out``: a ``.png`` file or a directory)."""
    from .files import check_output, plot_file

    out = args.out
    if out is not None:
        out = Path(out)
        if out.suffix.lower() != ".png":  # a directory (docs/guide/cli.md, --out)
            if out.exists() and not out.is_dir():
                raise FileExistsError(errno.EEXIST, f"--out {out} is an existing file that "
                                      "is not a PNG; give a directory or a name ending in "
                                      ".png")
            out.mkdir(parents=True, exist_ok=True)
            out = out / f"{Path(args.file).stem}.png"
        check_output(out, "file")
    written = plot_file(args.file, out)
    print(f"written: {written}")
    return 0


def cmd_reproduce(args: argparse.Namespace) -> int:
    """Reproduce the paper's figures and Table 2 (:mod:`hertzchain.reproduce`)."""
    from .files import check_output
    from .reproduce.command import run_command

    if getattr(args, "out", None) is not None:
        check_output(args.out, "dir")  # before the runs, not after them
        for sub in ("runs", "cache"):
            _clean_caches(Path(args.out) / sub, getattr(args, "force", False))
    return run_command(args)


def _clean_caches(directory: Path, force: bool) -> None:
    """Remove killed writers' temporaries; with ``--force`` also the settled waves."""
    from .cache import clear_settled_waves, remove_stale_temporaries

    for p in remove_stale_temporaries(directory):
        print(f"hertzchain: removed {p}, left by a killed writer", file=sys.stderr)
    if force:
        for p in clear_settled_waves(directory):
            print(f"hertzchain: removed the settled wave {p} (--force)", file=sys.stderr)


class _DeprecatedAlias(argparse.Action):
    """An old flag spelling: works as ``new`` and says so once on stderr."""

    def __init__(self, option_strings, dest, new: str, **kwargs):
        self.new = new
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"hertzchain: {option_string} is deprecated; use {self.new}", file=sys.stderr)
        setattr(namespace, self.dest, True if self.nargs == 0 else values)


class _VersionAction(argparse.Action):
    """``--version``: the installed version, read only when asked for (start-up)."""

    def __call__(self, parser, namespace, values, option_string=None):
        from . import __version__

        print(f"hertzchain {__version__}")  # on stdout, as argparse's "version" action
        parser.exit()


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """Build the argument parser (docs/guide/cli.md: the grammar).

    Parameters
    ----------
    command : str, optional
        The sub-command about to be parsed: only its parser is built (a process runs
        one command; the others' options, and the modules that define them, are not
        needed).  None: every sub-command (``hertzchain --help``).
    """

    def wanted(name: str) -> bool:
        return command is None or command == name

    parser = argparse.ArgumentParser(
        prog="hertzchain",
        description="Solitary waves in Hertzian granular chains: discrete (DEM), "
        "continuum (long-wave) and closed-form theory, side by side. Grain indices count "
        "from 0; --out names where a command writes (a directory, or for run/plot a "
        ".h5/.png file); --json prints strict JSON; exit status 0 ok, 2 error, 3 "
        "incomplete, 4 not verified (docs/guide/cli.md).",
    )
    from .scenario import schema_key

    parser.add_argument("--version", action=_VersionAction, nargs=0,
                        help="show program's version number and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    if wanted("theory"):
        p = sub.add_parser("theory", help="interface predictions for (alpha_rho, alpha_kn) or "
                           "two materials")
        p.add_argument("--alpha-rho", type=positive_float, default=None,
                       help="density ratio rho_R/rho_L (> 0)")
        p.add_argument("--alpha-kn", type=positive_float, default=None,
                       help="contact-stiffness ratio k_n^R/k_n^L (> 0)")
        p.add_argument("--left", metavar="MATERIAL", default=None,
                       help="left section's material (default: the paper's steel; `hertzchain "
                       "materials` lists the names)")
        p.add_argument("--right", metavar="MATERIAL", default=None,
                       help="right section's material: the ratios follow (equal diameters), "
                       "instead of --alpha-rho/--alpha-kn")
        d0_key = schema_key("chain", "delta0_over_d")
        p.add_argument("--delta0-over-d", type=scenario_number("chain", "delta0_over_d"),
                       default=None, metavar="D0",
                       help="left-section precompression delta0/d (dimensionless, range "
                       f"{d0_key.range_text()}: [chain] delta0_over_d of a scenario); adds the "
                       "sound speeds c0")
        p.add_argument("--delta0", type=scenario_number("chain", "delta0_over_d"),
                       action=_DeprecatedAlias, new="--delta0-over-d", dest="delta0_over_d",
                       help=argparse.SUPPRESS)
        p.add_argument("--diameter", type=scenario_number("chain", "diameter"),
                       default=5e-3, help="grain diameter in m (> 0; default 5e-3, the paper's)")
        p.add_argument("--json", action="store_true", help="print one JSON object")
        p.set_defaults(func=cmd_theory)

    if wanted("materials"):
        p = sub.add_parser("materials", help="the material library: density, Young's modulus, "
                           "Poisson ratio and their sources")
        p.add_argument("--json", action="store_true", help="print one JSON list")
        p.set_defaults(func=cmd_materials)

    scenario_help = ("scenario TOML file, or the name of a shipped one (e.g. fig2a, "
                     "chain_sections: hertzchain/scenarios/)")
    if wanted("run"):
        p = sub.add_parser("run", help="run a scenario (the models of its [models] table)")
        p.add_argument("scenario", help=scenario_help)
        p.add_argument("--out", default=None, metavar="OUT",
                       help="write the full run: a directory (OUT/<scenario>.h5) or a file "
                       "name ending in .h5 (written atomically; checkpoints beside it, .ckpt)")
        p.add_argument("--json", action="store_true", help="print the summary as JSON")
        add_checkpoint_argument(p, "with --out, s (>= 0; default 300). Rerunning the same "
                                "command resumes from the last checkpoint, bit for bit; "
                                "Ctrl-C stops with a checkpoint")
        add_force_argument(p, "discard an existing checkpoint of --out and start over")
        p.add_argument("--restart", action=_DeprecatedAlias, new="--force", dest="force",
                       nargs=0, help=argparse.SUPPRESS)
        add_rtol_argument(p)
        add_threads_argument(p, "kernel threads (>= 1; default: numba's; results are "
                             "identical)")
        add_progress_argument(p)
        p.set_defaults(func=cmd_run)

    if wanted("compare"):
        p = sub.add_parser("compare", help="run the discrete chain, the continuum and the "
                           "theory of a scenario side by side and compare them")
        p.add_argument("scenario", help=scenario_help)
        p.add_argument("--out", default="hertzchain-compare", metavar="DIR",
                       help="output directory (compare.h5, figures, report.md, runs/; default "
                       "./hertzchain-compare)")
        p.add_argument("--json", action="store_true", help="print every number as JSON")
        p.add_argument("--continuum", default=None, metavar="MODEL",
                       help="override [models] continuum: \"auto\", a model of continuum.MODELS "
                       "(eq4, eq7, ...), kdv, or off (default: the scenario's; checked as the "
                       "scenario key)")
        add_force_argument(p, "recompute the runs even if cached in OUT/runs (discards "
                           "checkpoints)")
        add_checkpoint_argument(p, "of the discrete run, s (>= 0; default 300); rerunning "
                                "resumes from the last one")
        add_rtol_argument(p)
        add_threads_argument(p, "kernel threads of the discrete solver (>= 1)")
        add_progress_argument(p)
        p.set_defaults(func=cmd_compare)

    if wanted("reproduce"):
        from .reproduce.command import add_arguments as reproduce_arguments

        p = sub.add_parser("reproduce", help="reproduce the paper's Figs. 2-8 and Table 2")
        reproduce_arguments(p)
        p.set_defaults(func=cmd_reproduce)

    if wanted("info"):
        p = sub.add_parser("info", help="describe an HDF5 result file")
        p.add_argument("file", help="an HDF5 file written by hertzchain")
        p.add_argument("--json", action="store_true", help="print one JSON object")
        p.set_defaults(func=cmd_info)

    if wanted("plot"):
        p = sub.add_parser("plot", help="plot an HDF5 result file to PNG")
        p.add_argument("file", help="an HDF5 file written by hertzchain run")
        p.add_argument("--out", default=None, metavar="OUT",
                       help="a directory (OUT/<file>.png) or a file name ending in .png "
                       "(default: beside the file)")
        p.set_defaults(func=cmd_plot)

    if wanted("sweep") or wanted("plot-sweep"):
        from .sweep import add_sweep_parsers

        add_sweep_parsers(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments without the program name.  None (the ``hertzchain`` console
        script, ``python -m hertzchain``) reads ``sys.argv`` and means that the process
        ends when ``main`` returns: the garbage collector's youngest generation is then
        collected every :data:`GC_THRESHOLD0` allocations, and everything alive is
        frozen (:func:`gc.freeze`) when ``main`` returns, so that the interpreter's
        collections at exit skip the ~10^5 objects of the imports (NumPy, numba,
        SciPy), which the operating system reclaims anyway: much of a small run's
        CPU time (docs/benchmarks.md, "Start-up of a small run").  A caller passing
        ``argv`` (tests, scripts) keeps its collector as it was.

    Returns
    -------
    int
        The exit status.
    """
    whole_process = argv is None
    if whole_process:
        gc.set_threshold(GC_THRESHOLD0, *gc.get_threshold()[1:])
    try:
        return _main(argv, whole_process)
    finally:
        if whole_process:
            gc.freeze()


GC_THRESHOLD0 = 20_000
"""Young-generation threshold (allocations) of a process that is one ``hertzchain``
command (CPython's default is 700): numba's first kernel load creates ~10^5 long-lived
objects, over which young collections would pass again and again.  Cyclic garbage is
still freed, at most this many allocations later."""


COMMANDS = ("theory", "materials", "run", "compare", "reproduce", "info", "plot", "sweep",
            "plot-sweep")
"""The sub-commands :func:`build_parser` registers."""


def _main(argv: Sequence[str] | None, whole_process: bool) -> int:
    words = sys.argv[1:] if argv is None else list(argv)
    # a command given first is all that is parsed: only its parser is built
    parser = build_parser(words[0] if words and words[0] in COMMANDS else None)
    args = parser.parse_args(argv)
    if getattr(args, "func", None) is None:
        parser.print_help()
        return 0
    return run_command(args, whole_process=whole_process)


def run_command(args: argparse.Namespace, *, whole_process: bool = False) -> int:
    """Run a parsed command; every user error becomes one message and an exit status.

    ``hertzchain: error: ...`` on stderr and exit status 2 for invalid input, I/O errors
    and instabilities (no traceback); 130 on Ctrl-C (a checkpointed run: its own
    status).  On a full disk the HDF5 library's destructor tracebacks are suppressed
    (:class:`FailedWrites`) and, in a process that is one command, the process ends at
    once after the message (HDF5 objects of a failed write can crash the interpreter
    when they are freed).
    """
    from discrete import InstabilityError
    from theory.jitcache import announce_compilation

    from .checkpoint import Interrupted

    with FailedWrites() as failed:
        try:
            with announce_compilation():  # a cold kernel cache is announced before compiling
                status = int(args.func(args) or 0)
            disk_full = False
        except BrokenPipeError:  # output piped into e.g. `head`
            return 0
        except (ValueError, OSError, InstabilityError, MemoryError) as exc:
            if isinstance(exc, MemoryError):
                exc = MemoryError("out of memory: the chain or its recording does not fit "
                                  "(lower [chain.sections] n, t_end or the recording)")
            print(f"hertzchain: error: {exc}", file=sys.stderr)
            status, disk_full = 2, is_disk_full(exc)
        except Interrupted as exc:  # SIGINT/SIGTERM during a checkpointed run
            print(f"hertzchain: {exc}", file=sys.stderr)
            return exc.exit_code
        except KeyboardInterrupt:
            print("hertzchain: interrupted", file=sys.stderr)
            return 130
        if failed.count and not disk_full:  # a write failed inside, and was absorbed
            print(f"hertzchain: error: disk full: {failed.count} HDF5 write(s) failed "
                  f"({failed.example}); free space and rerun", file=sys.stderr)
            status, disk_full = max(status, 2), True
    if disk_full and whole_process:
        # a failed HDF5 write can leave h5py objects that crash the interpreter when
        # they are freed (a segfault after the message): leave at once
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    return status


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
