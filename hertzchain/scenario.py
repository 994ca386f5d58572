"""Scenarios: one TOML file describes a chain, its initial state, the run and the models.

A scenario is the problem format of hertzchain (pyro2's ``problems/`` idea): the
commands ``hertzchain run``, ``hertzchain compare`` and ``hertzchain sweep``, and every
item of ``hertzchain reproduce``, read the same file and run it through one path
(:func:`hertzchain.models.run`).  It is validated strictly: unknown keys are errors (they
are usually typos) and every error names the key, the value and the allowed range.

Grain indices count from 0, here as everywhere in hertzchain (the paper's grain 201 is
index 200; docs/guide/cli.md); with a striker (``[initial] striker_mass`` other than 1)
the striker is grain 0 of the run and the indices of ``[run]`` and ``[record]`` count it.
Lengths are in m, times in s, velocities in m/s, densities in kg/m³, moduli in Pa.
Materials are named (:data:`theory.MATERIALS`, ``hertzchain materials``) or given as a
table ``{density, youngs_modulus, poisson_ratio}`` (kg/m³, Pa, 1; an optional ``name``).

The example with every key, and the tables of keys with their units and ranges, are
:func:`schema_reference` (made from the registries of laws, initial kinds and continuum
models; the documentation's page of this module shows them).

Models
------
``[models]`` names the models run side by side from the *same* initial grain state:
the discrete chain (paper Eq. 2, the reference), a long-wave continuum and the
closed-form theory.  ``continuum = "auto"`` picks, by one rule
(:meth:`ModelsSpec.continuum_model`), the model that is the accurate one for the incident
wave: the corrected Eq. 4 (its Rosenau form, :class:`continuum.BoussinesqPDE`) under
precompression while the incident strain amplitude stays within
:data:`AUTO_EQ4_MAX_STRAIN` × δ0; the grain-averaged quasi-continuum ``"qc"``
(:class:`continuum.GrainAveragedPDE`, docs/physics.md §24) at δ0 = 0 and from
:data:`AUTO_QC_MIN_STRAIN` × δ0 on, where it fits the chain
(:func:`quasicontinuum_applies`: no dissipative law, no drag, no periodic cells; and
no taper or gravity, where Eq. 7 was measured closer); and
the corrected, regularised Eq. 7 (:class:`continuum.NesterenkoPDE`, which keeps the
full Hertz force, with or without precompression, docs/physics.md §2–4) in between and
wherever the quasi-continuum does not fit;
a model that does not fit the regime (Eq. 4 or KdV at δ0 = 0; KdV, which is
unidirectional, on more than one section) is an error naming ``[models] continuum``.
Where each model applies is decided in one place, :func:`model_applies`: the continuum
is derived for the paper's chain — the lossless Hertz law in uniform sections of one
diameter without gravity (:func:`continuum_applies`); the theory describes every chain
but one with a disordered first section (:func:`theory_applies`).  Left out of
``[models]``, each runs where it applies — the theory in every command, the continuum
in ``hertzchain compare`` only (:meth:`Scenario.with_default_models`) — and is otherwise
off with the reason (:meth:`Scenario.skipped_models`); an explicit request for a model
that does not apply is an error naming why.  The discrete chain runs every chain
(examples: ``hertzchain/scenarios/examples/``).
The continuum steps with ``[models] integrator``, a splitting method of
:mod:`theory.splitting` (``order`` is its deprecated alias), at ``dt_safety`` × velocity
Verlet's limit 2/ω_max (ω_max with the stiffening at 1.5 × the largest wave strain),
below the method's own limit.  Not given, each is the model's own
(:meth:`ModelsSpec.continuum_step`: the class attributes ``default_integrator`` and
``default_dt_safety`` of :data:`continuum.MODELS`): Yoshida-4 drift first at 0.5 for
Eq. 4 and Eq. 7, position Verlet at 0.8 for the quasi-continuum, whose frequencies lie
far below ω_max (docs/physics.md §24); they are resolved where the model is known
(:mod:`hertzchain.models`, after ``"auto"``'s rule) and checked against the method's
stability limit where they are resolved, and already when the scenario is read if it
turns the continuum on, for every model it may run
(:meth:`ModelsSpec.possible_continuum_models`; :meth:`ModelsSpec.step_key` writes them
into the scenario's dict).

Chains beyond the paper
-----------------------
``[chain] law`` chooses the contact law (:data:`theory.laws.LAWS`; its parameters, e.g.
``exponent`` or ``damping_time``, are keys of ``[chain]`` too) and ``drag`` an on-site
drag, ``gravity``/``top_force`` a vertical chain; each
``[[chain.sections]]`` may have its own ``diameter`` and a per-grain ``profile``
(tapered, periodic unit cell) and seeded disorder; ``[record] sensors``, ``wall_forces``
and ``strain_maxima`` record what experiments measure.  They map to :mod:`discrete`
objects in one place, :func:`hertzchain.runner.build_chain` and
:func:`hertzchain.runner.build_law`.

Extending the format
--------------------
Every key is declared once, in :data:`SCHEMA` (type, default, range, unit, help), and
read by the one generic reader; this docstring's tables are generated from it
(:func:`schema_markdown`).  A new key is a :class:`Key` in its table plus a field of the
same name in the table's dataclass (``tests/hertzchain/test_scenario.py`` checks that the
two agree); checks that involve several keys live in the table's ``_check_*`` function.
Three kinds of keys come from registries instead, so that a new one is one file and a
registry line: ``[chain] law`` and each law's parameters from :data:`theory.laws.LAWS`
(:class:`theory.laws.LawParameter`), ``[initial] kind`` and each kind's keys and checks
from :data:`hertzchain.initial_kinds.INITIAL_KINDS`, and the values of ``[models]
continuum`` from :data:`continuum.MODELS` (:func:`continuum_models`).  They are read
when needed, never at import: the registries import NumPy, ``hertzchain --help`` must
not (so this docstring's tables are generated when it is read).
"""

from __future__ import annotations

import difflib
import math
import tomllib
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

__all__ = [
    "ScenarioError",
    "Key",
    "SCHEMA",
    "TABLE_DOCS",
    "continuum_models",
    "AUTO_EQ4_MAX_STRAIN",
    "AUTO_QC_MIN_STRAIN",
    "STEP_KEY_DEFAULT",
    "quasicontinuum_applies",
    "INTEGRATORS",
    "SectionSpec",
    "ChainSpec",
    "InitialSpec",
    "RunSpec",
    "RecordSpec",
    "ModelsSpec",
    "Scenario",
    "load_scenario",
    "model_applies",
    "continuum_applies",
    "theory_applies",
    "parse_scenario",
    "read_toml",
    "read_key",
    "schema_key",
    "schema_markdown",
    "schema_reference",
    "set_path",
    "shipped_scenarios",
]


class ScenarioError(ValueError):
    """A scenario file or table is invalid; the message names the key and allowed range."""


# -- the schema -------------------------------------------------------------------------
@dataclass(frozen=True)
class Key:
    """One scenario key: how it is read, validated and documented.

    Parameters
    ----------
    name : str
        The TOML key (and the field of the table's dataclass).
    kind : str
        ``"number"``, ``"integer"``, ``"bool"``, ``"string"``, ``"choice"``, ``"numbers"``
        (list of numbers), ``"integers"`` (list of integers), ``"material"`` (a name or a
        table), ``"auto_number"`` (``"auto"`` or a number), ``"auto_integer"``,
        ``"continuum"`` (a model name or ``false``), ``"wall"`` (a keyword of
        ``choices`` or a material name).
    default : object
        Value when the key is absent (None: no value).
    doc : str
        One-line help (the docs are generated from it).
    unit : str
        Unit for the docs ("" if dimensionless).
    low, high : float, optional
        Bounds of numbers (and list entries); ``low_open``/``high_open`` exclude them.
    choices : tuple
        Allowed values of a ``"choice"`` key.
    required : bool
        The key must be given.
    example : object
        Value shown in the generated example (default: ``default``).
    """

    name: str
    kind: str
    default: Any = None
    doc: str = ""
    unit: str = ""
    low: float | None = None
    high: float | None = None
    low_open: bool = True
    high_open: bool = True
    choices: tuple = ()
    required: bool = False
    example: Any = None

    def range_text(self) -> str:
        """The allowed values, for messages and docs."""
        if self.kind == "choice":
            return ", ".join(repr(c) for c in self.choices)
        if self.kind == "continuum":
            return ", ".join(repr(c) for c in continuum_models()) + " or false"
        if self.low is None and self.high is None:
            return ""
        lo = "-inf" if self.low is None else f"{self.low:g}"
        hi = "inf" if self.high is None else f"{self.high:g}"
        return ("(" if self.low_open else "[") + f"{lo}, {hi}" + (")" if self.high_open else "]")



@dataclass(frozen=True)
class _Registered:
    """A place in a table of :data:`SCHEMA` filled with keys built from a registry.

    ``builder`` names a function of this module returning the keys; it runs on each
    access (so that a law or kind registered later is seen) and not at import: the
    registries import NumPy, which ``hertzchain --help`` must not.
    """

    builder: str


AUTO_EQ4_MAX_STRAIN = 0.5
"""``[models] continuum = "auto"`` runs Eq. 4 under precompression only up to this incident
strain amplitude / δ0 (the peak dynamic overlap of the incident wave over the static
one), Eq. 7 above it up to :data:`AUTO_QC_MIN_STRAIN`
(:meth:`ModelsSpec.continuum_model`).  Eq. 4 keeps the Hertz force k δ0^{3/2}(1 +
s)^{3/2} to second order in s = strain/δ0; the dropped terms are 0.03 % of the dynamic
force at the paper's s = 0.09, 0.8 % at s = 0.5, 2.5 % at 1 and 7 % at 2, and past s ≈ 2
in tension its flux is ill-posed.  Measured against the discrete chain (model-validity
points, 200 | 200 grains, (α_ρ, α_kn) = (0.5, 2), (2, 0.5), (0.25, 4), (4, 0.25);
README): at s = 0.09 Eq. 4 is within 0.12 % (Eq. 7 0.005–0.15 %), at s = 0.74 Eq. 4
0.8–5.3 % (Eq. 7 0.03–1.7 %), at s = 1.9 Eq. 4 3–12 % (Eq. 7 0.25–2.3 %), and at s = 8.6
19 of 25 Eq. 4 runs blow up (Eq. 7 1.2–9.8 %)."""

