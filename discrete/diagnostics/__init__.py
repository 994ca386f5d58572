"""Wave analysis and energy bookkeeping for Hertz-chain states (paper Section 4).

Everything works on plain arrays — displacements u, velocities v, overlaps r, masses,
Hertz constants k, static overlaps δ0, section indices — so it applies equally to
snapshots of the discrete solver and to fields sampled from the continuum solvers; a few
wrappers take a ``Chain``-like object (attributes ``mass``, ``k``, ``delta0``,
``section``).  Index conventions: N grains, N + 1 contacts, contact j between grains
j-1 and j (0 and N the walls), r_j = δ0_j + u_{j-1} - u_j.

* :mod:`.energies` — energies per grain/contact/section and the linear/quadratic split
  of the potential energy;
* :mod:`.ratios` — Table 2 ratios (the kinetic/potential split phase-averaged over the
  lattice period), "incident"/"separated" times, Fig. 8 scaling;
* :mod:`.waves` — pulses, front position/amplitude/speed (Fig. 6), 1st/2nd parts;
* :mod:`.classify` — fracture/squeeze and compressive/expansive classification (Fig. 7);
* :mod:`.modes` — contact-move/free-flight/static modes and gap events (Fig. 3c/d);
* :mod:`.convergence` — v̄max/v0 of Fig. 2 with its spread and trend.
"""

from .classify import (
    ReflectedClassification,
    TransmittedClassification,
    classify_reflected,
    classify_transmitted,
)
from .convergence import PlateauStats, choose_plateau_range, vmax_plateau
from .energies import (
    ChainEnergies,
    chain_energies,
    chain_energies_of,
    contact_energy,
    contact_linear_energy,
    kinetic_energy,
    overlaps_from_displacements,
    section_sums,
    section_weights,
    snapshot_energies,
)
from .modes import (
    CONTACT_MOVE,
    FREE_FLIGHT,
    MODE_NAMES,
    STATIC,
    GapEvents,
    GrainModes,
    ModeSegment,
    gap_events,
    grain_modes,
)
from .ratios import (
    EnergyRatios,
    energy_ratios,
    energy_ratios_from_grid,
    incident_time_index,
    interface_activity,
    normalise_to_incident_peak,
    phase_averaged_ratios,
    phase_window,
    separated_time_index,
    table2_ratios,
)
from .waves import (
    Pulse,
    SpeedFit,
    arrival_times,
    assign_parts_by_collisions,
    find_pulses,
    fit_speed,
    front_positions,
    leading_pulse,
    section_range,
    split_parts_at_gap,
)

__all__ = [
    "CONTACT_MOVE",
    "FREE_FLIGHT",
    "MODE_NAMES",
    "STATIC",
    "ChainEnergies",
    "EnergyRatios",
    "GapEvents",
    "GrainModes",
    "ModeSegment",
    "PlateauStats",
    "Pulse",
    "ReflectedClassification",
    "SpeedFit",
    "TransmittedClassification",
    "arrival_times",
    "assign_parts_by_collisions",
    "chain_energies",
    "chain_energies_of",
    "choose_plateau_range",
    "classify_reflected",
    "classify_transmitted",
    "contact_energy",
    "contact_linear_energy",
    "energy_ratios",
    "energy_ratios_from_grid",
    "find_pulses",
    "fit_speed",
    "front_positions",
    "gap_events",
    "grain_modes",
    "incident_time_index",
    "interface_activity",
    "kinetic_energy",
    "leading_pulse",
    "normalise_to_incident_peak",
    "phase_averaged_ratios",
    "phase_window",
    "overlaps_from_displacements",
    "section_range",
    "section_sums",
    "section_weights",
    "separated_time_index",
    "snapshot_energies",
    "split_parts_at_gap",
    "table2_ratios",
    "vmax_plateau",
]
