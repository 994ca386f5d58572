"""What a run records, and the recorded data (paper Figs. 2, 3, 5, 8).

:class:`Recording` says what to record; :class:`Record` holds what was recorded.  Events:

* :class:`AtTime` — time t (s), taken at the first step with t_n >= t;
* :class:`WaveAt` — the centre of the leading wave reaches grain g: the grain's velocity
  has reached its running maximum above ``threshold`` (m/s) and has just started to
  decrease (tested after every step inside the kernel; the snapshot is taken one step
  later, which closes the velocity-Verlet step sequence, i.e. two steps after the
  sampled velocity peak).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["AtTime", "WaveAt", "Event", "Recording", "Record", "EnergyGrid", "Snapshot",
           "event_to_dict", "event_from_dict"]


@dataclass(frozen=True)
class AtTime:
    """Event: time ``t`` (s) is reached."""

    t: float

    @property
    def label(self) -> str:
        """A short name."""
        return f"t={self.t:.6g}"


@dataclass(frozen=True)
class WaveAt:
    """Event: the velocity peak of the leading wave has just passed grain ``grain``.

    ``threshold`` (m/s): the peak must exceed it; default (None) is 1 % of the largest
    grain speed of the initial state.
    """

    grain: int
    threshold: float | None = None

    @property
    def label(self) -> str:
        """A short name."""
        return f"wave_at={self.grain}"


Event = AtTime | WaveAt


@dataclass
class Recording:
    """What a :class:`~discrete.simulation.Simulation` records.

    Parameters
    ----------
    snapshots : sequence of AtTime / WaveAt / float / int
        Events at which all grains (u, v, overlaps) are stored; a float is a time (s),
        an int a grain index (:class:`WaveAt`).
    series_grains : sequence of int
        Grains whose u, v and the overlaps of their two contacts are recorded (Fig. 3c/d).
    series_every : int
        Steps between time-series samples.
    maxima : bool
        Keep per-grain running maxima of v and u (Fig. 2).
    energy_every : int or None
        Steps between rows of the per-grain energy space–time grid (Fig. 8); None: off.
    energy_coarsen : int
        Sum the energy grid over blocks of this many grains.
    monitor_every : int
        Steps between evaluations of the total energy (drift monitor).
    sensors : sequence of int
        Grains read as embedded force sensors (the mean of their two contact forces, N),
        sampled with the series (every ``series_every`` steps).
    wall_forces : bool
        Record the force on each wall (N), sampled with the series.
    strain_maxima : bool
        Keep the running maximum of every contact's overlap (needs ``maxima``); the
        strain maxima are (max overlap - δ0)/d.
    refined_maxima : bool or None
        Also keep the *refined* running maxima of v, between the steps
        (:attr:`Record.vmax_refined`; needs ``maxima``).  None (default): with a time step
        chosen for ``rtol`` (whose accuracy statement is about them), not otherwise —
        they cost the recording kernel a per-step test of every grain and a Hermite
        search for every grain whose maximum rises (about half the kernel's rate on a
        random-velocity chain, where ~1 % of the grains rise at every step; a few per
        cent in a wave, where only the front rises; docs/benchmarks.md).  Positions-only
        forces: with a dissipative law or drag the stored acceleration is the elastic
        one, not dv/dt, so :class:`discrete.Simulation` refuses True and None means
        False there.
    """

    snapshots: Sequence[AtTime | WaveAt | float | int] = ()
    series_grains: Sequence[int] = ()
    series_every: int = 1
    maxima: bool = True
    energy_every: int | None = None
    energy_coarsen: int = 1
    monitor_every: int = 10_000
    sensors: Sequence[int] = ()
    wall_forces: bool = False
    strain_maxima: bool = False
    refined_maxima: bool | None = None

    def events(self) -> list[Event]:
        """The snapshot events as :class:`AtTime` / :class:`WaveAt` objects."""
        return [as_event(e) for e in self.snapshots]

    def to_dict(self) -> dict:
        """JSON-able description (:meth:`from_dict` reads it back)."""
        return {"snapshots": [event_to_dict(e) for e in self.events()],
                "series_grains": [int(g) for g in self.series_grains],
                "series_every": int(self.series_every), "maxima": bool(self.maxima),
                "energy_every": None if self.energy_every is None else int(self.energy_every),
                "energy_coarsen": int(self.energy_coarsen),
                "monitor_every": int(self.monitor_every),
                "sensors": [int(g) for g in self.sensors],
                "wall_forces": bool(self.wall_forces),
                "strain_maxima": bool(self.strain_maxima),
                "refined_maxima": (None if self.refined_maxima is None
                                   else bool(self.refined_maxima))}

    @classmethod
    def from_dict(cls, d: dict) -> Recording:
        """The recording :meth:`to_dict` described."""
        return cls(snapshots=[event_from_dict(e) for e in d["snapshots"]],
                   series_grains=d["series_grains"], series_every=d["series_every"],
                   maxima=d["maxima"], energy_every=d["energy_every"],
                   energy_coarsen=d["energy_coarsen"], monitor_every=d["monitor_every"],
                   sensors=d.get("sensors", ()), wall_forces=d.get("wall_forces", False),
                   strain_maxima=d.get("strain_maxima", False),
                   refined_maxima=d.get("refined_maxima"))

    def validate(self, n: int) -> None:
        """Raise ValueError for anything that cannot work on a chain of ``n`` grains."""
        for e in self.events():
            check_event(e, n)
        for g in self.series_grains:
            if not 0 <= int(g) < n:
                raise ValueError(f"series grain {g} outside the chain [0, {n})")
        for g in self.sensors:
            if int(g) != g or not 0 <= int(g) < n:
                raise ValueError(f"sensor grain {g!r} outside the chain [0, {n})")
        if self.strain_maxima and not self.maxima:
            raise ValueError("strain_maxima needs maxima=True (the running maxima)")
        if self.refined_maxima not in (None, True, False):
            raise ValueError(f"refined_maxima must be None, True or False "
                             f"(got {self.refined_maxima!r})")
        if self.refined_maxima and not self.maxima:
            raise ValueError("refined_maxima needs maxima=True (the running maxima)")
        for name in ("series_every", "monitor_every", "energy_coarsen"):
            val = getattr(self, name)
            if int(val) != val or val < 1:
                raise ValueError(f"{name} must be an integer >= 1 (got {val!r})")
        if self.energy_every is not None and (int(self.energy_every) != self.energy_every
                                              or self.energy_every < 1):
            raise ValueError(f"energy_every must be None or an integer >= 1 "
                             f"(got {self.energy_every!r})")


def as_event(e) -> Event:
    """Turn a float (time, s) or int (grain) into an event object."""
    if isinstance(e, AtTime | WaveAt):
        return e
    if isinstance(e, bool):
        raise ValueError(f"not an event: {e!r}")
    if isinstance(e, int | np.integer):
        return WaveAt(int(e))
    if isinstance(e, float | np.floating):
        return AtTime(float(e))
    raise ValueError(f"not an event: {e!r} (use AtTime(t), WaveAt(grain), a float or an int)")


def event_to_dict(e: Event) -> dict:
    """JSON-able description of an event: its type and fields."""
    return {"type": type(e).__name__, **dataclasses.asdict(e)}


def event_from_dict(d: dict) -> Event:
    """The event :func:`event_to_dict` described (ValueError for an unknown type)."""
    d = dict(d)
    kind = d.pop("type", None)
    if kind not in ("AtTime", "WaveAt"):
        raise ValueError(f"unknown event type {kind!r}")
    return AtTime(**d) if kind == "AtTime" else WaveAt(**d)


def check_event(e: Event, n: int) -> None:
    """Raise ValueError if the event can never happen on a chain of ``n`` grains."""
    if isinstance(e, WaveAt):
        if not 0 <= e.grain < n:
            raise ValueError(f"WaveAt grain {e.grain} outside the chain [0, {n}): "
                             "the event can never happen")
        if e.threshold is not None and not (np.isfinite(e.threshold) and e.threshold > 0):
            raise ValueError(f"WaveAt threshold must be finite and > 0 (got {e.threshold!r})")
    elif isinstance(e, AtTime):
        if not np.isfinite(e.t):
            raise ValueError(f"AtTime t must be finite (got {e.t!r})")


@dataclass
class Snapshot:
    """All grains at one instant: u (m), v (m/s), overlaps (N+1,) (m)."""

    label: str
    t: float
    step: int
    u: np.ndarray
    v: np.ndarray
    overlaps: np.ndarray


@dataclass
class Record:
    """Data recorded by a run (appended to over successive ``run`` calls).

    Attributes
    ----------
    snapshots : list of Snapshot
    series_grains : (S,) int array
    series_t : (R,) array, s
    series : (R, S, 4) array
        u (m), v (m/s), left- and right-contact overlap (m) of each series grain.
    vmax, umax : (N,) arrays or None
        Running maxima of v (m/s) and u (m) since the start: the largest *sampled*
        values (at the steps; v̄max's of paper Fig. 2 as the figures read them).
    vmax_refined, vmax_time : (N,) arrays or None
        Refined running maxima of v (m/s), taken between the steps on the cubic Hermite
        interpolant of (v, a) (:mod:`discrete.interpolation`, :mod:`discrete.kernels`
        "Refined maxima"): they converge at the integrator's order, where ``vmax`` is
        O(h²) off; ``vmax_refined >= vmax``.  ``vmax_time``: the time each was
        reached, s.  None unless recorded (``Recording.refined_maxima``; by default in
        rtol runs) and in files of older versions.
    peak_state : (PEAK_ROWS, N) array or None
        The kernels' per-grain peak state behind ``vmax_refined`` (carried so that a
        continued run is bit for bit the uninterrupted one).
    energy : EnergyGrid
        The per-grain (or per-block of ``energy_coarsen`` grains) energy grid (Fig. 8),
        the one owner of its storage; read it as ``energy_t`` (T,) in s and
        ``energy_kinetic``, ``energy_potential`` (T, Nc) in J (read-only arrays,
        :meth:`energy_grids`).
    monitor_t, monitor_energy, monitor_shadow, monitor_dissipated : (M,) arrays
        Total energy (J), velocity Verlet's modified energy (J) and the energy
        dissipated since the start (J; 0 for conservative forces) at monitor times (s).
    sensor_grains : (S',) int array
    sensor_force : (R, S') array
        Embedded-sensor readings (mean of the two contact forces, N) at ``series_t``.
    wall_forces : bool
    wall_force : (R, 2) array
        Force on the left and right wall, N, at ``series_t`` (when ``wall_forces``).
    overlap_max : (N+1,) array or None
        Running maximum of every contact's overlap, m.
    """

    series_grains: np.ndarray
    snapshots: list[Snapshot] = field(default_factory=list)
    series_t: list = field(default_factory=list)
    series: list = field(default_factory=list)
    vmax: np.ndarray | None = None
    umax: np.ndarray | None = None
    energy: EnergyGrid = field(default_factory=lambda: EnergyGrid())
    energy_coarsen: int = 1
    monitor_t: list = field(default_factory=list)
    monitor_energy: list = field(default_factory=list)
    monitor_shadow: list = field(default_factory=list)
    monitor_dissipated: list = field(default_factory=list)
    sensor_grains: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    sensor_force: list = field(default_factory=list)
    wall_forces: bool = False
    wall_force: list = field(default_factory=list)
    overlap_max: np.ndarray | None = None
    vmax_refined: np.ndarray | None = None
    vmax_time: np.ndarray | None = None
    peak_state: np.ndarray | None = None

    _MONITOR = ("monitor_t", "monitor_energy", "monitor_shadow", "monitor_dissipated")

    def drop_monitor_sample_at(self, t: float) -> bool:
        """Drop the last monitor sample if it was taken at time ``t`` (s); True if dropped.

        (:meth:`Simulation.run <discrete.Simulation.run>` takes a sample when it returns
        and another when it starts: a run cut into segments drops the first of the two to
        stay bit for bit the uninterrupted run, ``hertzchain.checkpoint``.)
        """
        if not self.monitor_t or self.monitor_t[-1] != t:
            return False
        for name in self._MONITOR:
            getattr(self, name).pop()
        return True

    def check(self, n: int, recording: Recording) -> None:
        """ValueError if the record cannot belong to a chain of ``n`` grains recorded so."""
        a = self.arrays()
        if (len(self.series_t) != a["series"].shape[0]
                or (self.sensor_grains.size and a["sensor_force"].shape
                    != (len(self.series_t), self.sensor_grains.size))
                or (self.wall_forces and a["wall_force"].shape[0] != len(self.series_t))
                or not self.energy.consistent()
                or len({len(getattr(self, name)) for name in self._MONITOR}) != 1):
            raise ValueError("record arrays of inconsistent lengths")
        cols = -(-n // int(self.energy_coarsen))
        if len(self.energy) and self.energy.columns != cols:
            raise ValueError(f"record/energy_kinetic and record/energy_potential must have "
                             f"ceil(n / energy_coarsen) = {cols} columns (n {n}, "
                             f"energy_coarsen {self.energy_coarsen}; got "
                             f"{self.energy.columns})")
        if recording.strain_maxima and (self.overlap_max is None
                                        or self.overlap_max.shape != (n + 1,)):
            raise ValueError(f"record/overlap_max must have shape ({n + 1},)")
        if recording.maxima or self.vmax is not None:
            if self.vmax is None or self.umax is None or self.vmax.shape != (n,) \
                    or self.umax.shape != (n,):
                raise ValueError(f"record/vmax and record/umax must have shape ({n},)")
        refined = (self.vmax_refined, self.vmax_time, self.peak_state)
        if recording.refined_maxima and self.vmax_refined is None:
            raise ValueError("record/vmax_refined missing (the recording keeps refined "
                             "maxima)")
        if any(x is not None for x in refined):
            from .kernels import PEAK_ROWS

            if (self.vmax is None or any(x is None for x in refined)
                    or self.vmax_refined.shape != (n,) or self.vmax_time.shape != (n,)
                    or self.peak_state.shape != (PEAK_ROWS, n)):
                raise ValueError(f"record/vmax_refined, vmax_time ({n},) and peak_state "
                                 f"({PEAK_ROWS}, {n}) must come together, with vmax")
            if not np.all(self.vmax_refined >= self.vmax):
                raise ValueError("record/vmax_refined must be >= record/vmax everywhere "
                                 "(the refined maximum includes the samples)")

    def arrays(self) -> dict[str, np.ndarray]:
        """The list-valued fields as stacked arrays.

        New arrays, except the energy grids: read-only views of the record's own grid
        (:meth:`energy_grids`; a copy here would make ``discrete.save`` of a summarised
        run hold both grids twice).
        """
        s = len(self.series_grains)
        energy_t, ek, ep = self.energy_grids()
        return {
            "series_grains": np.asarray(self.series_grains, dtype=np.int64),
            "series_t": np.asarray(self.series_t, dtype=float),
            "series": (np.concatenate(self.series, axis=0) if self.series
                       else np.zeros((0, s, 4))),
            "energy_t": energy_t, "energy_kinetic": ek, "energy_potential": ep,
            "monitor_t": np.asarray(self.monitor_t, dtype=float),
            "monitor_energy": np.asarray(self.monitor_energy, dtype=float),
            "monitor_shadow": np.asarray(self.monitor_shadow, dtype=float),
            "monitor_dissipated": np.asarray(self.monitor_dissipated, dtype=float),
            "sensor_grains": np.asarray(self.sensor_grains, dtype=np.int64),
            "sensor_force": (np.concatenate(self.sensor_force, axis=0) if self.sensor_force
                             else np.zeros((0, len(self.sensor_grains)))),
            "wall_force": (np.concatenate(self.wall_force, axis=0) if self.wall_force
                           else np.zeros((0, 2))),
        }

    def energy_grids(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The energy grid (``energy_t``, ``energy_kinetic``, ``energy_potential``), no copy.

        ``energy_t`` (T,) in s, the two kinds (T, Nc) in J, the values of :meth:`arrays`
        (float64, bit for bit): read-only views of :attr:`energy`'s storage
        (:meth:`EnergyGrid.grids`).
        """
        return self.energy.grids()

    @property
    def energy_t(self) -> np.ndarray:
        """Times of the energy-grid rows, (T,) s (read-only, :meth:`energy_grids`)."""
        return self.energy.grids()[0]

    @property
    def energy_kinetic(self) -> np.ndarray:
        """Kinetic energy grid ½mv² per grain or block, (T, Nc) J (read-only view)."""
        return self.energy.grids()[1]

    @property
    def energy_potential(self) -> np.ndarray:
        """Potential (contact) energy grid per grain or block, (T, Nc) J (read-only view)."""
        return self.energy.grids()[2]

    def snapshot(self, label: str) -> Snapshot:
        """The first snapshot with this label (e.g. ``"wave_at=550"``)."""
        for s in self.snapshots:
            if s.label == label:
                return s
        raise KeyError(f"no snapshot {label!r}; have {[s.label for s in self.snapshots]}")


RESERVE_MAX_BYTES = 64 * 2**20
"""Largest storage (bytes per kind) :meth:`EnergyGrid.reserve` sets aside at once.

Reserved rows that are never written cost address space only (NumPy's ``empty``: pages
are given memory when first written; glibc maps an allocation of this size on its own),
but an unbounded ``t_end`` must not ask for an unbounded block; past it the storage
grows by segments (joined on the first read)."""

SMALL_MOVE_BYTES = 2**20
"""Rows already recorded (bytes per kind) that :meth:`EnergyGrid.reserve` moves into a
new segment rather than leave in a segment of their own (the row a
``discrete.Simulation`` takes at its start, before the run's reservation: else every
read would join two segments, i.e. copy the grid)."""


class EnergyGrid:
    """The energy space–time grid of a run (Fig. 8): the one owner of its storage.

    Storage: segments of (capacity, Nc) float64 C-contiguous arrays, one per kind
    (kinetic ½mv² and potential, the contact energies, J; docs/physics.md §6), and the
    row times (s).  A run reserves the rows it can take (:meth:`reserve`, from its
    ``t_end``), and the kernel writes each chunk's rows straight into the next rows of
    the storage (:meth:`block`, :meth:`commit`): no copy, and the grid is read
    (:meth:`grids`) as views of the filled rows.  Rows past the reservation (a run
    bounded by an event only) go to new segments (doubling), joined once on the first
    read, each segment freed as soon as it is copied.  So the process holds the grid
    itself (two kinds, kinetic and potential) and no stacked copy beside it.
    """

    def __init__(self) -> None:
        self._t: list[np.ndarray] = []  # per segment: (capacity,) times, s
        self._k: list[np.ndarray] = []  # per segment: (capacity, Nc) kinetic, J
        self._p: list[np.ndarray] = []  # per segment: (capacity, Nc) potential, J
        self._fill: list[int] = []  # rows written per segment
        self._open: int | None = None  # rows of the block handed out, not yet committed
        self._open_seg: np.ndarray | None = None  # the kinetic segment that block is in

    def __len__(self) -> int:
        """The number of rows T."""
        return sum(self._fill)

    @property
    def columns(self) -> int | None:
        """Nc, the grid's width (None before the first segment)."""
        return self._k[0].shape[1] if self._k else None

    def consistent(self) -> bool:
        """True if every segment has one width and its times and kinds as many rows."""
        return (len({b.shape[1] for b in self._k + self._p}) <= 1
                and all(len(t) >= f and k.shape[0] >= f and p.shape == k.shape
                        for t, k, p, f in zip(self._t, self._k, self._p, self._fill,
                                              strict=True)))

    def _check_closed(self, what: str) -> None:
        """RuntimeError if a block is handed out and not committed.

        (Its rows are the storage's next rows: any other change would move or overwrite
        them.)
        """
        if self._open is not None:
            raise RuntimeError(f"EnergyGrid.{what}: a block of {self._open} rows is open "
                               "(block); commit it first")

    def _check_cols(self, cols: int) -> None:
        if self._k and cols != self.columns:
            raise ValueError(f"cols must be the grid's columns {self.columns} (got {cols})")

    def reserve(self, rows: int, cols: int, at_least: int = 0) -> None:
        """Make room for ``rows`` more rows of ``cols`` columns.

        ``rows`` capped at :data:`RESERVE_MAX_BYTES` per kind, but at least ``at_least``.
        A new segment if the last has less room; rows already recorded, if few
        (:data:`SMALL_MOVE_BYTES`), are moved into it.
        """
        if (int(rows) != rows or rows < 0 or int(cols) != cols or cols < 1
                or int(at_least) != at_least or at_least < 0):
            raise ValueError(f"rows and at_least must be integers >= 0 and cols >= 1 (got "
                             f"{rows!r}, {at_least!r}, {cols!r})")
        self._check_closed("reserve")
        self._check_cols(cols)
        rows = max(int(min(rows, RESERVE_MAX_BYTES // (8 * cols))), int(at_least))
        if self._k and self._k[-1].shape[0] - self._fill[-1] >= rows:
            return
        n = len(self)
        move = n * cols * 8 <= SMALL_MOVE_BYTES
        cap = rows + (n if move else 0)
        t, k, p = np.empty(cap), np.empty((cap, cols)), np.empty((cap, cols))
        if move:
            if n:
                told, kold, pold = self.grids()
                t[:n], k[:n], p[:n] = told, kold, pold
            self._t, self._k, self._p, self._fill = [], [], [], []
        else:
            n = 0
        self._t.append(t)
        self._k.append(k)
        self._p.append(p)
        self._fill.append(n)

    def block(self, rows: int, cols: int) -> tuple[np.ndarray, np.ndarray]:
        """Views of the next ``rows`` rows of the storage (kinetic, potential), to be written.

        Uninitialised; :meth:`commit` then says how many were written (until then the
        grid refuses any other change, and a read).  Grows the storage (a new segment of
        at least the rows recorded so far: doubling) if needed.  ValueError for ``rows``
        not an integer >= 0.
        """
        if isinstance(rows, bool) or int(rows) != rows or rows < 0:
            raise ValueError(f"rows must be an integer >= 0 (got {rows!r})")
        rows = int(rows)
        self._check_closed("block")
        self._check_cols(cols)
        if not self._k or self._k[-1].shape[0] - self._fill[-1] < rows:
            self.reserve(max(rows, len(self)), cols, at_least=rows)
        f = self._fill[-1]
        self._open, self._open_seg = rows, self._k[-1]
        return self._k[-1][f:f + rows], self._p[-1][f:f + rows]

    def commit(self, t) -> None:
        """The rows just written into :meth:`block`'s views are taken, at times ``t`` (s).

        ValueError if no block is open, if ``t`` has more rows than the block, or if the
        storage is no longer the one the block was handed out from.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        if self._open is None:
            raise ValueError("t: no block is open (block hands out the rows to commit)")
        if not self._k or self._k[-1] is not self._open_seg:
            raise ValueError("commit: the storage changed since block handed out its rows")
        if t.size > self._open:
            raise ValueError(f"t: {t.size} rows, more than the block handed out "
                             f"({self._open} rows, block)")
        self._open = self._open_seg = None
        f = self._fill[-1]
        self._t[-1][f:f + t.size] = t
        self._fill[-1] = f + t.size

    def extend(self, t, kinetic: np.ndarray, potential: np.ndarray) -> None:
        """Append rows: times ``t`` (R,) s and the (R, Nc) kinds, J, kept as a segment.

        C-contiguous kinds (``discrete.io.load``'s arrays) are kept themselves, no copy;
        others are copied into C order (``np.ascontiguousarray``: the segments are
        C-contiguous, as the kernel's blocks).  ValueError for shapes that do not fit
        (naming the parameter).
        """
        self._check_closed("extend")
        t = np.asarray(t, dtype=float).reshape(-1)
        for name, b in (("kinetic", kinetic), ("potential", potential)):
            if not (isinstance(b, np.ndarray) and b.ndim == 2 and b.dtype == np.float64
                    and b.shape[0] == t.size):
                raise ValueError(f"{name} must be a float64 ({t.size}, Nc) array (got "
                                 f"{getattr(b, 'dtype', type(b))} {np.shape(b)})")
        if kinetic.shape != potential.shape or (self._k and kinetic.shape[1] != self.columns):
            raise ValueError(f"potential {potential.shape} must have the shape of kinetic "
                             f"{kinetic.shape} and the grid's columns")
        if not t.size:
            return
        self._t.append(t)
        for segs, b in ((self._k, kinetic), (self._p, potential)):
            segs.append(b if b.flags.c_contiguous else np.ascontiguousarray(b))
        self._fill.append(t.size)

    def append(self, t: float, kinetic: np.ndarray, potential: np.ndarray) -> None:
        """Append one row (copied into the storage): time ``t`` (s), the (Nc,) kinds (J).

        ValueError unless ``kinetic`` and ``potential`` are 1-D of one length (the grid's
        columns once it has some).
        """
        self._check_closed("append")
        if np.ndim(kinetic) != 1 or np.shape(potential) != np.shape(kinetic):
            raise ValueError(f"kinetic and potential must be 1-D arrays of one length (got "
                             f"shapes {np.shape(kinetic)}, {np.shape(potential)})")
        k, p = self.block(1, np.shape(kinetic)[0])
        k[0], p[0] = kinetic, potential
        self.commit([t])

    def grids(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t (T,) s, kinetic (T, Nc) J, potential (T, Nc) J), read-only views.

        Views of the filled rows of the storage; segments are joined into one on the
        first read after rows went to a second segment (each segment freed as it is
        copied, unless someone else holds it).  The values are those of the rows
        recorded, bit for bit.  RuntimeError while a block is open (its rows are not
        yet written: :meth:`commit`).
        """
        self._check_closed("grids")
        if len(self._k) > 1:
            n = len(self)
            for name in ("_t", "_k", "_p"):
                segs = getattr(self, name)
                out = np.empty((n, *segs[0].shape[1:]))
                i = 0
                for f in self._fill:
                    b = segs.pop(0)
                    out[i:i + f] = b[:f]
                    i += f
                    del b
                segs.append(out)
            self._fill = [n]
        if not self._k:
            out = [np.zeros(0), np.zeros((0, 0)), np.zeros((0, 0))]
        else:
            f = self._fill[0]
            out = [self._t[0][:f], self._k[0][:f], self._p[0][:f]]
        views = []
        for g in out:
            g = g.view()
            g.flags.writeable = False  # (a write raises instead of changing the record)
            views.append(g)
        return tuple(views)
