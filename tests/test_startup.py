"""Start-up of ``hertzchain run``: nothing is imported that the run does
not use.

A small run without ``--out`` needs NumPy, numba (which itself imports SciPy and, through
its extension hook, rocket-fft) and the solver; it must not import h5py (only when a
file is written or read), Dask, matplotlib, py-pde, the sweep machinery or tqdm (the
bar opens only once a run has lasted a second), nor SciPy's optimize, integrate or
interpolate (the wave train of a sonic vacuum is a closed form,
``discrete.waves._wave_of_energy``).  ``scipy.linalg`` is not in the list: numba imports
it itself when its CPU target loads the first kernel (``numba.np.arraymath`` checks for a
BLAS with ``scipy.linalg.cython_blas``, whose import runs ``scipy/linalg/__init__``).
Checked in a fresh interpreter: the test's own process has imported everything already.

A process that is one ``hertzchain`` command (``main()`` reading ``sys.argv``) runs with
the collector's young threshold raised and freezes it when ``main`` returns
(``hertzchain.cli.main``); a caller of ``main(argv)`` keeps its own collector.
"""

import json
import subprocess
import sys
import textwrap

TOML = """name = "small"
[chain]
[[chain.sections]]
n = 60
[initial]
kind = "impact"
v0 = 1.0
[run]
until_front_at = 40
"""

NOT_IMPORTED = ("h5py", "dask", "distributed", "matplotlib", "pde", "tqdm",
                "hertzchain.sweep.engine", "hertzchain.sweep.store", "hertzchain.compare",
                "hertzchain.reproduce.report", "continuum", "scipy.optimize",
                "scipy.integrate", "scipy.interpolate",
                # numba's threading layers: a chain below PARALLEL_MIN_GRAINS runs the
                # plain kernel, which has no parallel region (discrete.Simulation)
                "numba.np.ufunc.omppool", "numba.np.ufunc.tbbpool",
                "numba.np.ufunc.workqueue")


def _modules_after(argv: list[str], tmp_path) -> set[str]:
    code = textwrap.dedent(f"""
        import json, sys
        from hertzchain.cli import main
        status = main({argv!r})
        print(json.dumps(sorted(sys.modules)), file=sys.stderr)
        sys.exit(status)
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return set(json.loads(proc.stderr.strip().splitlines()[-1])), proc.stdout


def test_small_run_imports_only_what_it_uses(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(TOML)
    mods, out = _modules_after(["run", str(path), "--json"], tmp_path)
    assert json.loads(out)["completed"] is True
    loaded = sorted(m for m in NOT_IMPORTED if m in mods)
    assert not loaded, f"a small run imported {loaded}"
    assert "numba" in mods and "discrete.kernels" in mods  # (the check can fail)


def test_version_and_help_import_no_solver(tmp_path):
    code = ("import sys\nfrom hertzchain.cli import build_parser\nbuild_parser()\n"
            "print(sorted(m for m in ('numpy', 'numba', 'h5py', 'importlib.metadata')"
            " if m in sys.modules))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"
    proc = subprocess.run([sys.executable, "-m", "hertzchain.cli", "--version"],
                          capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert proc.returncode == 0 and proc.stdout.startswith("hertzchain "), proc


def _gc_after(call: str, tmp_path) -> tuple[bool, int, bool, int]:
    """Collector enabled, objects frozen by ``call``, numba loaded, the youngest
    generation's threshold: in a fresh process."""
    code = "\n".join([
        "import gc, json, sys",
        "from hertzchain.cli import main",
        "freeze0 = gc.get_freeze_count()",
        call,
        "print(json.dumps([gc.isenabled(), gc.get_freeze_count() - freeze0,"
        " 'numba' in sys.modules, gc.get_threshold()[0]]), file=sys.stderr)",
        "sys.exit(status)",
    ])
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return tuple(json.loads(proc.stderr.strip().splitlines()[-1]))


def test_command_line_process_freezes_the_collector(tmp_path):
    # main() of the process's own command line (argv None): collector enabled, young
    # threshold raised, everything alive frozen when main returns (skipped at exit)
    argv = ["hertzchain", "theory", "--alpha-rho", "2", "--alpha-kn", "1", "--json"]
    from hertzchain.cli import GC_THRESHOLD0

    enabled, frozen, numba_loaded, threshold = _gc_after(
        f"sys.argv = {argv!r}; status = main()", tmp_path)
    assert enabled and numba_loaded
    assert frozen > 50_000  # NumPy, numba, SciPy and the solver (~9e4 here)
    assert threshold == GC_THRESHOLD0 != 700  # young collections spaced out
    # a caller passing argv keeps its collector as it was
    enabled, frozen, _, threshold = _gc_after(f"status = main({argv[1:]!r})", tmp_path)
    assert enabled and frozen == 0 and threshold == 700


def test_parser_of_one_command_parses_as_the_whole():
    # main() builds only the parser of the command given first (hertzchain.cli.COMMANDS);
    # the list is every registered command, and one command's parser reads its own
    # arguments as the whole parser does
    from hertzchain.cli import COMMANDS, build_parser

    def commands(parser):
        return set(next(a for a in parser._actions if a.dest == "command").choices)

    assert commands(build_parser()) == set(COMMANDS)
    argv = ["run", "x.toml", "--json", "--threads", "2", "--rtol", "1e-4"]
    whole, alone = build_parser().parse_args(argv), build_parser("run").parse_args(argv)
    assert commands(build_parser("run")) == {"run"}
    assert {k: v for k, v in vars(whole).items()} == {k: v for k, v in vars(alone).items()}
    assert commands(build_parser("sweep")) == {"sweep", "plot-sweep"}
