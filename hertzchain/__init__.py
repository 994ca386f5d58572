"""hertzchain: solitary waves in one-dimensional Hertzian granular chains.

The command-line tool and the study pipeline (paper scenarios, comparison of the
discrete, continuum and theory results, sweeps, reports).  The solvers live in the
sibling packages :mod:`discrete`, :mod:`continuum` and :mod:`theory`.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("hertzchain")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
