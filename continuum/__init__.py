"""Long-wave continuum solvers for granular chains, built on py-pde.

* :class:`BoussinesqPDE` — the corrected Eq. 4 of the paper (precompressed chains) in
  the well-posed Rosenau / improved-Boussinesq form, for any contact law (its quadratic
  expansion about δ0 or the full law);
* :class:`NesterenkoPDE` — Nesterenko's strongly nonlinear Eq. 7 (corrected,
  conservative) for any power law F = kδ^n, regularised by saturating its dispersion at
  the coercivity limit;
* :class:`GrainAveragedPDE` — the grain-averaged quasi-continuum for the strongly
  nonlinear regime: the chain's exact averages over a grain (overlap and force) replaced
  by their [0/M] Padé approximant, for any elastic law (docs/physics.md §24);
* :class:`KdVPDE` — the unidirectional KdV reduction of Eq. 4 with its sech² soliton.

Both chain equations take a :class:`Medium` (:class:`theory.medium.Medium`: per-grain
masses, per-contact constants and static overlaps, the contact law, drag and gravity,
as plain arrays; ``discrete.Chain.medium()`` hands a chain over) in flux form on a
staggered grid whose unit of length is one grain, so fields line up with grain numbers;
every coefficient may vary from grain to grain (sections, tapers, gravity), periodic
sections are homogenised (:mod:`continuum.cells`: dimers, trimers), and dissipative laws
and drag add their viscous terms.  Their forces come from the law's compiled pieces
(:mod:`theory.laws`), fused into the steppers per law.  :func:`run` integrates with the
symplectic :class:`VerletSolver` (KdV: :class:`RK4Solver`), whose numba path is one
fused compiled loop per chunk (:mod:`continuum._stepper`: stepping, right-hand side,
tridiagonal solve, active window; the PDE's NumPy ``evolution_rate`` is the reference),
monitors energy (plus the dissipated energy) and momentum, raises
:class:`InstabilityError` on a NaN state or an energy drift, and writes HDF5 through
py-pde's ``FileStorage``.  :func:`sample_grains` reads a state grain by grain with the
discrete solver's energy definitions; :func:`energy_ratios` computes the paper's Table 2
for one interface.

Models are registered by name in :data:`MODELS` (``"eq4"``, ``"eq7"``, ``"qc"``): a new
continuum model is one file with a :class:`ChainPDEBase` subclass (``name``, ``label``,
:meth:`~ChainPDEBase.for_chain`, its own ``default_integrator`` and
``default_dt_safety``) and one :func:`register_model` call; scenario files
then select it by its ``name`` (``[models] continuum``, validated against
:data:`MODELS`) and legends show its ``label``.  This package imports :mod:`theory`
only.
"""

from theory.splitting import SPLITTINGS, STABILITY_LIMITS

from .base import ChainPDEBase
from .boussinesq import BoussinesqPDE
from .cells import homogenise
from .initial import (
    compacton,
    compacton_parameters,
    from_grains,
    launch_interpolation,
    solitary_wave,
    solitary_wave_parameters,
)
from .kdv import KdVPDE
from .medium import Discretisation, Medium, discretise
from .nesterenko import NesterenkoPDE
from .quasicontinuum import GrainAveragedPDE
from .sampling import GrainSample, sample_grains, section_energies
from .scattering import PAPER_VELOCITY_MAX, energy_ratios, section_lengths
from .solver import InstabilityError, RK4Solver, RunResult, VerletSolver, run

__all__ = [
    "BoussinesqPDE",
    "ChainPDEBase",
    "Discretisation",
    "GrainAveragedPDE",
    "GrainSample",
    "InstabilityError",
    "KdVPDE",
    "MODELS",
    "Medium",
    "NesterenkoPDE",
    "PAPER_VELOCITY_MAX",
    "RK4Solver",
    "RunResult",
    "VerletSolver",
    "compacton",
    "compacton_parameters",
    "discretise",
    "energy_ratios",
    "from_grains",
    "launch_interpolation",
    "homogenise",
    "register_model",
    "run",
    "sample_grains",
    "section_energies",
    "section_lengths",
    "solitary_wave",
    "solitary_wave_parameters",
]

MODELS: dict[str, type[ChainPDEBase]] = {}
"""The chain continuum models by name (``[models] continuum`` of a scenario)."""


def register_model(cls: type[ChainPDEBase]) -> type[ChainPDEBase]:
    """Register a continuum model class under its ``name`` (usable as a class decorator).

    ValueError unless ``cls`` is a :class:`ChainPDEBase` subclass with a non-empty
    ``name`` and ``label``, its own :meth:`~ChainPDEBase.for_chain` and its own time step
    (``default_integrator`` a method of :data:`theory.splitting.SPLITTINGS`,
    ``default_dt_safety`` in (0, half that method's stability limit): the step of a
    scenario that gives neither ``[models] integrator`` nor ``dt_safety``), or if another
    class holds the name.
    """
    if not (isinstance(cls, type) and issubclass(cls, ChainPDEBase)):
        raise ValueError(f"a continuum model must subclass continuum.ChainPDEBase (got {cls!r})")
    for attr in ("name", "label"):
        if not isinstance(getattr(cls, attr), str) or not getattr(cls, attr):
            raise ValueError(f"{cls.__name__}.{attr} must be a non-empty string")
    if cls.for_chain.__func__ is ChainPDEBase.for_chain.__func__:  # type: ignore[attr-defined]
        raise ValueError(f"{cls.__name__} must define the classmethod for_chain")
    method = getattr(cls, "default_integrator", None)
    if method not in SPLITTINGS:
        raise ValueError(f"{cls.__name__}.default_integrator must name a splitting method of "
                         f"theory.splitting.SPLITTINGS {sorted(SPLITTINGS)} (got {method!r})")
    safety, limit = getattr(cls, "default_dt_safety", None), 0.5 * STABILITY_LIMITS[method]
    if not (isinstance(safety, int | float) and 0 < safety < limit):
        raise ValueError(f"{cls.__name__}.default_dt_safety must lie in (0, {limit:.4g}), "
                         f"below half the stability limit of {method!r} (got {safety!r})")
    if MODELS.get(cls.name, cls) is not cls:
        raise ValueError(f"continuum model name {cls.name!r} is taken by "
                         f"{MODELS[cls.name].__qualname__}")
    MODELS[cls.name] = cls
    return cls


register_model(BoussinesqPDE)
register_model(NesterenkoPDE)
register_model(GrainAveragedPDE)
