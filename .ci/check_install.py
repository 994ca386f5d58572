"""Check that hertzchain's packages import from where the last ``pip install`` put them.

Usage: ``python .ci/check_install.py installed|editable [--compile]`` from the repository
root, inside the venv.

The failure this guards against (issue 11): numba's default ``cache=True`` location is the
package's own ``__pycache__``; after ``pip install .`` a run wrote compiled files into
``site-packages/discrete/__pycache__/``, the next ``pip install -e .`` removed only the
files pip had installed, and the leftover ``site-packages/discrete/`` directory was
imported as an empty namespace package in front of the editable install.  Checked here:

* each package is a regular package (has ``__init__.py``), imported from the repository
  (``editable``) or from site-packages (``installed``);
* no directory of ours in site-packages holds a file pip did not install (for
  ``editable``: there is no such directory at all);
* ``--compile``: run a tiny discrete and continuum simulation first (compiling or loading
  the numba kernels), so a cache written into the package would be caught.
"""

from __future__ import annotations

import csv
import importlib.metadata
import importlib.util
import sys
import sysconfig
from pathlib import Path

PACKAGES = ("theory", "discrete", "continuum", "hertzchain")


def _compile() -> None:
    import continuum._kernels  # noqa: F401  (compiles or loads the continuum kernels)
    from discrete import Chain, WaveAt
    from discrete.initial import impact

    sim = impact(Chain.two_section(20, 0)).simulation()
    info = sim.run(until=WaveAt(15), progress=False)
    assert info.stopped_by == "wave_at=15", info


def _recorded(site: Path) -> set[Path]:
    dist = importlib.metadata.distribution("hertzchain")
    files = set()
    for row in csv.reader((dist.read_text("RECORD") or "").splitlines()):
        if row:
            files.add((site / row[0]).resolve())
    return files


def main(argv: list[str]) -> int:
    """Command-line entry point (see the module docstring)."""
    mode = argv[0]
    if mode not in ("installed", "editable"):
        raise SystemExit("usage: check_install.py installed|editable [--compile]")
    if "--compile" in argv:
        _compile()
    repo = Path.cwd().resolve()
    site = Path(sysconfig.get_paths()["purelib"]).resolve()
    errors = []
    for name in PACKAGES:
        spec = importlib.util.find_spec(name)
        origin = Path(spec.origin).resolve() if spec and spec.origin else None
        if origin is None or origin.name != "__init__.py":
            errors.append(f"{name}: not a regular package (namespace package from "
                          f"{list(spec.submodule_search_locations or []) if spec else None})")
            continue
        home = repo if mode == "editable" else site
        if not origin.is_relative_to(home):
            errors.append(f"{name}: imported from {origin}, expected under {home}")
    recorded = _recorded(site) if mode == "installed" else set()
    for name in PACKAGES:
        d = site / name
        if not d.exists():
            continue
        if mode == "editable":
            errors.append(f"{d} exists beside the editable install (it would shadow it)")
            continue
        stray = [p for p in d.rglob("*") if p.is_file() and p.resolve() not in recorded
                 and p.suffix != ".pyc"]
        if stray:
            errors.append(f"{d}: files pip did not install: {[str(p) for p in stray[:5]]}")
    for e in errors:
        print("check_install:", e, file=sys.stderr)
    if not errors:
        print(f"check_install: {mode} install OK ({', '.join(PACKAGES)} from "
              f"{repo if mode == 'editable' else site})")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
