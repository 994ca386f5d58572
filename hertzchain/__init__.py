"""hertzchain: solitary waves in one-dimensional Hertzian granular chains.

The command-line tool and the study pipeline (paper scenarios, comparison of the
discrete, continuum and theory results, sweeps, reports).  The solvers live in the
sibling packages :mod:`discrete`, :mod:`continuum` and :mod:`theory`.

Nothing is imported here: ``__version__`` is read from the installed metadata when it
is first asked for, so that ``hertzchain run`` does not pay for it at start-up.
"""

from functools import cache

__all__ = ["__version__"]


@cache
def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("hertzchain")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "0.0.0+unknown"


def __getattr__(name: str):
    if name == "__version__":
        return _version()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
