"""Closed-form theory of solitary waves in Hertzian granular chains.

The contact laws shared by the three models (:mod:`theory.laws`: Hertz, power laws,
viscoelastic Hertz, with their long-wave coefficients), materials and Hertz constants
(:mod:`theory.materials`), static precompression (:mod:`theory.precompression`), wave
speeds (:mod:`theory.speeds`), linear-acoustic interface predictions
(:mod:`theory.interface`), solitary-wave profiles (:mod:`theory.profiles`) and the table
of symplectic splitting methods the solvers step with (:mod:`theory.splitting`).

Chains beyond the paper (docs/physics.md §14): vertical chains under gravity
(:mod:`theory.gravity`), tapered chains (:mod:`theory.tapers`), dimers and trimers
(:mod:`theory.dimers`), dissipative chains (:mod:`theory.dissipation`) and a heavy
striker's wave train (:mod:`theory.striker`).  Their public names are exported here too,
loaded on first use (these modules import SciPy, which ``import theory`` does not), except
the long-wave wave's energy and its inverse, whose names do not say which wave they
describe: use them as ``theory.gravity.solitary_wave_energy`` and
``theory.gravity.solitary_wave_amplitude`` (module access works for every name, e.g.
``theory.tapers.binary_collision``).

Depends on nothing else of hertzchain.
"""

import importlib

from .interface import (
    MAX_SOLITON_COUNT,
    PAPER_POINTS,
    InterfacePrediction,
    alphas_from_gammas,
    energy_reflection,
    energy_transmission,
    fission_parameter,
    gamma_c0,
    gamma_rg,
    predict,
    pressure_reflection,
    pressure_transmission,
    region,
    table2_prediction,
    transmitted_soliton_count,
    velocity_reflection,
    velocity_transmission,
)
from .laws import (
    HERTZ,
    LAWS,
    ContactLaw,
    LongWave,
    PowerLaw,
    ViscoelasticHertz,
    as_law,
    law_from_dict,
    register_law,
)
from .materials import (
    MATERIALS,
    PAPER_DIAMETER,
    PAPER_MATERIAL,
    STEEL_TABLE1,
    LibraryMaterial,
    Material,
    effective_modulus,
    get_material,
    grain_mass,
    hertz_constant,
    hertz_constant_wall,
    material_names,
    material_ratios,
    paper_kn,
    resolve_material_name,
)
from .precompression import (
    static_energy,
    static_force,
    static_overlap,
    static_overlaps,
    wave_contact_energy,
)
from .profiles import (
    ChainState,
    DiscreteSolitaryWave,
    SonicVacuumWave,
    compacton_motion,
    compacton_strain,
    compacton_width,
    discrete_solitary_wave,
    discrete_speed_constant,
    kdv_soliton_motion,
    kdv_soliton_strain,
    kdv_soliton_width,
    sonic_vacuum_wave_constants,
)
from .speeds import (
    c0,
    c_mat,
    kdv_speed,
    kdv_speed_exact,
    lattice_dispersion,
    linear_stiffness,
    long_wave_dispersion,
    nesterenko_speed,
    sonic_vacuum_speed,
)
from .splitting import ORDER_METHODS, SPLITTINGS, STABILITY_LIMITS, Splitting, get_splitting

__all__ = [
    "HERTZ",
    "LAWS",
    "ContactLaw",
    "LongWave",
    "PowerLaw",
    "ViscoelasticHertz",
    "as_law",
    "law_from_dict",
    "register_law",
    "compacton_width",
    "long_wave_dispersion",
    "static_overlap",
    "ChainState",
    "ORDER_METHODS",
    "SPLITTINGS",
    "STABILITY_LIMITS",
    "Splitting",
    "get_splitting",
    "DiscreteSolitaryWave",
    "compacton_motion",
    "compacton_strain",
    "discrete_solitary_wave",
    "discrete_speed_constant",
    "SonicVacuumWave",
    "sonic_vacuum_wave_constants",
    "kdv_soliton_motion",
    "kdv_soliton_strain",
    "kdv_soliton_width",
    "PAPER_POINTS",
    "PAPER_DIAMETER",
    "PAPER_MATERIAL",
    "STEEL_TABLE1",
    "InterfacePrediction",
    "Material",
    "LibraryMaterial",
    "MATERIALS",
    "get_material",
    "material_names",
    "material_ratios",
    "resolve_material_name",
    "alphas_from_gammas",
    "c0",
    "c_mat",
    "effective_modulus",
    "energy_reflection",
    "energy_transmission",
    "fission_parameter",
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
    "transmitted_soliton_count",
    "MAX_SOLITON_COUNT",
    "velocity_reflection",
    "velocity_transmission",
    "wave_contact_energy",
]

# -- chains beyond the paper: exported lazily (module docstring) --------------------------
# each module's __all__ but theory.gravity's solitary_wave_energy/solitary_wave_amplitude
# (module access only: generic names)
_CHAIN_MODULES: dict[str, tuple[str, ...]] = {
    "gravity": ("static_forces_under_gravity", "static_overlaps_under_gravity",
                "DepthExponents", "weak_wave_depth_exponents", "VerticalWave",
                "solitary_wave_descent", "weak_pulse_arrival_times"),
    "tapers": ("bca_velocities", "BinaryCollision", "binary_collision", "bca_arrival_times",
               "wall_impact_force", "TaperRatios", "geometric_taper_ratios",
               "AdiabaticTaperWave", "adiabatic_taper_wave"),
    "dimers": ("FIRST_ANTIRESONANCE_HERTZ", "HomogenisedCell", "homogenise_cell",
               "cell_sound_speed", "cell_solitary_speed", "antiresonance_mass_ratios"),
    "dissipation": ("kuwabara_kono_damping", "shock_from_piston", "critical_viscosity",
                    "ShockTail", "shock_tail_modes", "critical_viscosity_lattice",
                    "drag_wave_decay", "kuwabara_kono_wave_decay", "RESTITUTION_C1",
                    "RESTITUTION_C2", "restitution_series", "restitution_coefficient"),
    "striker": ("StrikerTrain", "striker_train"),
}
_LAZY = {name: module for module, names in _CHAIN_MODULES.items() for name in names}
__all__ += list(_LAZY)


def __getattr__(name: str):
    """Load a chain module, or one of its exported names, on first use (PEP 562)."""
    if name in _CHAIN_MODULES:
        return importlib.import_module(f"{__name__}.{name}")
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY) | set(_CHAIN_MODULES))
