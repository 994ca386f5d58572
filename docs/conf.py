"""Sphinx configuration of the hertzchain documentation.

Build: ``pip install -e ".[docs]"`` then ``sphinx-build -W --keep-going -b html docs
docs/_build/html`` (as ``.ci/run`` does).  The API reference lists every public module
of the four packages, found at build time (:func:`_public_modules`): a new module
appears without editing these files.  The gallery (``docs/examples/*.py``) is executed
at build time by sphinx-gallery.
"""

from __future__ import annotations

import os
import pkgutil
import re
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # build from a checkout without installing, too
HERE = Path(__file__).resolve().parent

import hertzchain  # noqa: E402

project = "hertzchain"
author = "hertzchain developers"
copyright = "hertzchain developers"  # noqa: A001
release = version = getattr(hertzchain, "__version__", "0.1.0")

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.json", "examples/README.txt",
                    "figures"]
myst_enable_extensions = ["dollarmath", "amsmath", "deflist"]
myst_heading_anchors = 3
suppress_warnings = [
    "myst.header",   # physics.md starts its sections at "##"
    "ref.python",    # a short name in a type field ("n") matching several attributes
]

# --- API reference --------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpy-style docstrings state the types
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
napoleon_use_ivar = True

PACKAGES = ("theory", "discrete", "continuum", "hertzchain")


def _public_modules() -> tuple[list[str], list[str]]:
    """Every public package and module of ours (no ``_private`` or ``__main__`` ones)."""
    packages, modules = [], []
    for pkg in PACKAGES:
        packages.append(pkg)
        mod = __import__(pkg)
        for info in pkgutil.walk_packages(mod.__path__, prefix=pkg + "."):
            if any(part.startswith("_") for part in info.name.split(".")):
                continue
            (packages if info.ispkg else modules).append(info.name)
    return sorted(packages), sorted(modules)


def _write_api_index() -> None:
    packages, modules = _public_modules()
    lines = ["API reference", "=============", "",
             "Generated from the docstrings: every public package and module of ``theory``, "
             "``discrete``, ``continuum`` and ``hertzchain``, found when the documentation is "
             "built.", "", "Packages", "--------", "",
             ".. autosummary::", "   :toctree: generated", "   :template: package.rst", ""]
    lines += [f"   {name}" for name in packages]
    lines += ["", "Modules", "-------", "",
              ".. autosummary::", "   :toctree: generated", "   :template: module.rst", ""]
    lines += [f"   {name}" for name in modules]
    text = "\n".join(lines) + "\n"
    path = HERE / "api.rst"
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


_write_api_index()
templates_path = ["_templates"]

# --- docstrings: |x| means an absolute value, not a reST substitution ---------------------
_LITERAL = re.compile(r"(``.+?``|`[^`]*`)")


def _escape_bars(app, what, name, obj, options, lines) -> None:
    """Escape ``|`` outside literals, roles and math blocks (run after napoleon).

    The docstrings write absolute values as ``|x|``, which reST would read as a
    substitution reference (an error).  Table rows and line blocks (``| ``, ``+``) are
    left alone, as are ``.. math::`` blocks and anything between backticks.
    """
    in_math, math_indent = False, 0
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if in_math:
            if stripped and indent <= math_indent:
                in_math = False
            else:
                continue
        if stripped.startswith(".. math::"):
            in_math, math_indent = True, indent
            continue
        if "|" not in line or stripped.startswith(("| ", "+")) or stripped == "|":
            continue
        parts = _LITERAL.split(line)
        lines[i] = "".join(p if k % 2 else p.replace("|", "\\|")
                           for k, p in enumerate(parts))


def _scenario_reference(app, what, name, obj, options, lines) -> None:
    """Append the scenario reference to ``hertzchain.scenario``'s page.

    The example and key tables are made from the registries of laws, initial kinds and
    continuum models (:func:`hertzchain.scenario.schema_reference`), so a registered law's
    keys appear without editing a docstring.
    """
    if what == "module" and name == "hertzchain.scenario":
        from hertzchain.scenario import schema_reference

        lines.extend(["", *schema_reference().splitlines()])


def setup(app) -> None:
    """Sphinx hooks: the scenario reference, then the docstring filter after napoleon's."""
    app.connect("autodoc-process-docstring", _scenario_reference, priority=550)
    app.connect("autodoc-process-docstring", _escape_bars, priority=600)

# --- gallery ----------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "within_subsection_order": "FileNameSortKey",
}
os.environ.setdefault("HERTZCHAIN_DOCS_BUILD", "1")

# --- HTML -------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = "hertzchain"
html_theme_options = {"show_toc_level": 2, "navigation_with_keys": False}
html_static_path: list[str] = []