AUTO_QC_MIN_STRAIN = 9.0
"""``[models] continuum = "auto"`` runs the grain-averaged quasi-continuum ``"qc"``
(:class:`continuum.GrainAveragedPDE`, docs/physics.md §24) from this incident strain
amplitude / δ0 on, and at δ0 = 0, on the chains it fits (:func:`quasicontinuum_applies`;
:meth:`ModelsSpec.continuum_model`).  A wave this strong is a few grains wide, and
Eq. 7's long-wave expansion of the grain average to O(d²) misses what the
quasi-continuum's order-M Padé average keeps.  Measured against the discrete chain on
the model-validity map (lossless Hertz chains, 5 × 5 interfaces; docs/physics.md §24):
at strain/δ0 = 9, 100 and in the sonic vacuum Eq. 7 is off by up to 8–12 % of the
incident energy (median 1.8–3.5 %), the quasi-continuum within 2.2 % and far cheaper
(the CPU times are in docs/physics.md §24); at strain/δ0 = 1 Eq. 7 is the closer model
(0.1–1.7 % against 0.1–6 %).  Between 1 and 9 the crossover is not measured: 9
is the lowest amplitude at which the quasi-continuum is known to be the better one."""

STEP_KEY_DEFAULT = ("position_yoshida4", 0.5)
"""The continuum step that :meth:`Scenario.to_dict` writes as a ``[models] integrator`` of
None and, where no continuum is on, as the ``dt_safety`` (:meth:`ModelsSpec.step_key`):
the scenario-wide default before each continuum model declared its own (Eq. 4's and
Eq. 7's ``default_integrator`` and ``default_dt_safety`` of :data:`continuum.MODELS`),
so that a scenario stepped as before keeps its dict, and the cache keys and sweep point
ids made from it."""

_AUTO_QC_TOLERANCE = 1e-9
"""Relative slack of the ``>=`` :data:`AUTO_QC_MIN_STRAIN` test: a wave set at exactly
that strain/δ0 (``[initial] strain_max``) reads its peak back to round-off, and must
fall on the quasi-continuum's side."""

def continuum_models() -> tuple[str, ...]:
    """Values of ``[models] continuum`` besides ``false``.

    ``"auto"`` (:meth:`ModelsSpec.continuum_model`), the registered chain models of
    :data:`continuum.MODELS` by name, and ``"kdv"`` (:class:`continuum.KdVPDE`, the
    unidirectional reduction, run by :mod:`hertzchain.models` on its own path).  Imports
    :mod:`continuum` (py-pde): called only when a value is checked or documented, never
    by a run that does not use the continuum.
    """
    import continuum

    return ("auto", *continuum.MODELS, "kdv")


INTEGRATORS = ("verlet", "yoshida4", "blanes_moan4")
"""Time integrators of the discrete solver (:data:`discrete.integrators.INTEGRATORS`)."""

CONTINUUM_INTEGRATORS = ("verlet", "yoshida4", "blanes_moan4", "position_verlet",
                         "position_yoshida4")
"""Values of ``[models] integrator``: the names of :data:`theory.splitting.SPLITTINGS`
(written out, as :data:`INTEGRATORS` is: ``theory`` imports NumPy, which
``hertzchain --help`` must not; the test compares the two)."""

MATERIAL_KEYS = ("density", "youngs_modulus", "poisson_ratio")


WALLS = ("paper", "hertz", "flat", "free")
"""The wall keywords of ``[chain] left_wall``/``right_wall``; any other value is a material
name of :data:`theory.MATERIALS`: a flat wall of that material."""

PROFILES = ("uniform", "tapered", "periodic")
"""Values of ``[[chain.sections]] profile``."""

_TABLE_KEYS: dict[str, tuple[Key | _Registered, ...]] = {
    "": (
        Key("name", "string", "", "free label", example="my-chain"),
    ),
    "chain": (
        Key("diameter", "number", 5e-3, "grain diameter d", "m", low=0),
        Key("delta0_over_d", "number", 0.0, "static overlap of the first section's "
            "contacts / d (each section's follows from force equilibrium)", low=0,
            low_open=False, high=0.1, example=1e-3),
        Key("material", "material", "paper", "first section's material: a name of "
            "theory.MATERIALS (\"paper\": Hertz constant, ν = 0.30, reproduces the paper; "
            "\"table1\": ν = 0.25; \"steel\", \"brass\", \"ptfe\", …: `hertzchain "
            "materials`) or a table {density (kg/m³), youngs_modulus (Pa), poisson_ratio}"),
        Key("left_wall", "wall", "paper", "left end: \"paper\" (as a grain–grain "
            "contact), \"hertz\" (a rigid flat), \"flat\" (a flat wall of the adjacent "
            "grain's own material), a material name (a flat wall of that material: "
            "\"steel\", \"brass\", …, `hertzchain materials`) or \"free\" (only at "
            "δ0 = 0)", choices=WALLS),
        Key("right_wall", "wall", "paper", "right end (as left_wall)", choices=WALLS),
        _Registered("_law_keys"),
        Key("drag", "number", 0.0, "on-site viscous drag rate β: force -m_i β v_i on every "
            "grain", "1/s", low=0, low_open=False),
        Key("gravity", "number", 0.0, "vertical chain, grain 0 on top, standing on the "
            "right wall: acceleration of gravity along the chain (9.81 on Earth); the static "
            "overlaps grow with depth from force equilibrium (then delta0_over_d must be 0: "
            "give top_force)", "m/s²", low=0, low_open=False),
        Key("top_force", "number", 0.0, "with gravity: static force on the top (left) wall "
            "(0: nothing presses from above)", "N", low=0, low_open=False),
    ),
    "chain.sections": (
        Key("n", "integer", None, "grains of this section (sum over sections >= 2)", low=1,
            low_open=False, required=True, example=200),
        Key("alpha_rho", "number", 1.0, "density / the first section's", low=0),
        Key("alpha_kn", "number", 1.0, "contact stiffness k_n / the first section's", low=0),
        Key("material", "material", None, "instead of alpha_rho/alpha_kn: a material name "
            "(`hertzchain materials`) or table {density (kg/m³), youngs_modulus (Pa), "
            "poisson_ratio}"),
        Key("diameter", "number", None, "this section's grain diameter (default: [chain] "
            "diameter)", "m", low=0),
        Key("profile", "choice", "uniform", "per-grain profile: \"uniform\", \"tapered\" "
            "(mass ratio per grain, mass_ratio) or \"periodic\" (a repeated unit cell: "
            "cell_diameters, cell_alpha_rho, cell_alpha_kn)", choices=PROFILES),
        Key("mass_ratio", "number", None, "tapered: m_{i+1}/m_i at fixed material (< 1: "
            "forward taper, large to small grains; > 1 backward)", low=0),
        Key("cell_diameters", "numbers", (), "periodic: diameter / the section's of each "
            "grain of the unit cell (a dimer of mass ratio ε: [1.0, ε^{1/3}])", low=0),
        Key("cell_alpha_rho", "numbers", (), "periodic: density factor of each cell grain "
            "(default all 1)", low=0),
        Key("cell_alpha_kn", "numbers", (), "periodic: k_n factor of each cell grain "
            "(default all 1)", low=0),
        Key("disorder_mass", "number", 0.0, "seeded disorder: relative standard deviation "
            "of the grain masses (factor 1 + σ√3 U, U uniform in [-1, 1])", low=0,
            low_open=False, high=0.5, high_open=False),
        Key("disorder_stiffness", "number", 0.0, "seeded disorder: relative standard "
            "deviation of the grain–grain contact constants", low=0, low_open=False,
            high=0.5, high_open=False),
        Key("disorder_diameter", "number", 0.0, "seeded disorder: relative standard "
            "deviation of the diameters (masses and contact constants follow)", low=0,
            low_open=False, high=0.5, high_open=False),
        Key("seed", "integer", None, "seed of the disorder's random numbers (default: the "
            "section's index 0, 1, …, so that two disordered sections differ)", low=0,
            low_open=False),
    ),
    "initial": (
        _Registered("_initial_keys"),
    ),
    "run": (
        Key("t_end", "number", None, "end time (give t_end and/or until_front_at)", "s",
            low=0, example=2.4e-3),
        Key("until_front_at", "integer", None, "stop when the leading wave's velocity peak "
            "passes this grain", low=0, low_open=False),
        Key("dt", "auto_number", None, "time step: \"auto\" (a fraction dt_fraction of the "
            "shortest contact period) or a value", "s", low=0, example="auto"),
        Key("dt_fraction", "number", None, "\"auto\" dt as a fraction of the shortest "
            "contact period 2π/ω_max (default: the integrator's, 0.002 for verlet); at most "
            "1/π, velocity Verlet's stability limit dt < 2/ω — a chain's own limit is lower "
            "(√2/(2π) ≈ 0.225 for identical grains) and is checked on the built chain",
            low=0, high=1 / math.pi, high_open=False),
        Key("integrator", "choice", "verlet", "discrete time integrator (\"auto\": the "
            "cheapest for rtol; needs rtol)", choices=(*INTEGRATORS, "auto")),
        Key("rtol", "number", None, "relative accuracy of the recorded quantities: dt (and "
            "with integrator = \"auto\" the method) chosen from a step-doubling probe "
            "(discrete.timestep); default none: dt_fraction", low=0, high=1),
        Key("max_steps", "integer", 100_000_000, "step limit", low=1, low_open=False),
    ),
    "record": (
        Key("snapshot_times", "numbers", (), "times of full snapshots (u, v, overlaps)", "s",
            low=0, low_open=False, example=[0.0]),
        Key("snapshot_grains", "integers", (), "full snapshots when the leading wave's peak "
            "passes these grains", low=0, low_open=False),
        Key("time_series_grains", "integers", (), "grains whose u, v and contact overlaps "
            "are recorded every series_every steps", low=0, low_open=False),
        Key("series_every", "integer", 1, "steps between time-series samples", low=1,
            low_open=False),
        Key("energy_every", "integer", 0, "steps between rows of the per-grain energy "
            "space–time grid (0: automatic, every half grain transit, if energy_grid)",
            low=0, low_open=False),
        Key("energy_grid", "bool", True, "record the energy grid (the runner's energy ratios "
            "and front speeds need it)"),
        Key("running_max", "bool", True, "per-grain running maxima of v and u"),
        Key("sensors", "integers", (), "grains read as embedded force sensors (the mean of "
            "their two contact forces, N), sampled every series_every steps", low=0,
            low_open=False),
        Key("wall_forces", "bool", False, "record the force on each wall (N), sampled "
            "every series_every steps"),
        Key("strain_maxima", "bool", False, "running maximum of every contact's overlap "
            "(the strain maxima (max δ - δ0)/d; needs running_max)"),
    ),
    "models": (
        Key("discrete", "bool", True, "the discrete chain (paper Eq. 2; the reference)"),
        Key("continuum", "continuum", None, "long-wave continuum: \"auto\" (Eq. 4 if δ0 > 0 "
            f"and the incident strain / δ0 <= {AUTO_EQ4_MAX_STRAIN:g}; the quasi-continuum "
            f"\"qc\" at δ0 = 0 and from strain / δ0 >= {AUTO_QC_MIN_STRAIN:g} on a chain "
            "without drag, dissipative law, periodic cells, taper or gravity; otherwise "
            "Eq. 7), "
            "a model of continuum.MODELS by name, "
            "\"kdv\" (one precompressed section) or false; not given: \"auto\" in "
            "`hertzchain compare` where it applies, off in run and sweep (its cost)",
            example="auto"),
        Key("theory", "bool", None, "closed-form theory: wave speeds of the law's exponent, "
            "the interface (Eqs. 9–13 and the strongly nonlinear theory), the theories of "
            "gravity, tapers, dimers, dissipation and strikers; not given: on where it "
            "applies"),
        Key("nodes_per_grain", "integer", 5, "continuum grid nodes per grain (odd)", low=1,
            low_open=False),
        Key("integrator", "choice", None, "the continuum's splitting method "
            "(theory.splitting; kick-first ones with merged FSAL kicks); not given: the "
            "one of order, else the model's own (continuum.MODELS[...].default_integrator: "
            "\"position_yoshida4\" for Eq. 4 and Eq. 7, \"position_verlet\" for the "
            "quasi-continuum \"qc\")", choices=CONTINUUM_INTEGRATORS,
            example="blanes_moan4"),
        Key("order", "integer", None, "deprecated alias of integrator: 2 = "
            "\"position_verlet\", 4 = \"position_yoshida4\"", low=2,
            low_open=False, high=4, high_open=False, example=4),
        Key("dt_safety", "number", None, "the safety of the continuum's pde.stable_dt, with "
            "the stiffening at 1.5 × the largest wave strain included: for Eq. 4 the step "
            "as a fraction of velocity Verlet's stability limit 2/ω_max, which must stay "
            "below the integrator's own (theory.splitting.STABILITY_LIMITS / 2: Yoshida-4 "
            "0.79, Verlet 1, Blanes–Moan-4 1.58; checked for every model the continuum may "
            "run); for Eq. 7 the factor of its step 0.4 × safety × h/c "
            "(NesterenkoPDE.stable_dt, ω_max Δt ≈ 0.8 safety before dispersion) and for "
            "the quasi-continuum of 1.2 × safety/ω_max (the same check is more cautious "
            "there); not given: the model's own (continuum.MODELS[...].default_dt_safety: "
            "0.5 for Eq. 4 and Eq. 7, 0.8 for \"qc\"); not for KdV", low=0, high=2,
            example=0.5),
        Key("nonlinearity", "choice", "quadratic", "Eq. 4 flux: \"quadratic\" (Eq. 4's "
            "expansion about δ0) or \"full\" (the chain's own contact law, any law); "
            "\"hertz\" is the former name of \"full\", the same on a Hertz chain and "
            "refused on another", choices=("quadratic", "full", "hertz")),
        Key("delta_floor", "number", 1e-2, "Eq. 7 regularisation: δ^{1/4} continued "
            "linearly below this fraction of the incident peak overlap (docs/physics.md §4)",
            low=0, high=1),
        Key("dispersion_cap", "number", 10.0, "Eq. 7 regularisation: dispersion multiplier "
            "-min(k², cap), grains⁻² (<= 10 keeps the energy bounded below)", low=0,
            high=10, high_open=False),
        Key("samples", "integer", 40, "common sample times of the comparison (profiles, "
            "fronts, energy partition); the discrete run stores a snapshot at each", low=2,
            low_open=False),
        Key("compare_times", "numbers", (), "times of the profile panels (default: before, "
            "during and after the interface)", "s", low=0, low_open=False),
    ),
}
"""The keys of every table as written here; :data:`SCHEMA` fills in the registered ones."""


