"""Scenarios: a documented TOML description of one simulation, validated strictly.

A scenario file has four tables (every key optional unless marked *required*)::

    name = "M"                        # free label

    [chain]
    diameter = 5e-3                   # grain diameter d, m (> 0)
    delta0_over_d = 1e-3              # static overlap of the first section / d (>= 0, < 0.1)
    material = "paper"                # "paper" (Hertz, nu=0.30), "table1" (nu=0.25) or
                                      # {density=, youngs_modulus=, poisson_ratio=}
    left_wall = "paper"               # "paper" (as grain-grain), "hertz" (rigid flat), "free"
    right_wall = "paper"
    [[chain.sections]]                # *required*, one or more, left to right
    n = 200                           # grains (>= 1); sum over sections >= 2
    alpha_rho = 1.0                   # density / first section's (> 0), or material = ...
    alpha_kn = 1.0                    # contact stiffness / first section's (> 0)

    [initial]
    kind = "cut_wave"                 # "impact", "cut_wave" or "exact_wave"
    v0 = 1.0                          # impact velocity, m/s (impact, cut_wave)
    striker_mass = 1.0                # impact: striker mass / first grain's (> 0)
    center = 100                      # cut_wave, exact_wave: grain of the wave's peak
    half_width = 40                   # cut_wave: grains kept on each side (>= 30)
    velocity_max = 0.0822             # exact_wave: peak grain velocity, m/s

    [run]
    t_end = 0.01                      # s (> 0), and/or
    until_front_at = 550              # stop when the leading wave's centre reaches this grain
    dt = "auto"                       # "auto" or a time step in s (> 0)
    max_steps = 100000000

    [record]
    snapshot_times = [0.001, 0.002]   # s
    time_series_grains = [395, 396]   # grain indices (0-based)
    energy_every = 50                 # steps between energy-grid rows (0 = off)
    running_max = true

Grain indices are 0-based (the paper's grain 201 is index 200).  Unknown keys are
errors (they are usually typos); every error names the key, the value and the allowed
range.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

__all__ = [
    "ScenarioError",
    "SectionSpec",
    "ChainSpec",
    "InitialSpec",
    "RunSpec",
    "RecordSpec",
    "Scenario",
    "load_scenario",
    "parse_scenario",
]


class ScenarioError(ValueError):
    """A scenario file or table is invalid; the message names the key and allowed range."""


# -- small typed readers ------------------------------------------------------------
def _check_keys(table: dict, allowed: set[str], where: str) -> None:
    unknown = set(table) - allowed
    if unknown:
        raise ScenarioError(
            f"unknown key(s) {sorted(unknown)} in [{where}]; allowed: {sorted(allowed)}")


def _number(table: dict, key: str, where: str, default=None, *, low=None, high=None,
            low_open=True, high_open=True, required=False) -> float | None:
    if key not in table:
        if required:
            raise ScenarioError(f"[{where}] {key} is required")
        return default
    val = table[key]
    if isinstance(val, bool) or not isinstance(val, int | float):
        raise ScenarioError(f"[{where}] {key} must be a number (got {val!r})")
    val = float(val)
    if not math.isfinite(val):
        raise ScenarioError(f"[{where}] {key} must be finite (got {val!r})")
    bad_low = low is not None and (val <= low if low_open else val < low)
    bad_high = high is not None and (val >= high if high_open else val > high)
    if bad_low or bad_high:
        lo = "-inf" if low is None else f"{low:g}"
        hi = "inf" if high is None else f"{high:g}"
        br = ("(" if low_open else "[") + f"{lo}, {hi}" + (")" if high_open else "]")
        raise ScenarioError(f"[{where}] {key} = {val!r} is outside the allowed range {br}")
    return val


def _integer(table: dict, key: str, where: str, default=None, *, low=None,
             required=False) -> int | None:
    if key not in table:
        if required:
            raise ScenarioError(f"[{where}] {key} is required")
        return default
    val = table[key]
    if isinstance(val, bool) or not isinstance(val, int):
        raise ScenarioError(f"[{where}] {key} must be an integer (got {val!r})")
    if low is not None and val < low:
        raise ScenarioError(f"[{where}] {key} = {val} must be >= {low}")
    return val


def _choice(table: dict, key: str, where: str, choices: tuple[str, ...], default: str) -> str:
    val = table.get(key, default)
    if val not in choices:
        raise ScenarioError(f"[{where}] {key} = {val!r}; allowed: {list(choices)}")
    return val


# -- the specs ------------------------------------------------------------------------
MATERIAL_KEYS = {"density", "youngs_modulus", "poisson_ratio"}


def _material(value, where: str):
    if isinstance(value, str):
        if value not in ("paper", "table1"):
            raise ScenarioError(f"[{where}] material = {value!r}; allowed: 'paper', 'table1' "
                                "or a table {density, youngs_modulus, poisson_ratio}")
        return value
    if not isinstance(value, dict):
        raise ScenarioError(f"[{where}] material must be a name or a table (got {value!r})")
    _check_keys(value, MATERIAL_KEYS, f"{where}.material")
    return {
        "density": _number(value, "density", f"{where}.material", low=0, required=True),
        "youngs_modulus": _number(value, "youngs_modulus", f"{where}.material", low=0,
                                  required=True),
        "poisson_ratio": _number(value, "poisson_ratio", f"{where}.material", low=-1,
                                 high=0.5, required=True),
    }


@dataclass(frozen=True)
class SectionSpec:
    """One section of the chain: ``n`` grains, ratios to the first section or a material."""

    n: int
    alpha_rho: float = 1.0
    alpha_kn: float = 1.0
    material: Any = None


@dataclass(frozen=True)
class ChainSpec:
    """The chain: sections, diameter (m), precompression δ0/d of the first section, walls."""

    sections: tuple[SectionSpec, ...]
    diameter: float = 5e-3
    delta0_over_d: float = 0.0
    material: Any = "paper"
    left_wall: str = "paper"
    right_wall: str = "paper"

    @property
    def n(self) -> int:
        """Total number of grains."""
        return sum(s.n for s in self.sections)


@dataclass(frozen=True)
class InitialSpec:
    """Initial condition (see module docstring)."""

    kind: str = "impact"
    v0: float = 1.0
    striker_mass: float = 1.0
    center: int | None = None
    half_width: int = 40
    velocity_max: float | None = None


@dataclass(frozen=True)
class RunSpec:
    """Stop condition and time step."""

    t_end: float | None = None
    until_front_at: int | None = None
    dt: float | None = None
    max_steps: int = 100_000_000


@dataclass(frozen=True)
class RecordSpec:
    """What to record."""

    snapshot_times: tuple[float, ...] = ()
    time_series_grains: tuple[int, ...] = ()
    energy_every: int = 0
    running_max: bool = True


@dataclass(frozen=True)
class Scenario:
    """A complete, validated scenario."""

    chain: ChainSpec
    initial: InitialSpec = field(default_factory=InitialSpec)
    run: RunSpec = field(default_factory=RunSpec)
    record: RecordSpec = field(default_factory=RecordSpec)
    name: str = ""

    def to_dict(self) -> dict:
        """Plain nested dict (JSON-able; the cache key and the HDF5 attributes)."""
        return asdict(self)


def _parse_chain(t: dict) -> ChainSpec:
    w = "chain"
    _check_keys(t, {"sections", "diameter", "delta0_over_d", "material", "left_wall",
                    "right_wall"}, w)
    raw = t.get("sections")
    if not isinstance(raw, list) or not raw:
        raise ScenarioError("[chain] sections is required: a list of [[chain.sections]] "
                            "tables with at least one entry")
    sections = []
    for i, s in enumerate(raw):
        ws = f"chain.sections[{i}]"
        if not isinstance(s, dict):
            raise ScenarioError(f"[{ws}] must be a table (got {s!r})")
        _check_keys(s, {"n", "alpha_rho", "alpha_kn", "material"}, ws)
        mat = _material(s["material"], ws) if "material" in s else None
        if mat is not None and ("alpha_rho" in s or "alpha_kn" in s):
            raise ScenarioError(f"[{ws}] give either material or alpha_rho/alpha_kn, not both")
        sections.append(SectionSpec(
            n=_integer(s, "n", ws, low=1, required=True),
            alpha_rho=_number(s, "alpha_rho", ws, 1.0, low=0),
            alpha_kn=_number(s, "alpha_kn", ws, 1.0, low=0),
            material=mat,
        ))
    spec = ChainSpec(
        sections=tuple(sections),
        diameter=_number(t, "diameter", w, 5e-3, low=0),
        delta0_over_d=_number(t, "delta0_over_d", w, 0.0, low=0, low_open=False, high=0.1),
        material=_material(t.get("material", "paper"), w),
        left_wall=_choice(t, "left_wall", w, ("paper", "hertz", "free"), "paper"),
        right_wall=_choice(t, "right_wall", w, ("paper", "hertz", "free"), "paper"),
    )
    if spec.n < 2:
        raise ScenarioError(f"[chain] the chain needs >= 2 grains (got {spec.n})")
    if spec.delta0_over_d > 0 and "free" in (spec.left_wall, spec.right_wall):
        raise ScenarioError("[chain] a precompressed chain (delta0_over_d > 0) needs two "
                            "walls; left_wall/right_wall = 'free' is only allowed at 0")
    return spec


def _parse_initial(t: dict, n: int) -> InitialSpec:
    w = "initial"
    _check_keys(t, {"kind", "v0", "striker_mass", "center", "half_width", "velocity_max"}, w)
    kind = _choice(t, "kind", w, ("impact", "cut_wave", "exact_wave"), "impact")
    spec = InitialSpec(
        kind=kind,
        v0=_number(t, "v0", w, 1.0, low=0),
        striker_mass=_number(t, "striker_mass", w, 1.0, low=0),
        center=_integer(t, "center", w, None, low=0),
        half_width=_integer(t, "half_width", w, 40, low=30),
        velocity_max=_number(t, "velocity_max", w, None, low=0),
    )
    if kind in ("cut_wave", "exact_wave"):
        if spec.center is None:
            raise ScenarioError(f"[initial] center is required for kind = {kind!r}")
        margin = spec.half_width if kind == "cut_wave" else 10
        if not margin <= spec.center < n - margin:
            raise ScenarioError(
                f"[initial] center = {spec.center} places the wave outside the chain; "
                f"allowed range [{margin}, {n - margin - 1}] for {n} grains")
    if kind == "exact_wave" and spec.velocity_max is None:
        raise ScenarioError("[initial] velocity_max (m/s, > 0) is required for 'exact_wave'")
    return spec


def _parse_run(t: dict, n: int) -> RunSpec:
    w = "run"
    _check_keys(t, {"t_end", "until_front_at", "dt", "max_steps"}, w)
    dt = t.get("dt", "auto")
    if dt == "auto":
        dt_val = None
    else:
        dt_val = _number(t, "dt", w, low=0)
    spec = RunSpec(
        t_end=_number(t, "t_end", w, None, low=0),
        until_front_at=_integer(t, "until_front_at", w, None, low=0),
        dt=dt_val,
        max_steps=_integer(t, "max_steps", w, 100_000_000, low=1),
    )
    if spec.t_end is None and spec.until_front_at is None:
        raise ScenarioError("[run] give t_end (s, > 0) and/or until_front_at (grain index)")
    if spec.until_front_at is not None and spec.until_front_at >= n:
        raise ScenarioError(f"[run] until_front_at = {spec.until_front_at} can never be "
                            f"reached: allowed range [0, {n - 1}] for {n} grains")
    return spec


def _parse_record(t: dict, n: int, t_end: float | None) -> RecordSpec:
    w = "record"
    _check_keys(t, {"snapshot_times", "time_series_grains", "energy_every", "running_max"}, w)
    times = t.get("snapshot_times", [])
    grains = t.get("time_series_grains", [])
    if not isinstance(times, list) or not isinstance(grains, list):
        raise ScenarioError("[record] snapshot_times and time_series_grains must be lists")
    times_v = tuple(_number({"t": x}, "t", "record.snapshot_times", low=0, low_open=False)
                    for x in times)
    if t_end is not None and any(x > t_end for x in times_v):
        raise ScenarioError(f"[record] snapshot_times must be <= run.t_end = {t_end}")
    grains_v = tuple(_integer({"g": g}, "g", "record.time_series_grains", low=0)
                     for g in grains)
    if any(g >= n for g in grains_v):
        raise ScenarioError(f"[record] time_series_grains must lie in [0, {n - 1}]")
    running_max = t.get("running_max", True)
    if not isinstance(running_max, bool):
        raise ScenarioError(f"[record] running_max must be true or false (got {running_max!r})")
    return RecordSpec(
        snapshot_times=times_v,
        time_series_grains=grains_v,
        energy_every=_integer(t, "energy_every", w, 0, low=0),
        running_max=running_max,
    )


def parse_scenario(data: dict) -> Scenario:
    """Validate a scenario given as nested dicts (the parsed TOML)."""
    if not isinstance(data, dict):
        raise ScenarioError("a scenario must be a table")
    _check_keys(data, {"name", "chain", "initial", "run", "record"}, "top level")
    for key in ("chain", "initial", "run", "record"):
        if key in data and not isinstance(data[key], dict):
            raise ScenarioError(f"[{key}] must be a table")
    if "chain" not in data:
        raise ScenarioError("[chain] table is required")
    chain = _parse_chain(data["chain"])
    run = _parse_run(data.get("run", {}), chain.n)
    name = data.get("name", "")
    if not isinstance(name, str):
        raise ScenarioError(f"name must be a string (got {name!r})")
    return Scenario(
        chain=chain,
        initial=_parse_initial(data.get("initial", {}), chain.n),
        run=run,
        record=_parse_record(data.get("record", {}), chain.n, run.t_end),
        name=name,
    )


def read_toml(path: Path, error: type[ValueError] = ValueError, what: str = "file") -> dict:
    """Parse a TOML file; a missing or malformed file raises ``error`` naming the path."""
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError as exc:
        raise error(f"{what} not found: {path}") from exc
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not valid TOML: {exc}") from exc


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file."""
    path = Path(path)
    data = read_toml(path, ScenarioError, "scenario file")
    try:
        return parse_scenario(data)
    except ScenarioError as exc:
        raise ScenarioError(f"{path}: {exc}") from None
