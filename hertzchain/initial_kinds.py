"""The kinds of initial state of a scenario (``[initial] kind``): one class each, one registry line.

Every model starts from the same discrete grain state; a *kind* is one recipe for it and
says, in one class (:class:`InitialKind`), everything the package needs to know of it:

* its ``[initial]`` keys (:attr:`InitialKind.keys`, :class:`hertzchain.scenario.Key`:
  type, default, range, unit, help) and the checks that involve the chain
  (:meth:`InitialKind.check`);
* how it builds the discrete initial state (:meth:`InitialKind.build`, a
  :class:`discrete.initial.Initial`), which key names its amplitude and which state is
  checked against the small-strain range (:meth:`InitialKind.amplitude_state`);
* where its incident wave is, which is what the continuum, the theory and
  ``hertzchain compare`` read: either **placed** (:attr:`InitialKind.placed`: the state
  *is* the wave, its peak at grain ``center``; position, peak velocity and strain are read
  off the state), or **formed on the way** (an impact: the wave's speed and amplitude are
  estimated from the state, :meth:`InitialKind.incident_velocity`, and measured on the
  discrete run when its peak passes the middle of section 0,
  :func:`hertzchain.measure.incident_grain`; the incident front is fitted once the wave
  has formed);
* how the continuum takes the state (:attr:`InitialKind.interpolation`, of
  :func:`continuum.from_grains`), whether it is one struck grain (the linear chain's
  Bessel front, :attr:`InitialKind.single_struck_grain`) and whether it prepends a
  striker grain (:meth:`InitialKind.striker_grains`).

:mod:`hertzchain.scenario`, :mod:`hertzchain.runner`, :mod:`hertzchain.models` and
:mod:`hertzchain.compare` ask the kind (``scenario.initial.initial_kind``) and never
compare its name.  A new kind is a subclass in a file of its own and one
:func:`register_initial_kind` call; the scenario files, the validation (did-you-mean,
ranges) and the scenario reference follow.

This module imports no NumPy (the scenario schema reads the keys, and
``hertzchain --help`` must not import it): building a state imports :mod:`discrete`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar

from .scenario import Key, ScenarioError

if TYPE_CHECKING:  # pragma: no cover
    from .scenario import ChainSpec, InitialSpec

__all__ = ["InitialKind", "Impact", "CutWave", "ExactWave", "INITIAL_KINDS",
           "register_initial_kind", "initial_kind", "initial_keys"]


class InitialKind:
    """One kind of initial state (module docstring); subclasses set the class attributes.

    Attributes
    ----------
    name : str
        The value of ``[initial] kind``.
    doc : str
        One line of help (the scenario reference is generated from it).
    keys : tuple of Key
        The ``[initial]`` keys it reads (a key shared by two kinds is the same
        :class:`~hertzchain.scenario.Key`).
    placed : bool
        The state is the incident wave with its peak at grain ``center`` (a key of the
        kind); False: the wave forms on the way and is measured on the discrete run.
    interpolation : str
        How the continuum interpolates the state (:func:`continuum.from_grains`):
        ``"smooth"`` for a smooth wave (the model's own choice, cubic splines or the
        band-limited interpolant), ``"grains"`` for a state that jumps from grain
        to grain (keeps the grains' momentum and energy).
    single_struck_grain : bool
        One grain moves, the rest is at rest (the linear chain's Bessel-function front,
        :class:`hertzchain.models.ChainTheory` ``"linear"``, describes it).
    """

    name: ClassVar[str] = ""
    doc: ClassVar[str] = ""
    keys: ClassVar[tuple[Key, ...]] = ()
    placed: ClassVar[bool] = False
    interpolation: ClassVar[str] = "smooth"
    single_struck_grain: ClassVar[bool] = False

    # ---------------------------------------------------------------- scenario
    def check(self, spec: InitialSpec, chain: ChainSpec) -> None:
        """ScenarioError for values that do not fit this chain.

        Default: a placed wave's ``center`` is given and inside the chain by
        :meth:`margin` grains.
        """
        if not self.placed:
            return
        center = spec.center
        if center is None:
            raise ScenarioError(f"[initial] center is required for kind = {self.name!r}")
        margin, n = self.margin(spec), chain.n
        if not margin <= center < n - margin:
            raise ScenarioError(
                f"[initial] center = {center} places the wave outside the chain; "
                f"allowed range [{margin}, {n - margin - 1}] for {n} grains")

    def margin(self, spec: InitialSpec) -> int:
        """Grains a placed wave needs on each side of ``center``."""
        return 10

    def striker_grains(self, spec: InitialSpec) -> int:
        """Grains prepended to the chain by the state (a striker): 0 or 1."""
        return 0

    def amplitude_key(self, spec: InitialSpec) -> str:
        """The ``[initial]`` key that sets the amplitude (named in messages)."""
        raise NotImplementedError

    # ---------------------------------------------------------------- state
    def build(self, spec: InitialSpec, chain_spec: ChainSpec, chain, *, cache_dir=None):
        """The discrete initial state (:class:`discrete.initial.Initial`) on ``chain``.

        ``chain``: the built :class:`discrete.Chain`; ``cache_dir``: where a costly
        state may be cached (None: in memory only).  ValueError if it does not fit.
        """
        raise NotImplementedError

    def amplitude_state(self, spec: InitialSpec, chain, init=None):
        """The state whose expected overlaps are checked against the small-strain range.

        Called before the state is built (``init`` None) and after (``init`` the built
        state); returns the state to check, or None for nothing at this stage.  Default:
        the built state.
        """
        return init

    def build_error(self, spec: InitialSpec, exc: Exception) -> str:
        """The message of a ValueError of :meth:`build`, naming the key at fault."""
        if self.placed:
            return (f"[initial] center = {spec.center} (kind = {self.name!r}): the "
                    f"requested wave does not fit in the chain or in one section: {exc}")
        return f"[initial] kind = {self.name!r}: {exc}"

    def incident_velocity(self, init) -> float:
        """Peak grain velocity of the incident wave, m/s (of a formed wave: an estimate)."""
        import numpy as np

        return float(np.max(np.abs(init.v)))


# ----------------------------------------------------------------------- the kinds
V0 = Key("v0", "number", 1.0, "impact velocity", "m/s", low=0)
CENTER = Key("center", "integer", None, "grain of the wave's peak", low=0, low_open=False,
             example=100)

IMPACT_FORMATION = 0.68
"""v̄max/v0 of an impact's solitary wave at δ0 = 0 (paper Fig. 2): the estimate of its
peak velocity before it is measured on the run."""


class Impact(InitialKind):
    """Grain 0 (or a prepended striker) moves at ``v0``, the rest at rest (paper Fig. 2)."""

    name = "impact"
    doc = "grain 0 at v0"
    keys = (V0, Key("striker_mass", "number", 1.0, "striker mass / the first grain's; "
                    "other than 1 the striker is an extra grain prepended as grain 0 of the "
                    "run (so the run's grain i + 1 is the chain's grain i)", low=0))
    interpolation = "grains"
    single_struck_grain = True

    def check(self, spec, chain):
        """A striker grain is not part of a vertical chain's static equilibrium."""
        if spec.striker_mass != 1.0 and chain.gravity > 0:
            raise ScenarioError("[initial] striker_mass != 1 with [chain] gravity > 0: a "
                                "striker grain is not part of the chain's static "
                                "equilibrium; give striker_mass = 1 (grain 0 is struck)")

    def striker_grains(self, spec):
        """1 with a striker (``striker_mass`` other than 1)."""
        return int(spec.striker_mass != 1.0)

    def amplitude_key(self, spec):
        """``v0``."""
        return "v0"

    def build(self, spec, chain_spec, chain, *, cache_dir=None):
        """:func:`discrete.initial.impact`; the striker's mass in kg."""
        from discrete.initial import impact

        ms = None if spec.striker_mass == 1.0 else spec.striker_mass * float(chain.mass[0])
        return impact(chain, spec.v0, striker_mass=ms)

    def amplitude_state(self, spec, chain, init=None):
        """Checked before building: the impact itself (without a striker)."""
        if init is not None:
            return None
        from discrete.initial import impact

        return impact(chain, spec.v0)

    def incident_velocity(self, init):
        """:data:`IMPACT_FORMATION` × v0 (the wave forms on the way)."""
        return IMPACT_FORMATION * super().incident_velocity(init)


class CutWave(InitialKind):
    """The settled impact wave, cut and placed at ``center`` (paper Section 2)."""

    name = "cut_wave"
    doc = "the settled impact wave, cut and placed: paper Section 2"
    keys = (CENTER, Key("half_width", "integer", 40, "grains kept on each side of the peak",
                        low=30, low_open=False), V0)
    placed = True

    def check(self, spec, chain):
        """``center`` inside by ``half_width``; a settled Hertz wave of a uniform chain."""
        super().check(spec, chain)
        if chain.exponent != 1.5:
            raise ScenarioError(f"[initial] kind = 'cut_wave' is a settled Hertz wave; "
                                f"[chain] exponent = {chain.exponent!r} needs another kind "
                                "(e.g. 'impact' or 'exact_wave')")
        if chain.gravity > 0:
            raise ScenarioError("[initial] kind = 'cut_wave' needs a uniform precompression; "
                                "with [chain] gravity > 0 use kind = 'impact'")

    def margin(self, spec):
        """``half_width``."""
        return spec.half_width

    def amplitude_key(self, spec):
        """``v0`` (of the impact that is settled)."""
        return "v0"

    def build(self, spec, chain_spec, chain, *, cache_dir=None):
        """:func:`discrete.initial.cut_wave`, its settled wave cached in ``cache_dir``."""
        from discrete.initial import cut_wave

        from .cache import remove_stale_temporaries

        if cache_dir is not None:  # a killed cache write's temporary
            remove_stale_temporaries(cache_dir)
        return cut_wave(chain, spec.center, v0=spec.v0, half_width=spec.half_width,
                        cache_dir=cache_dir)

    def amplitude_state(self, spec, chain, init=None):
        """Checked before settling: the impact at ``v0`` (cheap)."""
        return Impact().amplitude_state(spec, chain, init)

    def incident_velocity(self, init):
        """The settled wave's peak velocity as measured when it was cut."""
        params = init.params or {}
        return float(params["v_peak"]) if "v_peak" in params else \
            super().incident_velocity(init)


class ExactWave(InitialKind):
    """The exact discrete solitary wave of the chain's law (docs/physics.md §7)."""

    name = "exact_wave"
    doc = "the exact discrete solitary wave, docs/physics.md §7"
    keys = (CENTER, Key("velocity_max", "number", None, "peak grain velocity", "m/s", low=0),
            Key("strain_max", "number", None, "instead of velocity_max: peak dynamic "
                "overlap (r - δ0)/d", low=0))
    placed = True

    def check(self, spec, chain):
        """``center`` inside; exactly one amplitude; a uniform precompression."""
        super().check(spec, chain)
        if (spec.velocity_max is None) == (spec.strain_max is None):
            raise ScenarioError("[initial] give exactly one of velocity_max (m/s, > 0) or "
                                "strain_max (> 0) for kind = 'exact_wave'")
        if chain.gravity > 0:
            raise ScenarioError("[initial] kind = 'exact_wave' needs a uniform "
                                "precompression; with [chain] gravity > 0 use kind = 'impact'")

    def amplitude_key(self, spec):
        """``velocity_max`` or ``strain_max``, whichever is given."""
        return "velocity_max" if spec.strain_max is None else "strain_max"

    def build(self, spec, chain_spec, chain, *, cache_dir=None):
        """:func:`discrete.initial.exact_wave` for the chain's law."""
        from discrete.initial import exact_wave

        return exact_wave(chain, spec.center, velocity_max=spec.velocity_max,
                          strain_max=spec.strain_max, law=chain_spec.contact_law())

    def incident_velocity(self, init):
        """The exact wave's own peak velocity."""
        return float(init.params["velocity_max"])


INITIAL_KINDS: dict[str, InitialKind] = {}
"""The registered kinds by name (``[initial] kind``)."""


def register_initial_kind(kind: InitialKind) -> InitialKind:
    """Register ``kind`` (an :class:`InitialKind` instance) under its ``name``.

    ValueError unless it has a non-empty ``name``, a tuple of
    :class:`~hertzchain.scenario.Key` whose names are not ``kind`` and, where another
    kind has a key of the same name, the same key; a placed kind must have ``center``;
    another kind may not hold the name.
    """
    if not isinstance(kind, InitialKind):
        raise ValueError(f"an initial kind must be an InitialKind instance (got {kind!r})")
    if not isinstance(kind.name, str) or not kind.name:
        raise ValueError(f"{type(kind).__name__}.name must be a non-empty string")
    if not (isinstance(kind.keys, tuple) and all(isinstance(k, Key) for k in kind.keys)):
        raise ValueError(f"{type(kind).__name__}.keys must be a tuple of "
                         "hertzchain.scenario.Key")
    names = [k.name for k in kind.keys]
    if "kind" in names or len(set(names)) != len(names):
        raise ValueError(f"{type(kind).__name__}.keys: names must be distinct and not "
                         f"'kind' (got {names})")
    if kind.placed and "center" not in names:
        raise ValueError(f"{type(kind).__name__} is placed: it needs the key 'center'")
    if kind.interpolation not in ("smooth", "grains"):
        raise ValueError(f"{type(kind).__name__}.interpolation must be 'smooth' or 'grains'")
    known = {k.name: k for other in INITIAL_KINDS.values() if other.name != kind.name
             for k in other.keys}
    for k in kind.keys:
        if k.name in known and known[k.name] != k:
            raise ValueError(f"[initial] {k.name} is a key of another kind with another "
                             "definition: share the same Key")
    held = INITIAL_KINDS.get(kind.name)
    if held is not None and type(held) is not type(kind):
        raise ValueError(f"initial kind name {kind.name!r} is taken by "
                         f"{type(held).__qualname__}")
    INITIAL_KINDS[kind.name] = kind
    return kind


def initial_kind(name: str) -> InitialKind:
    """The registered kind ``name`` (ValueError naming the registered ones otherwise)."""
    try:
        return INITIAL_KINDS[name]
    except KeyError:
        raise ValueError(f"unknown initial kind {name!r}; registered: "
                         f"{', '.join(INITIAL_KINDS)}") from None


def initial_keys() -> tuple[Key, ...]:
    """``[initial] kind`` and the keys of every registered kind, in registration order.

    A key's help names the kinds that read it (``"cut_wave, exact_wave: grain of the
    wave's peak"``).
    """
    kinds = ", ".join(f"\"{k.name}\" ({k.doc})" for k in INITIAL_KINDS.values())
    out: dict[str, Key] = {"kind": Key("kind", "choice", "impact", kinds,
                                       choices=tuple(INITIAL_KINDS), example="cut_wave")}
    users: dict[str, list[str]] = {}
    for kind in INITIAL_KINDS.values():
        for key in kind.keys:
            users.setdefault(key.name, []).append(kind.name)
            out.setdefault(key.name, key)
    for name, who in users.items():
        k = out[name]
        out[name] = Key(k.name, k.kind, k.default, f"{', '.join(who)}: {k.doc}", k.unit,
                        k.low, k.high, k.low_open, k.high_open, k.choices, k.required,
                        k.example)
    return tuple(out.values())


for _kind in (Impact(), CutWave(), ExactWave()):
    register_initial_kind(_kind)