def _law_keys() -> tuple[Key, ...]:
    """``[chain] law`` and the parameters of every registered law (:data:`theory.laws.LAWS`).

    Each :class:`theory.laws.LawParameter` becomes a number key of its range, unit and
    default; a name shared by several laws is read with the first law's definition.
    ValueError for a parameter named as another ``[chain]`` key (``drag``, …).
    """
    from theory.laws import LAWS

    doc = "contact law (theory.laws): " + " or ".join(
        f"\"{name}\" {cls.help_text()}" for name, cls in LAWS.items())
    keys = {"law": Key("law", "choice", "power", doc, choices=tuple(LAWS))}
    owners: dict[str, list[str]] = {}
    taken = {k.name for k in SCHEMA.written("chain")} | {"sections"}
    for name, cls in LAWS.items():
        for p in cls.parameters:
            if p.name in taken:
                raise ValueError(f"contact law {name!r}: its parameter {p.name!r} is a "
                                 "[chain] key of the chain's own: rename it")
            owners.setdefault(p.name, []).append(name)
            if p.name not in keys:
                keys[p.name] = Key(p.name, "number", float(p.default), p.doc, p.unit,
                                   low=p.low, high=p.high, low_open=p.low_open,
                                   high_open=p.high_open)
    for name, laws in owners.items():
        k = keys[name]
        keys[name] = replace(k, doc="law = " + " or ".join(f"\"{n}\"" for n in laws)
                             + f": {k.doc}")
    return tuple(keys.values())


def _initial_keys() -> tuple[Key, ...]:
    """``[initial] kind`` and every registered kind's keys (:mod:`hertzchain.initial_kinds`)."""
    from .initial_kinds import initial_keys

    return initial_keys()


class _Schema(Mapping):
    """:data:`SCHEMA`: the tables of keys, with the registered ones filled in on access."""

    def __init__(self, tables: dict[str, tuple[Key | _Registered, ...]]) -> None:
        self._tables = tables

    def __getitem__(self, table: str) -> tuple[Key, ...]:
        out: list[Key] = []
        for k in self._tables[table]:
            out.extend(globals()[k.builder]() if isinstance(k, _Registered) else (k,))
        return tuple(out)

    def __iter__(self):
        return iter(self._tables)

    def __len__(self) -> int:
        return len(self._tables)

    def written(self, table: str) -> tuple[Key, ...]:
        """The keys of ``table`` written in this module (no registry imported)."""
        return tuple(k for k in self._tables[table] if isinstance(k, Key))


SCHEMA = _Schema(_TABLE_KEYS)
"""Every key of every table (``""`` is the top level, ``"chain.sections"`` one entry of
``[[chain.sections]]``): a mapping table → keys.  The contact laws' keys (``[chain] law``
and each law's parameters) come from :data:`theory.laws.LAWS` on each access; the other
keys are written in this module."""

TABLE_DOCS = {
    "": "An optional label (default: the file name).",
    "chain": "The chain: sections left to right, walls, precompression.",
    "chain.sections": "One or more ``[[chain.sections]]`` tables, left to right "
                      "(*required*).",
    "initial": "Initial grain state (shared by every model).",
    "run": "Stop condition and the discrete solver's time step.",
    "record": "What the discrete solver records.",
    "models": "Which models run side by side, and the continuum's settings.",
}


# -- generic reading -----------------------------------------------------------------
def _where(table: str) -> str:
    return "top level" if table == "" else table


def did_you_mean(word, known) -> str:
    """``"; did you mean 'x'?"`` for the closest of ``known`` to ``word`` (difflib), or ""."""
    close = difflib.get_close_matches(str(word), [str(k) for k in known], n=2, cutoff=0.6)
    return f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""


def _check_keys(data: dict, allowed, where: str, tables=()) -> None:
    """ScenarioError for keys of ``data`` not in ``allowed`` (tables: also allowed here).

    Each unknown key is named with the closest allowed key or table (did you mean), and
    the allowed keys and tables are listed.
    """
    unknown = sorted(set(data) - set(allowed) - set(tables), key=str)
    if not unknown:
        return
    parts = []
    prefix = "" if where == "top level" else f"{where}."
    for k in unknown:
        if did_you_mean(k, tables):  # a misspelt table, e.g. [inital]
            close = difflib.get_close_matches(str(k), tables, n=1, cutoff=0.6)[0]
            parts.append(f"unknown table [{prefix}{k}]; did you mean [{prefix}{close}]?")
        else:
            parts.append(f"unknown key {k!r} in [{where}]{did_you_mean(k, allowed)}")
    listed = f"allowed keys: {', '.join(sorted(allowed))}" if allowed else "no keys"
    if tables:
        listed += f"; tables: {', '.join(f'[{prefix}{t}]' for t in tables)}"
    raise ScenarioError(f"{'; '.join(parts)} ({listed})")


def _read_number(key: Key, val, where: str, name: str | None = None) -> float:
    name = name or key.name
    if isinstance(val, bool) or not isinstance(val, int | float):
        raise ScenarioError(f"[{where}] {name} must be a number (got {val!r})")
    val = float(val)
    if not math.isfinite(val):
        raise ScenarioError(f"[{where}] {name} must be finite (got {val!r})")
    bad_low = key.low is not None and (val <= key.low if key.low_open else val < key.low)
    bad_high = key.high is not None and (val >= key.high if key.high_open else val > key.high)
    if bad_low or bad_high:
        raise ScenarioError(f"[{where}] {name} = {val!r} is outside the allowed range "
                            f"{key.range_text()}")
    return val


