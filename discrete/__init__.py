"""Discrete-element solver for 1-D chains of Hertzian spheres (paper Section 2, Eqs. 1-2).

Chains (:class:`Chain`, :class:`Section`), contact laws (:mod:`theory.laws`: Hertz,
power laws, viscoelastic Hertz), the :class:`Simulation` with numba kernels built per law
(:mod:`discrete.kernels`) and a NumPy reference (:mod:`discrete.reference`), the time
step (:class:`TimeStep`),
energies (:mod:`discrete.energy`), recording (:class:`Recording`, :class:`WaveAt`,
:class:`AtTime`), initial conditions (:mod:`discrete.initial`) and HDF5 output
(:func:`save`, :func:`load`).
"""

from theory.laws import HERTZ, ContactLaw, PowerLaw, ViscoelasticHertz

from .chain import Chain, Disorder, Periodic, Section, Tapered
from .initial import Initial, cut_wave, exact_wave, impact, place_wave, settled_wave
from .recording import AtTime, Record, Recording, Snapshot, WaveAt
from .simulation import InstabilityError, RunInfo, SavedSimulation, Simulation, State
from .timestep import DT_FRACTION, TimeStep, default_dt, expected_overlaps, stable_dt


def __getattr__(name: str):
    # HDF5 (h5py) is imported when a file is first written or read, not with the solver,
    # so that a run without output does not pay for its import at start-up
    if name in ("load", "save"):
        from . import io

        return getattr(io, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "DT_FRACTION",
    "HERTZ",
    "AtTime",
    "Chain",
    "ContactLaw",
    "Disorder",
    "Initial",
    "InstabilityError",
    "Periodic",
    "PowerLaw",
    "Record",
    "Recording",
    "RunInfo",
    "SavedSimulation",
    "Section",
    "Simulation",
    "Snapshot",
    "State",
    "Tapered",
    "TimeStep",
    "ViscoelasticHertz",
    "WaveAt",
    "cut_wave",
    "default_dt",
    "exact_wave",
    "expected_overlaps",
    "impact",
    "load",
    "place_wave",
    "save",
    "settled_wave",
    "stable_dt",
]
