"""Closed-form theory of solitary waves in Hertzian granular chains.

Materials and Hertz constants (:mod:`theory.materials`), static precompression
(:mod:`theory.precompression`), wave speeds (:mod:`theory.speeds`), linear-acoustic
interface predictions (:mod:`theory.interface`) and solitary-wave profiles
(:mod:`theory.profiles`).  Depends on nothing else of hertzchain.
"""

from .interface import (
    PAPER_POINTS,
    InterfacePrediction,
    alphas_from_gammas,
    energy_reflection,
    energy_transmission,
    gamma_c0,
    gamma_rg,
    predict,
    pressure_reflection,
    pressure_transmission,
    region,
    table2_prediction,
    velocity_reflection,
    velocity_transmission,
)
from .materials import (
    PAPER_DIAMETER,
    PAPER_MATERIAL,
    STEEL_TABLE1,
    Material,
    effective_modulus,
    grain_mass,
    hertz_constant,
    hertz_constant_wall,
    paper_kn,
)
from .precompression import static_energy, static_force, static_overlaps
from .profiles import (
    ChainState,
    DiscreteSolitaryWave,
    compacton_motion,
    compacton_strain,
    discrete_solitary_wave,
    discrete_speed_constant,
    kdv_soliton_motion,
    kdv_soliton_strain,
    kdv_soliton_width,
)
from .speeds import (
    c0,
    c_mat,
    kdv_speed,
    kdv_speed_exact,
    lattice_dispersion,
    linear_stiffness,
    nesterenko_speed,
    sonic_vacuum_speed,
)

__all__ = [
    "ChainState",
    "DiscreteSolitaryWave",
    "compacton_motion",
    "compacton_strain",
    "discrete_solitary_wave",
    "discrete_speed_constant",
    "kdv_soliton_motion",
    "kdv_soliton_strain",
    "kdv_soliton_width",
    "PAPER_POINTS",
    "PAPER_DIAMETER",
    "PAPER_MATERIAL",
    "STEEL_TABLE1",
    "InterfacePrediction",
    "Material",
    "alphas_from_gammas",
    "c0",
    "c_mat",
    "effective_modulus",
    "energy_reflection",
    "energy_transmission",
    "gamma_c0",
    "gamma_rg",
    "grain_mass",
    "hertz_constant",
    "hertz_constant_wall",
    "kdv_speed",
    "kdv_speed_exact",
    "lattice_dispersion",
    "linear_stiffness",
    "nesterenko_speed",
    "paper_kn",
    "predict",
    "pressure_reflection",
    "pressure_transmission",
    "region",
    "sonic_vacuum_speed",
    "static_energy",
    "static_force",
    "static_overlaps",
    "table2_prediction",
    "velocity_reflection",
    "velocity_transmission",
]