def _read_integer(key: Key, val, where: str, name: str | None = None) -> int:
    name = name or key.name
    if isinstance(val, bool) or not isinstance(val, int):
        raise ScenarioError(f"[{where}] {name} must be an integer (got {val!r})")
    # the same bounds as numbers, open or closed as range_text() documents them
    bad_low = key.low is not None and (val <= key.low if key.low_open else val < key.low)
    bad_high = key.high is not None and (val >= key.high if key.high_open else val > key.high)
    if bad_low or bad_high:
        op, bound = ((">" if key.low_open else ">=", key.low) if bad_low
                     else ("<" if key.high_open else "<=", key.high))
        raise ScenarioError(f"[{where}] {name} = {val} must be {op} {bound:g} (allowed "
                            f"range {key.range_text()})")
    return val


MATERIAL_UNITS = {"density": "kg/m³", "youngs_modulus": "Pa", "poisson_ratio": ""}


def _read_material(val, where: str):
    """One material key, validated: a name or a table.

    ``"paper"``/``"table1"`` are kept as the name (the paper's materials); another name of
    :data:`theory.MATERIALS` is read into its table, with its ``name`` (the values are
    recorded with the run); a table ``{density, youngs_modulus, poisson_ratio}`` (kg/m³,
    Pa, 1) may carry a ``name``.
    """
    if isinstance(val, str):
        from theory import MATERIALS, resolve_material_name

        try:
            key = resolve_material_name(val)
        except ValueError as exc:
            raise ScenarioError(f"[{where}] material = {val!r}: {exc}") from None
        if key in ("paper", "table1"):
            return key
        m = MATERIALS[key].material
        return {"name": key, "density": m.density, "youngs_modulus": m.youngs_modulus,
                "poisson_ratio": m.poisson_ratio}
    if not isinstance(val, dict):
        raise ScenarioError(f"[{where}] material must be a name (`hertzchain materials`) or "
                            "a table {density (kg/m³), youngs_modulus (Pa), poisson_ratio} "
                            f"(got {val!r})")
    w = f"{where}.material"
    _check_keys(val, (*MATERIAL_KEYS, "name"), w)
    out = {}
    if "name" in val:
        if not isinstance(val["name"], str):
            raise ScenarioError(f"[{w}] name must be a string (got {val['name']!r})")
        out["name"] = val["name"]
    for name, low, high in (("density", 0, None), ("youngs_modulus", 0, None),
                            ("poisson_ratio", -1, 0.5)):
        if name not in val:
            unit = f" ({MATERIAL_UNITS[name]})" if MATERIAL_UNITS[name] else ""
            raise ScenarioError(f"[{w}] {name}{unit} is required")
        out[name] = _read_number(Key(name, "number", low=low, high=high,
                                     unit=MATERIAL_UNITS[name]), val[name], w)
    return out


def _read_wall(key: Key, val, where: str) -> str:
    """A wall: a keyword of :data:`WALLS` or a material name (its :data:`theory.MATERIALS` key).

    A material name is a flat wall of that material, whose contact constant takes both
    materials (:func:`theory.hertz_constant_wall`; :func:`hertzchain.runner.build_chain`).
    Errors name the closest keywords and materials (did you mean).
    """
    if not isinstance(val, str):
        raise ScenarioError(f"[{where}] {key.name} must be a string: one of "
                            f"{', '.join(repr(c) for c in key.choices)} or a material name "
                            f"(`hertzchain materials`) (got {val!r})")
    if val in key.choices:
        return val
    from theory import MATERIALS, resolve_material_name

    try:
        return resolve_material_name(val)
    except ValueError:
        known = (*key.choices, *MATERIALS)
        raise ScenarioError(f"[{where}] {key.name} = {val!r}{did_you_mean(val, known)} "
                            f"(allowed: {', '.join(repr(c) for c in key.choices)} or a "
                            "material name, `hertzchain materials`)") from None


def _read_value(key: Key, val, where: str):
    """One value of ``key`` validated (ScenarioError naming the key otherwise)."""
    k = key.kind
    if k == "number":
        return _read_number(key, val, where)
    if k == "integer":
        return _read_integer(key, val, where)
    if k == "bool":
        if not isinstance(val, bool):
            raise ScenarioError(f"[{where}] {key.name} must be true or false (got {val!r})")
        return val
    if k == "string":
        if not isinstance(val, str):
            raise ScenarioError(f"[{where}] {key.name} must be a string (got {val!r})")
        return val
    if k == "choice":
        if val not in key.choices:
            raise ScenarioError(f"[{where}] {key.name} = {val!r}"
                                f"{did_you_mean(val, key.choices)} (allowed: "
                                f"{', '.join(repr(c) for c in key.choices)})")
        return val
    if k in ("numbers", "integers"):
        if not isinstance(val, list):
            raise ScenarioError(f"[{where}] {key.name} must be a list (got {val!r})")
        read = _read_number if k == "numbers" else _read_integer
        return tuple(read(key, x, where, f"{key.name}[{i}]") for i, x in enumerate(val))
    if k == "material":
        return _read_material(val, where)
    if k == "wall":
        return _read_wall(key, val, where)
    if k == "auto_number":
        return None if val == "auto" else _read_number(key, val, where)
    if k == "continuum":
        if val is False:
            return False
        if val is True:
            return "auto"
        if val not in continuum_models():
            raise ScenarioError(f"[{where}] {key.name} = {val!r}"
                                f"{did_you_mean(val, continuum_models())} (allowed: "
                                f"{key.range_text()})")
        return val
    raise AssertionError(f"unknown key kind {k!r}")  # pragma: no cover - schema bug


def schema_key(table: str, name: str) -> Key:
    """The :class:`Key` ``name`` of ``table`` in :data:`SCHEMA` (KeyError if absent).

    The one definition of a key's range, also for the command-line flags that mirror a
    scenario key (``hertzchain theory --delta0`` is ``[chain] delta0_over_d``).
    """
    for key in SCHEMA.written(table):  # the registries (NumPy) only if needed
        if key.name == name:
            return key
    for key in SCHEMA[table]:
        if key.name == name:
            return key
    raise KeyError(f"no key {name!r} in [{_where(table)}]")


def read_key(table: str, name: str, value):
    """``value`` validated as ``[table] name`` (ScenarioError naming it and its range)."""
    return _read_value(schema_key(table, name), value, _where(table))


def _read_table(data, table: str, tables=()) -> dict[str, Any]:
    """Values of every key of ``table`` (defaults filled in), validated one by one.

    ``tables``: the names of the sub-tables allowed in ``data`` besides the keys (named
    in the message for an unknown key that is close to one).
    """
    where = _where(table)
    if not isinstance(data, dict):
        raise ScenarioError(f"[{where}] must be a table (got {data!r})")
    keys = SCHEMA[table]
    _check_keys(data, [k.name for k in keys], where, tables)
    out = {}
    for key in keys:
        if key.name in data:
            out[key.name] = _read_value(key, data[key.name], where)
        elif key.required:
            raise ScenarioError(f"[{where}] {key.name} is required")
        else:
            out[key.name] = key.default
    return out


# -- the specs ------------------------------------------------------------------------
@dataclass(frozen=True)
class SectionSpec:
    """One section of the chain: ``n`` grains, ratios to the first section or a material."""

    n: int
    alpha_rho: float = 1.0
    alpha_kn: float = 1.0
    material: Any = None
    diameter: float | None = None
    profile: str = "uniform"
    mass_ratio: float | None = None
    cell_diameters: tuple[float, ...] = ()
    cell_alpha_rho: tuple[float, ...] = ()
    cell_alpha_kn: tuple[float, ...] = ()
    disorder_mass: float = 0.0
    disorder_stiffness: float = 0.0
    disorder_diameter: float = 0.0
    seed: int = 0

    @property
    def uniform(self) -> bool:
        """Identical grains: no profile and no disorder."""
        return self.profile == "uniform" and not (
            self.disorder_mass or self.disorder_stiffness or self.disorder_diameter)


@dataclass(frozen=True)
class ChainSpec:
    """The chain: sections, diameter (m), precompression δ0/d of the first section, walls.

    ``law`` names a contact law of :data:`theory.laws.LAWS` and ``law_params`` holds
    its parameters (:attr:`theory.laws.ContactLaw.parameters`, as (name, value) pairs:
    those given and the others' defaults); :meth:`contact_law` builds it.  In
    :meth:`Scenario.to_dict` and the files the parameters are keys of ``[chain]``
    (``exponent``, ``damping_time``, …), as they are written.
    """

    sections: tuple[SectionSpec, ...]
    diameter: float = 5e-3
    delta0_over_d: float = 0.0
    material: Any = "paper"
    left_wall: str = "paper"
    right_wall: str = "paper"
    law: str = "power"
    law_params: tuple[tuple[str, float], ...] = ()
    drag: float = 0.0
    gravity: float = 0.0
    top_force: float = 0.0

    @property
    def n(self) -> int:
        """Total number of grains."""
        return sum(s.n for s in self.sections)

    @property
    def law_values(self) -> dict[str, float]:
        """The law's parameters by name (:attr:`law_params` as a dict)."""
        return dict(self.law_params)

    def contact_law(self):
        """The :class:`theory.laws.ContactLaw` of :attr:`law` and :attr:`law_params`.

        :meth:`theory.laws.ContactLaw.from_params` of the class registered under the
        name (the one mapping from a scenario to a law; imports :mod:`theory`).
        """
        from theory.laws import LAWS

        return LAWS[self.law].from_params(**self.law_values)

    @property
    def exponent(self) -> float:
        """Exponent n of the law's elastic part k [δ]_+^n (3/2: Hertz, paper Eq. 1)."""
        return float(self.contact_law().exponent)


@dataclass(frozen=True)
class InitialSpec:
    """Initial grain state (see :data:`SCHEMA` ``["initial"]``).

    ``kind`` names a kind of :data:`hertzchain.initial_kinds.INITIAL_KINDS` and
    ``params`` holds its keys as (name, value) pairs (those given, the others at their
    defaults).  Every registered key reads as an attribute (``spec.v0``, ``spec.center``):
    the kind's value, or the key's default for another kind's key.  In
    :meth:`Scenario.to_dict` the keys are keys of ``initial``, as written in a file.
    """

    kind: str = "impact"
    params: tuple[tuple[str, Any], ...] = ()

    def __getattr__(self, name: str):
        if name.startswith("_"):
            raise AttributeError(name)
        own = dict(self.params)
        if name in own:
            return own[name]
        for key in _initial_keys()[1:]:
            if key.name == name:
                return key.default
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r} (not a "
                             "key of a registered initial kind)")

    @property
    def initial_kind(self):
        """The registered :class:`hertzchain.initial_kinds.InitialKind` of ``kind``."""
        from .initial_kinds import initial_kind

        return initial_kind(self.kind)

    @property
    def striker_grains(self) -> int:
        """Grains the state prepends to the chain (an impact's striker, grain 0): 0 or 1."""
        return self.initial_kind.striker_grains(self)


