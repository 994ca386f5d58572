"""Discrete-element solver for 1-D chains of Hertzian spheres (paper Section 2, Eqs. 1-2).

Chains (:class:`Chain`, :class:`Section`), the velocity-Verlet :class:`Simulation` with
numba kernels (:mod:`discrete.kernels`) and a NumPy reference (:mod:`discrete.reference`),
energies (:mod:`discrete.energy`), recording (:class:`Recording`, :class:`WaveAt`,
:class:`AtTime`), initial conditions (:mod:`discrete.initial`) and HDF5 output
(:func:`save`, :func:`load`).
"""

from .chain import Chain, Section
from .initial import Initial, cut_wave, exact_wave, impact, place_wave, settled_wave
from .io import load, save
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
    "Initial",
    "InstabilityError",
    "Record",
    "Recording",
    "RunInfo",
    "Section",
    "Simulation",
    "Snapshot",
    "State",
    "WaveAt",
    "cut_wave",
    "default_dt",
    "exact_wave",
    "impact",
    "load",
    "place_wave",
    "save",
    "settled_wave",
    "stable_dt",
]
