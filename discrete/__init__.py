"""Discrete-element solver for 1-D chains of Hertzian spheres (paper Section 2, Eqs. 1-2).

Chains (:class:`Chain`, :class:`Section`), the velocity-Verlet :class:`Simulation` with
numba kernels (:mod:`discrete.kernels`) and a NumPy reference (:mod:`discrete.reference`),
energies (:mod:`discrete.energy`), recording (:class:`Recording`, :class:`WaveAt`,
:class:`AtTime`), initial conditions (:mod:`discrete.initial`) and HDF5 output
(:func:`save`, :func:`load`).
"""

from .chain import Chain, Section
from .recording import AtTime, Record, Recording, Snapshot, WaveAt
from .simulation import (
    DT_FRACTION,
    InstabilityError,
    RunInfo,
    Simulation,
    State,
    default_dt,
    stable_dt,
)

__all__ = [
    "DT_FRACTION",
    "AtTime",
    "Chain",
    "InstabilityError",
    "Record",
    "Recording",
    "RunInfo",
    "Section",
    "Simulation",
    "Snapshot",
    "State",
    "WaveAt",
    "default_dt",
    "stable_dt",
]