@dataclass(frozen=True)
class RunSpec:
    """Stop condition and the discrete time step."""

    t_end: float | None = None
    until_front_at: int | None = None
    dt: float | None = None
    dt_fraction: float | None = None
    integrator: str = "verlet"
    max_steps: int = 100_000_000
    rtol: float | None = None


@dataclass(frozen=True)
class RecordSpec:
    """What the discrete solver records."""

    snapshot_times: tuple[float, ...] = ()
    snapshot_grains: tuple[int, ...] = ()
    time_series_grains: tuple[int, ...] = ()
    series_every: int = 1
    energy_every: int = 0
    energy_grid: bool = True
    running_max: bool = True
    sensors: tuple[int, ...] = ()
    wall_forces: bool = False
    strain_maxima: bool = False


@dataclass(frozen=True)
class ModelsSpec:
    """The models run side by side and the continuum's settings.

    ``continuum`` is ``False``, one of :func:`continuum_models` or None (not given: the
    default of the command, :meth:`Scenario.with_default_models`); ``theory`` is a bool
    or None (not given: on where it applies).  :meth:`continuum_model` resolves
    ``"auto"`` for a chain; ``integrator``/``order`` and ``dt_safety`` None (not given)
    are the model's own, resolved by :meth:`continuum_step`.
    """

    discrete: bool = True
    continuum: str | bool | None = None
    theory: bool | None = None
    nodes_per_grain: int = 5
    integrator: str | None = None
    order: int | None = None
    dt_safety: float | None = None
    nonlinearity: str = "quadratic"
    delta_floor: float = 1e-2
    dispersion_cap: float = 10.0
    samples: int = 40
    compare_times: tuple[float, ...] = ()

    def continuum_model(self, chain: ChainSpec,
                        strain_over_delta0: float | None = None) -> str | None:
        """The continuum equation run on ``chain``: a model name or None (off).

        The one rule behind ``"auto"`` (every command, the model-validity map and the
        summaries read it here); any other value is returned as given.  With δ0 =
        ``chain.delta0_over_d`` and s = ``strain_over_delta0``, the incident wave's peak
        dynamic strain / δ0 (known once the initial state is built; None: not known):

        * ``"qc"``, the grain-averaged quasi-continuum, at δ0 = 0 and where s >=
          :data:`AUTO_QC_MIN_STRAIN` — on a chain it fits
          (:func:`quasicontinuum_applies`) and whose coefficients do not grade along
          it (no tapered section, no gravity), otherwise ``"eq7"`` (on the shipped
          tapers and the gravity example Eq. 7 is the closer, docs/physics.md §25);
        * ``"eq7"`` under precompression where :data:`AUTO_EQ4_MAX_STRAIN` < s <
          :data:`AUTO_QC_MIN_STRAIN`;
        * ``"eq4"`` under precompression where s <= :data:`AUTO_EQ4_MAX_STRAIN` or s is
          not known.

        Parameters
        ----------
        chain : ChainSpec
            The chain the continuum runs (its δ0, drag, law and section profiles).
        strain_over_delta0 : float or None
            Incident peak dynamic strain over δ0 (dimensionless, >= 0); ignored at δ0 = 0.

        Returns
        -------
        str or None
            ``"eq4"``, ``"eq7"``, ``"qc"`` for ``"auto"``; the given name otherwise;
            None where the continuum is off.
        """
        if not isinstance(chain, ChainSpec):
            raise TypeError(f"chain must be a ChainSpec (the rule reads its δ0, drag, law "
                            f"and profiles), got {type(chain).__name__}")
        if not self.continuum:
            return None
        if self.continuum != "auto":
            return str(self.continuum)
        d0 = float(chain.delta0_over_d)
        s = strain_over_delta0
        if not d0 > 0 or (s is not None
                          and s >= AUTO_QC_MIN_STRAIN * (1 - _AUTO_QC_TOLERANCE)):
            graded = chain.gravity > 0 or any(sec.profile == "tapered"
                                              for sec in chain.sections)
            return "eq7" if graded or quasicontinuum_applies(chain) else "qc"
        if s is not None and s > AUTO_EQ4_MAX_STRAIN:
            return "eq7"
        return "eq4"

    def possible_continuum_models(self, chain: ChainSpec,
                                  strain_over_delta0: float | None = None
                                  ) -> tuple[str, ...]:
        """The models the continuum may run on ``chain``, before the wave is measured.

        ``"auto"`` (:meth:`continuum_model`): the one model it picks at δ0 = 0 or at a
        known incident strain/δ0 ``strain_over_delta0`` (a wave set by ``[initial]
        strain_max``, which the run reads back to round-off, within the rule's slack);
        else under precompression ``"eq4"``, ``"eq7"`` and, where the chain fits it,
        ``"qc"`` (the measured strain decides among them).  Any other name: itself; off
        (False or None): none.  The scenario's check of the step
        (:meth:`continuum_step` for each) and its dict (:meth:`step_key`) read it.
        """
        if not self.continuum:
            return ()
        if self.continuum != "auto":
            return (str(self.continuum),)
        if not float(chain.delta0_over_d) > 0 or strain_over_delta0 is not None:
            return (str(self.continuum_model(chain, strain_over_delta0)),)
        strong = self.continuum_model(chain, math.inf)
        return ("eq4", "eq7") if strong == "eq7" else ("eq4", "eq7", str(strong))

    def step_key(self, chain: ChainSpec, strain_over_delta0: float | None = None
                 ) -> dict[str, Any]:
        """How :meth:`Scenario.to_dict` writes the step's keys that are not given.

        The scenario's dict makes its cache keys and sweep point ids, so a value not
        given is written as what it resolves to (:meth:`continuum_step`) where the
        scenario decides that — for every model of :meth:`possible_continuum_models`
        alike — and as None where the measured wave decides (``"auto"`` under
        precompression on a chain the quasi-continuum fits, without ``strain_max``: the
        dict then differs from any with the values given).  :data:`STEP_KEY_DEFAULT`
        keeps the earlier dicts: Yoshida-4 is written as an ``integrator`` of None, and
        a ``dt_safety`` where no continuum is on as its 0.5.

        Returns
        -------
        dict
            ``{"integrator": str or None, "dt_safety": float or None}``, the keys not
            given only.
        """
        models = self.possible_continuum_models(chain, strain_over_delta0)
        own: list = []
        if models:
            import continuum

            own = [continuum.MODELS.get(m, continuum.BoussinesqPDE) for m in models]
        out: dict[str, Any] = {}
        if self.integrator is None and self.order is None:
            methods = {c.default_integrator for c in own}
            one = methods.pop() if len(methods) == 1 else STEP_KEY_DEFAULT[0]
            out["integrator"] = None if one == STEP_KEY_DEFAULT[0] else one
        if self.dt_safety is None:
            safeties = {float(c.default_dt_safety) for c in own}
            out["dt_safety"] = (STEP_KEY_DEFAULT[1] if not own else
                                safeties.pop() if len(safeties) == 1 else None)
        return out

    def continuum_step(self, model: str) -> tuple[str, float]:
        """The splitting method and dt_safety the continuum ``model`` steps with.

        The one resolution rule: ``integrator`` if given, else the method of the
        deprecated ``order`` (2 = position Verlet, 4 = Yoshida-4 drift first,
        :data:`theory.splitting.ORDER_METHODS`), else the model's own
        ``default_integrator``; ``dt_safety`` if given, else the model's own
        ``default_dt_safety`` (class attributes of :data:`continuum.MODELS`: Yoshida-4 at
        0.5 for Eq. 4 and Eq. 7, position Verlet at 0.8 for the quasi-continuum, whose
        frequencies lie far below ω_max, docs/physics.md §24).  ``"kdv"`` (stepped by
        py-pde's RK4 at its own stable_dt, not by these) gets Eq. 4's, the equation it
        reduces, recorded in its cache key.  The step must satisfy ω_max Δt = 2 ×
        dt_safety < the method's stability limit (:data:`theory.splitting.STABILITY_LIMITS`).

        Parameters
        ----------
        model : str
            A model of :data:`continuum.MODELS` or ``"kdv"`` (``"auto"`` resolved:
            :meth:`continuum_model`).

        Returns
        -------
        (str, float)
            The method's name (:data:`theory.splitting.SPLITTINGS`) and dt_safety.

        Raises
        ------
        ScenarioError
            The step is beyond the method's stability limit, naming ``[models]
            dt_safety`` (and ``integrator`` where the two come from different places)
            with the allowed range.
        """
        import continuum
        from theory.splitting import ORDER_METHODS, STABILITY_LIMITS

        own = continuum.MODELS.get(model) or (continuum.BoussinesqPDE if model == "kdv"
                                              else None)
        if own is None:
            raise ScenarioError(f"[models] continuum = {model!r} is not a model of "
                                f"continuum.MODELS ({', '.join(map(repr, continuum.MODELS))})"
                                " or 'kdv'")
        method = (self.integrator if self.integrator is not None
                  else ORDER_METHODS[self.order] if self.order is not None
                  else own.default_integrator)
        safety = float(self.dt_safety if self.dt_safety is not None
                       else own.default_dt_safety)
        limit = 0.5 * STABILITY_LIMITS[method]
        if not safety < limit:
            named = ("integrator" if self.integrator is not None
                     else "order" if self.order is not None else "")
            given = self.dt_safety is not None
            runs = (", which continuum = 'auto' may run on this chain"
                    if self.continuum == "auto" and model != "eq4" else "")
            what = (f"[models] dt_safety = {safety:g}" if given else
                    f"[models] dt_safety (not given: the own {safety:g} of continuum "
                    f"{model!r}{runs})")
            origin = (f"the method of [models] {named}" if named
                      else f"the own method of continuum {model!r}{runs}")
            fix = ("set [models] dt_safety in that range" if not given else
                   f"lower dt_safety{' or change ' + named if named else ''}")
            raise ScenarioError(f"{what} is beyond the stability limit of integrator "
                                f"{method!r}: allowed (0, {limit:.4g}) (ω_max Δt = 2 "
                                f"dt_safety < {STABILITY_LIMITS[method]:g}; {origin}): "
                                f"{fix}")
        return method, safety

    @property
    def names(self) -> tuple[str, ...]:
        """The models run, in order ("discrete", "continuum", "theory").

        Of a resolved spec (:meth:`Scenario.with_default_models`); a model not given
        (None) counts as off here.
        """
        return tuple(n for n, on in (("discrete", self.discrete),
                                     ("continuum", bool(self.continuum)),
                                     ("theory", self.theory)) if on)


