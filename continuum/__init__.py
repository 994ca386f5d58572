"""Long-wave continuum solvers for Hertzian chains, built on py-pde.

* :class:`BoussinesqPDE` — the corrected Eq. 4 of the paper (precompressed chains) in
  the well-posed Rosenau / improved-Boussinesq form;
* :class:`NesterenkoPDE` — Nesterenko's strongly nonlinear Eq. 7 (corrected,
  conservative), regularised by saturating its dispersion at the coercivity limit;
* :class:`KdVPDE` — the unidirectional KdV reduction of Eq. 4 with its sech² soliton.

Both chain equations take a :class:`Medium` (piecewise mass, contact stiffness and
static overlap, as plain arrays) in flux form on a staggered grid whose unit of length
is the grain diameter, so fields line up with grain numbers.  :func:`run` integrates
with the symplectic :class:`VerletSolver` (KdV: :class:`RK4Solver`), whose numba path is
one fused compiled loop per chunk (:mod:`continuum._stepper`: stepping, right-hand side,
tridiagonal solve, active window; the PDE's NumPy ``evolution_rate`` is the reference),
monitors energy and momentum, raises :class:`InstabilityError` on a NaN state or an
energy drift, and writes HDF5 through py-pde's ``FileStorage``.
:func:`sample_grains` reads a state grain by grain with the discrete solver's energy
definitions; :func:`energy_ratios` computes the paper's Table 2 for one interface.
This package imports :mod:`theory` only.
"""

from .boussinesq import BoussinesqPDE
from .initial import (
    compacton,
    compacton_parameters,
    from_grains,
    solitary_wave,
    solitary_wave_parameters,
)
from .kdv import KdVPDE
from .medium import Discretisation, Medium
from .nesterenko import NesterenkoPDE
from .sampling import GrainSample, sample_grains, section_energies
from .scattering import PAPER_VELOCITY_MAX, energy_ratios
from .solver import InstabilityError, RK4Solver, RunResult, VerletSolver, run

__all__ = [
    "BoussinesqPDE",
    "Discretisation",
    "GrainSample",
    "InstabilityError",
    "KdVPDE",
    "Medium",
    "NesterenkoPDE",
    "PAPER_VELOCITY_MAX",
    "RK4Solver",
    "RunResult",
    "VerletSolver",
    "compacton",
    "compacton_parameters",
    "energy_ratios",
    "from_grains",
    "run",
    "sample_grains",
    "section_energies",
    "solitary_wave",
    "solitary_wave_parameters",
]