@dataclass(frozen=True)
class Scenario:
    """A complete, validated scenario."""

    chain: ChainSpec
    initial: InitialSpec = field(default_factory=InitialSpec)
    run: RunSpec = field(default_factory=RunSpec)
    record: RecordSpec = field(default_factory=RecordSpec)
    models: ModelsSpec = field(default_factory=ModelsSpec)
    name: str = ""

    def to_dict(self) -> dict:
        """Plain nested dict (JSON-able; HDF5 attributes, sweep point ids).

        The law's parameters are keys of ``chain`` after ``law``, as in a file: those of
        every registered law, the other laws' at their defaults (so that a file that
        names ``exponent`` with another law reads back, and a chain's dict, its cache
        key and sweep point id do not depend on which law is chosen beyond the values).
        A ``[models] integrator`` or ``dt_safety`` not given is written as
        :meth:`ModelsSpec.step_key`: what it resolves to where the scenario decides it,
        None where the measured incident wave does.
        """
        d = self._plain()
        d["models"].update(self.models.step_key(self.chain, self.incident_strain_given()))
        return d

    def incident_strain_given(self) -> float | None:
        """The incident wave's strain/δ0 where the file sets it, else None.

        ``[initial] strain_max`` (ξ_max/d of an exact wave) over ``[chain]
        delta0_over_d``, under precompression; the run measures it on the built state
        (the same to round-off) and ``"auto"`` picks its model there
        (:meth:`ModelsSpec.continuum_model`).
        """
        d0 = float(self.chain.delta0_over_d)
        strain = getattr(self.initial, "strain_max", None)
        return float(strain) / d0 if strain is not None and d0 > 0 else None

    def _plain(self) -> dict:
        """:meth:`to_dict` with every value as given (None: not given)."""
        d = asdict(self)
        d["chain"] = _flat_law_params(d["chain"])
        d["initial"] = _flat_initial_params(d["initial"])
        return d

    def discrete_dict(self) -> dict:
        """What the discrete run depends on: everything but ``name`` and ``[models]``.

        The cache and checkpoint key of the discrete run (:mod:`hertzchain.models`), so
        that scenarios differing only in their label or in the other models share it.
        """
        d = self.to_dict()
        d.pop("name")
        d.pop("models")
        return d

    def replace(self, **tables) -> Scenario:
        """A copy with whole tables replaced (``record=RecordSpec(...)``), not re-validated."""
        return replace(self, **tables)

    def to_input(self) -> dict:
        """The TOML-like input that parses back to this scenario (:func:`parse_scenario`)."""
        def clean(x):
            if isinstance(x, dict):
                return {k: clean(v) for k, v in x.items() if v is not None}
            if isinstance(x, tuple | list):
                return [clean(v) for v in x]
            return x

        out = clean(self._plain())
        for sec in out["chain"]["sections"]:
            if "material" in sec:
                sec.pop("alpha_rho", None)
                sec.pop("alpha_kn", None)
        return out

    def skipped_models(self, *, compare: bool = False) -> dict[str, str]:
        """The models not given in ``[models]`` that do not apply here, with the reason.

        {model: one-line reason} (:func:`model_applies`, the one place that decides);
        a model given explicitly that does not apply is refused when the scenario is
        parsed.  ``compare``: for ``hertzchain compare`` (the continuum's default is on
        there; in ``run`` and ``sweep`` it is off whether or not it applies, and not
        listed).
        """
        out = {}
        for name in ("continuum", "theory"):
            if getattr(self.models, name) is not None or (name == "continuum"
                                                          and not compare):
                continue
            why = model_applies(name, self.chain, self.initial)
            if why:
                out[name] = why
        return out

    def with_default_models(self, *, compare: bool = False) -> Scenario:
        """A copy whose ``[models]`` not given are resolved (the defaults' one rule).

        ``theory`` not given: on where it applies (:func:`model_applies`).
        ``continuum`` not given: with ``compare`` (``hertzchain compare``) ``"auto"``
        where it applies, otherwise off (``hertzchain run``, sweeps and ``reproduce`` run
        the continuum only when asked: it costs more than the discrete run).  The
        reasons for what stays off: :meth:`skipped_models`.
        """
        m = self.models
        values = {}
        if m.theory is None:
            values["theory"] = not model_applies("theory", self.chain, self.initial)
        if m.continuum is None:
            values["continuum"] = "auto" if compare and not model_applies(
                "continuum", self.chain, self.initial) else False
        return replace(self, models=replace(m, **values)) if values else self

    def with_values(self, values: dict[str, Any]) -> Scenario:
        """A validated copy with keys set by dotted path (``"chain.sections.1.alpha_rho"``).

        List entries are addressed by their 0-based index (as sweep axes do); every
        value is validated as if it had been written in the file.
        """
        data = self.to_input()
        for path, value in values.items():
            set_path(data, path, value)
        return parse_scenario(data)


def _flat_law_params(chain: dict) -> dict:
    """``chain`` (asdict of a :class:`ChainSpec`) with ``law_params`` as keys after ``law``."""
    own = dict(chain["law_params"])
    out = {}
    for name, value in chain.items():
        if name == "law_params":
            continue
        out[name] = value
        if name == "law":
            for key in _law_keys()[1:]:
                out[key.name] = own.get(key.name, key.default)
    return out


def _flat_initial_params(initial: dict) -> dict:
    """``initial`` (asdict of an :class:`InitialSpec`) with ``params`` as keys after ``kind``."""
    own = dict(initial["params"])
    return {"kind": initial["kind"],
            **{k.name: own.get(k.name, k.default) for k in _initial_keys()[1:]}}


_SPECS = {"chain": ChainSpec, "chain.sections": SectionSpec, "initial": InitialSpec,
          "run": RunSpec, "record": RecordSpec, "models": ModelsSpec}


# -- cross-key checks, one function per table --------------------------------------------
def _disordered(values: dict) -> bool:
    return bool(values["disorder_mass"] or values["disorder_stiffness"]
                or values["disorder_diameter"])


def _check_sections(values: dict, where: str, raw: dict) -> None:
    if values["material"] is not None and ("alpha_rho" in raw or "alpha_kn" in raw):
        raise ScenarioError(f"[{where}] give either material or alpha_rho/alpha_kn, not both")
    profile = values["profile"]
    if profile == "tapered" and values["mass_ratio"] is None:
        raise ScenarioError(f"[{where}] profile = 'tapered' needs mass_ratio (m_(i+1)/m_i, "
                            "> 0)")
    if profile != "tapered" and values["mass_ratio"] is not None:
        raise ScenarioError(f"[{where}] mass_ratio applies to profile = 'tapered' only "
                            f"(profile = {profile!r})")
    cells = ("cell_diameters", "cell_alpha_rho", "cell_alpha_kn")
    if profile == "periodic":
        m = len(values["cell_diameters"])
        if m == 0:
            raise ScenarioError(f"[{where}] profile = 'periodic' needs cell_diameters (a "
                                "list of diameter factors > 0, one per grain of the cell)")
        for name in cells[1:]:
            if values[name] and len(values[name]) != m:
                raise ScenarioError(f"[{where}] {name} must have one entry per grain of the "
                                    f"cell: {m} (the length of cell_diameters)")
    else:
        for name in cells:
            if values[name]:
                raise ScenarioError(f"[{where}] {name} applies to profile = 'periodic' only "
                                    f"(profile = {profile!r})")


def _law_params(values: dict, raw: dict) -> tuple[tuple[str, float], ...]:
    """The chosen law's parameters, popped from ``values`` (the read ``[chain]`` table).

    Each is read with its own law's :class:`theory.laws.LawParameter` (range, default);
    a parameter of another law is refused unless it is at its default (a file written
    from :meth:`Scenario.to_dict` names them all).
    """
    from theory.laws import LAWS

    law = values["law"]
    own = LAWS[law].parameters
    for key in _law_keys()[1:]:
        value = values.pop(key.name)
        if key.name in raw and key.name not in {p.name for p in own} and value != key.default:
            owners = [n for n, c in LAWS.items() if key.name in {p.name for p in c.parameters}]
            unit = f" {key.unit}" if key.unit else ""
            raise ScenarioError(f"[chain] {key.name} = {value!r}{unit} applies to law = "
                                f"{' or '.join(repr(n) for n in owners)} only (law = "
                                f"{law!r}; its parameters: "
                                f"{', '.join(p.name for p in own) or 'none'})")
    out = []
    for p in own:
        key = Key(p.name, "number", float(p.default), unit=p.unit, low=p.low, high=p.high,
                  low_open=p.low_open, high_open=p.high_open)
        out.append((p.name, _read_number(key, raw[p.name], "chain") if p.name in raw
                    else key.default))
    return tuple(out)


def _check_chain(spec: ChainSpec) -> None:
    if spec.n < 2:
        raise ScenarioError(f"[chain] the chain needs >= 2 grains (got {spec.n})")
    last = spec.sections[-1]
    if len(spec.sections) > 1 and last.n == 1 and spec.right_wall == "free":
        i = len(spec.sections) - 1
        raise ScenarioError(
            f"[chain.sections[{i}]] n = 1 with [chain] right_wall = 'free': the last "
            "section has no contact of its own (its grain touches only the interface), so "
            "it has no contact constant k_n; give it >= 2 grains or a right wall")
    if spec.delta0_over_d > 0 and "free" in (spec.left_wall, spec.right_wall):
        raise ScenarioError("[chain] a precompressed chain (delta0_over_d > 0) needs two "
                            "walls; left_wall/right_wall = 'free' is only allowed at 0")
    try:
        spec.contact_law()
    except ValueError as exc:  # a law's own checks beyond its parameters' ranges
        raise ScenarioError(f"[chain] law = {spec.law!r}: {exc}") from None
    if spec.gravity > 0:
        if spec.delta0_over_d > 0:
            raise ScenarioError("[chain] delta0_over_d must be 0 with gravity > 0: the "
                                "overlaps grow with depth from force equilibrium; press from "
                                "above with top_force (N)")
        if spec.right_wall == "free":
            raise ScenarioError("[chain] gravity > 0 needs a floor: right_wall = 'paper' or "
                                "'hertz' (not 'free')")
        if spec.top_force > 0 and spec.left_wall == "free":
            raise ScenarioError("[chain] top_force > 0 needs a top wall: left_wall = 'paper' "
                                "or 'hertz' (not 'free')")
    elif spec.top_force != 0:
        raise ScenarioError(f"[chain] top_force = {spec.top_force!r} N applies with gravity "
                            "> 0 only (without gravity set delta0_over_d)")


def _initial_params(values: dict, raw: dict) -> tuple[tuple[str, Any], ...]:
    """The kind's own keys of the read ``[initial]`` table, as (name, value) pairs.

    A key of another kind is refused unless it is at its default (a file written from
    :meth:`Scenario.to_dict` names them all).
    """
    from .initial_kinds import INITIAL_KINDS

    kind = INITIAL_KINDS[values["kind"]]
    own = {k.name for k in kind.keys}
    for key in _initial_keys()[1:]:
        if key.name in raw and key.name not in own and values[key.name] != key.default:
            users = [n for n, k in INITIAL_KINDS.items() if key.name in {x.name for x in k.keys}]
            raise ScenarioError(f"[initial] {key.name} applies to kind = "
                                f"{' or '.join(repr(u) for u in users)} only (kind = "
                                f"{kind.name!r})")
    return tuple((k.name, values[k.name]) for k in kind.keys)


def _grains_text(n: int, initial: InitialSpec) -> str:
    """``"100 grains"``, or with a striker ``"99 grains and the striker (grain 0)"``."""
    if initial.striker_grains:
        return f"{n - 1} grains and the striker (grain 0 of the run)"
    return f"{n} grains"


def _check_run(spec: RunSpec, n: int, initial: InitialSpec) -> None:
    if spec.t_end is None and spec.until_front_at is None:
        raise ScenarioError("[run] give t_end (s, > 0) and/or until_front_at (grain index)")
    if spec.until_front_at is not None and spec.until_front_at >= n:
        raise ScenarioError(f"[run] until_front_at = {spec.until_front_at} can never be "
                            f"reached: allowed range [0, {n - 1}] for "
                            f"{_grains_text(n, initial)}")
    if spec.dt is not None and spec.dt_fraction is not None:
        raise ScenarioError("[run] give dt or dt_fraction, not both (dt_fraction sets the "
                            "'auto' dt)")
    if spec.rtol is not None and spec.dt_fraction is not None:
        raise ScenarioError("[run] give rtol or dt_fraction, not both (both set the 'auto' "
                            "dt; an explicit dt wins over rtol)")
    if spec.integrator == "auto" and spec.rtol is None:
        raise ScenarioError("[run] integrator = 'auto' needs rtol (the method is chosen for "
                            "that accuracy); allowed without rtol: "
                            f"{', '.join(INTEGRATORS)}")


def _check_record(spec: RecordSpec, n: int, t_end: float | None,
                  initial: InitialSpec) -> None:
    if t_end is not None and any(x > t_end for x in spec.snapshot_times):
        raise ScenarioError(f"[record] snapshot_times must be <= run.t_end = {t_end}")
    for name in ("time_series_grains", "snapshot_grains", "sensors"):
        bad = [g for g in getattr(spec, name) if g >= n]
        if bad:
            raise ScenarioError(f"[record] {name} = {list(getattr(spec, name))}: {bad[0]} is "
                                f"not a grain; allowed range [0, {n - 1}] for "
                                f"{_grains_text(n, initial)}")
    if spec.strain_maxima and not spec.running_max:
        raise ScenarioError("[record] strain_maxima = true needs running_max = true")


# -- where each model applies: the one place -------------------------------------------
def continuum_applies(chain: ChainSpec, initial: InitialSpec) -> str:
    """Why the long-wave continuum does not apply to this chain ("" where it does).

    The continuum (:mod:`continuum`, docs/physics.md §19) discretises the chain's own
    per-grain and per-contact coefficients (:class:`theory.medium.Medium`): any contact
    law under precompression (Eq. 4, Rosenau form), a power-law elastic part at any
    precompression (Eq. 7 for exponent n), sections, tapers, disorder, gravity,
    dissipative laws and drag (the viscous long-wave term) and periodic cells
    (homogenised).  It does not describe an impact on a linear chain (n = 1): no
    solitary wave forms, and the struck grain's pulse spreads at the grid scale (the
    Bessel-function front of the harmonic lattice), outside every long-wave equation.
    This function is the one place that says where the continuum applies.
    """
    if chain.exponent == 1.0 and not initial.initial_kind.placed:
        return (f"[chain] exponent = 1.0 with [initial] kind = {initial.kind!r}: a linear "
                "chain forms no solitary wave, and the state's pulse spreads at the grid "
                "scale (the lattice's Bessel front), outside the long-wave equations")
    return ""


def theory_applies(chain: ChainSpec, initial: InitialSpec) -> str:
    """Why the closed-form theory does not apply to this chain ("" where it does).

    The theory (:class:`hertzchain.models.TheoryModel`) describes the leading wave of
    the first section — for any power-law exponent, with dissipation, gravity, a taper
    or a periodic cell (:mod:`theory.gravity`, :mod:`theory.tapers`,
    :mod:`theory.dimers`, :mod:`theory.dissipation`, :mod:`theory.striker`) — and says
    for each quantity it cannot predict why (null with a reason).  It does not apply
    where it has nothing to predict: a disordered first section (no published
    closed form for the wave of a random chain) or a last section without a contact.
    """
    first = chain.sections[0]
    for name in ("disorder_mass", "disorder_stiffness", "disorder_diameter"):
        if getattr(first, name):
            return (f"[chain.sections[0]] {name} = {getattr(first, name)!r}: no closed "
                    "form describes the wave of a disordered section")
    return ""


def quasicontinuum_applies(chain: ChainSpec) -> str:
    """Why the grain-averaged quasi-continuum does not fit ``chain`` ("" where it does).

    :class:`continuum.GrainAveragedPDE` (docs/physics.md §24) is conservative and
    resolves every grain's own mass and contact: it refuses (``ValueError``) a
    dissipative contact law or on-site drag (it has no viscous long-wave term: those
    take Eq. 4 or Eq. 7), homogenised periodic cells (``profile = "periodic"``: their
    dispersion factor is Eq. 4's and Eq. 7's) and periodic ends (which no scenario has:
    the continuum's ends are free or walls).  This is its refusal read off the scenario,
    without building the medium, for :meth:`ModelsSpec.continuum_model`: where it
    names a reason, ``"auto"`` runs Eq. 7 instead.
    """
    if chain.drag:
        return (f"[chain] drag = {chain.drag:g}: the quasi-continuum is conservative (no "
                "viscous long-wave term)")
    if chain.contact_law().dissipative:
        return (f"[chain] law = {chain.law!r} is dissipative: the quasi-continuum is "
                "conservative (no viscous long-wave term)")
    for i, sec in enumerate(chain.sections):
        if sec.profile == "periodic":
            return (f"[chain.sections[{i}]] profile = 'periodic': the quasi-continuum "
                    "resolves grains, it does not homogenise cells")
    return ""


_APPLIES = {"continuum": continuum_applies, "theory": theory_applies}


def model_applies(model: str, chain: ChainSpec, initial: InitialSpec) -> str:
    """Why ``model`` (``"continuum"`` or ``"theory"``) does not apply ("" where it does).

    The single place where applicability is decided: the parser refuses an explicit
    request with this reason, and a model not given is left off with it
    (:meth:`Scenario.skipped_models`, printed by ``hertzchain compare`` and stored in
    its JSON).  The discrete chain applies to every chain.
    """
    if model == "discrete":
        return ""
    if model not in _APPLIES:
        raise ValueError(f"model must be 'discrete', 'continuum' or 'theory' (got {model!r})")
    return _APPLIES[model](chain, initial)


def _check_models(spec: ModelsSpec, chain: ChainSpec, initial: InitialSpec) -> None:
    from theory.splitting import ORDER_METHODS, get_splitting

    theory_on = spec.theory if spec.theory is not None else not model_applies(
        "theory", chain, initial)
    if not (spec.discrete or spec.continuum or theory_on):
        raise ScenarioError("[models] every model is off: set discrete, continuum or theory")
    if spec.nodes_per_grain % 2 == 0:
        raise ScenarioError(f"[models] nodes_per_grain = {spec.nodes_per_grain} must be odd "
                            "(a node on every grain centre)")
    if spec.order is not None and spec.order not in ORDER_METHODS:
        raise ScenarioError(f"[models] order = {spec.order}; allowed: 2, 4 (deprecated: "
                            "use integrator)")
    if spec.continuum == "kdv" and (spec.integrator is not None or spec.order is not None
                                    or spec.dt_safety is not None):
        raise ScenarioError("[models] integrator, order and dt_safety do not apply to "
                            "continuum = \"kdv\" (KdV steps with py-pde's Runge-Kutta at its "
                            "own stable_dt): drop them")
    if spec.order is not None and spec.integrator is not None and (
            spec.order != (order := get_splitting(spec.integrator).order)):
        raise ScenarioError(f"[models] order = {spec.order} contradicts integrator = "
                            f"{spec.integrator!r} (order {order}): drop order")
    # the step of every model the continuum may run, each at its own defaults where not
    # given ("auto" under precompression: the incident wave decides later).  A continuum
    # off or not given is not checked here: the defaults are the model classes' own, and
    # importing the continuum (py-pde) would cost every discrete run's start-up; where
    # `compare` or a sweep turns it on, the run resolves the step with the same check
    # (ModelsSpec.continuum_step, a ScenarioError naming the key and the range)
    strain = Scenario(chain=chain, initial=initial).incident_strain_given()
    for name in spec.possible_continuum_models(chain, strain):
        if name != "kdv":
            spec.continuum_step(name)
    for name in ("continuum", "theory"):  # an explicit request must apply
        why = model_applies(name, chain, initial) if getattr(spec, name) else ""
        if why:
            value = "true" if getattr(spec, name) is True else repr(getattr(spec, name))
            raise ScenarioError(f"[models] {name} = {value} does not apply to this chain: "
                                f"{why}; set [models] {name} = false, or leave it out (it "
                                "then runs where it applies)")
    if spec.nonlinearity == "hertz" and chain.exponent != 1.5:
        raise ScenarioError(f"[models] nonlinearity = 'hertz' is the Hertz law's full force; "
                            f"[chain] law = {chain.law!r} has exponent {chain.exponent:g}: "
                            "use 'full' (the chain's own law)")
    d0 = chain.delta0_over_d
    model = spec.continuum_model(chain)
    if model in ("eq4", "kdv") and d0 == 0:
        raise ScenarioError(
            f"[models] continuum = {spec.continuum!r} needs a precompressed chain "
            f"([chain] delta0_over_d > 0): {'Eq. 4' if model == 'eq4' else 'KdV'} "
            "linearises about δ0 and has no sonic vacuum; use \"eq7\" or \"auto\"")
    if model == "kdv" and len(chain.sections) != 1:
        raise ScenarioError(
            f"[models] continuum = 'kdv' is unidirectional and needs one section (got "
            f"{len(chain.sections)}); use \"eq4\" or \"auto\" for an interface")


def parse_scenario(data: dict) -> Scenario:
    """Validate a scenario given as nested dicts (the parsed TOML)."""
    if not isinstance(data, dict):
        raise ScenarioError("a scenario must be a table")
    top = {k: v for k, v in data.items() if k not in _TABLES}
    values = _read_table(top, "", _TABLES)
    for key in _TABLES:
        if key in data and not isinstance(data[key], dict):
            raise ScenarioError(f"[{key}] must be a table")
    if "chain" not in data:
        raise ScenarioError("[chain] table is required")
    raw_chain = dict(data["chain"])
    raw_sections = raw_chain.pop("sections", None)
    if not isinstance(raw_sections, list) or not raw_sections:
        raise ScenarioError("[chain] sections is required: a list of [[chain.sections]] "
                            "tables with at least one entry")
    sections = []
    for i, s in enumerate(raw_sections):
        where = f"chain.sections[{i}]"
        if not isinstance(s, dict):
            raise ScenarioError(f"[{where}] must be a table (got {s!r})")
        try:
            v = _read_table(s, "chain.sections")
        except ScenarioError as exc:
            raise ScenarioError(str(exc).replace("[chain.sections]", f"[{where}]")) from None
        if v["seed"] is None:  # the section's index: disordered sections differ
            v["seed"] = i if _disordered(v) else 0
        _check_sections(v, where, s)
        sections.append(SectionSpec(**v))
    chain_values = _read_table(raw_chain, "chain", ("sections",))
    chain = ChainSpec(sections=tuple(sections),
                      law_params=_law_params(chain_values, raw_chain), **chain_values)
    _check_chain(chain)
    n = chain.n
    raw_initial = data.get("initial", {})
    initial_values = _read_table(raw_initial, "initial")
    initial = InitialSpec(kind=initial_values["kind"],
                          params=_initial_params(initial_values, raw_initial))
    initial.initial_kind.check(initial, chain)
    n_run = n + initial.striker_grains
    run = RunSpec(**_read_table(data.get("run", {}), "run"))
    _check_run(run, n_run, initial)
    if run.integrator not in ("verlet", "auto") and (chain.contact_law().dissipative
                                                     or chain.drag > 0):
        cause = "drag > 0" if chain.drag > 0 else f"law = {chain.law!r}"
        raise ScenarioError(
            f"[run] integrator = {run.integrator!r} needs forces that depend on positions "
            f"only; with [chain] {cause} the forces depend on velocities: use integrator = "
            "'verlet' (velocity Verlet between exact dissipative sub-steps, "
            "discrete.kernels)")
    record = RecordSpec(**_read_table(data.get("record", {}), "record"))
    _check_record(record, n_run, run.t_end, initial)
    raw_models = data.get("models", {})
    models = ModelsSpec(**_read_table(raw_models, "models"))
    _check_models(models, chain, initial)
    return Scenario(chain=chain, initial=initial, run=run, record=record, models=models,
                    name=values["name"])


_TABLES = ("chain", "initial", "run", "record", "models")


def set_path(data: dict, path: str, value) -> None:
    """Set ``value`` at a dotted ``path`` of nested tables/lists (ScenarioError if absent)."""
    keys = path.split(".")
    node = data
    for i, key in enumerate(keys[:-1]):
        if isinstance(node, list):
            if not key.isdigit() or int(key) >= len(node):
                raise ScenarioError(f"{path}: no entry {key} in {'.'.join(keys[:i])}")
            node = node[int(key)]
        else:
            node = node.setdefault(key, {})
        if not isinstance(node, dict | list):
            raise ScenarioError(f"{path}: {'.'.join(keys[:i + 1])} is not a table or list")
    last = keys[-1]
    if isinstance(node, list):
        if not last.isdigit() or int(last) >= len(node):
            raise ScenarioError(f"{path}: no entry {last} in {'.'.join(keys[:-1])}")
        node[int(last)] = value
    elif value is None:
        node.pop(last, None)
    else:
        node[last] = value


def read_toml(path: Path, error: type[ValueError] = ValueError, what: str = "file") -> dict:
    """Parse a TOML file; a missing or malformed file raises ``error`` naming the path."""
    try:
        with Path(path).open("rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError as exc:
        raise error(f"{what} not found: {path}") from exc
    except IsADirectoryError as exc:
        raise error(f"{what} {path} is a directory; give a TOML file") from exc
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not valid TOML: {exc}") from exc
    except UnicodeDecodeError as exc:  # TOML is UTF-8 (TOML 1.0 spec)
        raise error(f"{path}: not UTF-8 text (TOML files are UTF-8): byte "
                    f"{exc.object[exc.start:exc.start + 1]!r} at offset {exc.start}") from None
    except RecursionError:
        raise error(f"{path}: not valid TOML for a {what}: arrays or tables nested too "
                    "deeply (a scenario nests at most a few levels)") from None


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file (a name without a path: a shipped one)."""
    path = Path(path)
    if not path.exists() and path.parent == Path(".") and path.stem in shipped_scenarios():
        path = shipped_scenarios()[path.stem]
    data = read_toml(path, ScenarioError, "scenario file")
    try:
        sc = parse_scenario(data)
    except ScenarioError as exc:
        raise ScenarioError(f"{path}: {exc}") from None
    return sc if sc.name else replace(sc, name=path.stem)


def shipped_scenarios() -> dict[str, Path]:
    """The scenario files shipped in ``hertzchain/scenarios/`` (incl. ``paper/``), by stem."""
    root = Path(__file__).resolve().parent / "scenarios"
    return {p.stem: p for p in sorted(root.rglob("*.toml"))}


# -- docs -------------------------------------------------------------------------------
def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(v)


def schema_markdown() -> str:
    """The scenario schema as Markdown: one table of keys per TOML table (from :data:`SCHEMA`)."""
    out = []
    for table, keys in SCHEMA.items():
        head = "Top level" if table == "" else (
            "``[[chain.sections]]``" if table == "chain.sections" else f"``[{table}]``")
        out.append(f"{head} — {TABLE_DOCS[table]}\n")
        out.append("=" * 18 + "  " + "=" * 16 + "  " + "=" * 60)
        out.append(f"{'key':18}  {'default':16}  meaning")
        out.append("=" * 18 + "  " + "=" * 16 + "  " + "=" * 60)
        for k in keys:
            default = "*required*" if k.required else (
                "—" if k.default is None else _toml_value(k.default))
            extra = []
            if k.unit:
                extra.append(k.unit)
            if k.kind == "continuum":
                extra.append(f"one of {k.range_text()}")
            elif k.kind != "choice" and k.range_text():
                extra.append(f"range {k.range_text()}")
            doc = k.doc + (f" ({'; '.join(extra)})" if extra else "")
            out.append(f"{k.name:18}  {default:16}  {doc}")
        out.append("=" * 18 + "  " + "=" * 16 + "  " + "=" * 60 + "\n")
    return "\n".join(out)


def _example() -> str:
    """A complete example scenario built from the schema's examples and defaults."""
    lines = []

    def emit(table: str, indent: str = "") -> None:
        for k in SCHEMA[table]:
            v = k.example if k.example is not None else k.default
            if v is None or (table == "chain.sections" and k.name == "material"):
                continue
            lines.append(f"{indent}{k.name} = {_toml_value(v)}")

    emit("")
    for table in ("chain", "initial", "run", "record", "models"):
        lines.append(f"\n[{table}]")
        emit(table)
        if table == "chain":
            lines.append("[[chain.sections]]")
            emit("chain.sections")
            lines.append("[[chain.sections]]\nn = 800\nalpha_rho = 0.5\nalpha_kn = 2.0")
    return "\n".join(lines)


def schema_reference() -> str:
    """The scenario reference (reST): an example with every key, then :func:`schema_markdown`.

    Made from the registries on each call; the documentation inserts it into this
    module's page (``docs/conf.py``).
    """
    return ("Example (every key shown; all are optional except ``[chain]`` with at least "
            "one section)::\n\n" + "\n".join("    " + ln if ln else ""
                                             for ln in _example().splitlines())
            + "\n\nKeys\n----\n" + schema_markdown())


_REGISTERED_FIELDS = {"chain": {"sections", "law", "law_params"},
                      "initial": {"kind", "params"}}
"""The fields of a table's dataclass that hold registered keys (and sub-tables)."""


def _check_schema_matches_specs() -> None:
    for table, spec in _SPECS.items():
        names = {k.name for k in SCHEMA.written(table)}
        have = {f.name for f in fields(spec)} - _REGISTERED_FIELDS.get(table, set())
        if names != have:  # pragma: no cover - a schema edit without the dataclass
            raise AssertionError(f"SCHEMA[{table!r}] and {spec.__name__} disagree: "
                                 f"{sorted(names ^ have)}")


_check_schema_matches_specs()
