"""Output of a :class:`hertzchain.compare.Comparison`: one HDF5 file, figures, a report.

``compare.h5`` (written to a temporary name and renamed, sealed by
:func:`theory.integrity.sealed_hdf5` and verified on reading; attribute ``format`` =
:data:`FORMAT`) holds

* root attributes ``scenario`` (JSON), ``comparison`` (JSON: every number of
  :meth:`Comparison.to_dict`, the differences, the errors, the verdict) and ``units``;
* a group per sampled model (``discrete``, ``continuum``): ``t`` (the common sample
  times, s), ``energy/<kind>_<side>`` and ``fronts/<wave>``, ``peaks/<wave>`` over
  them, and the profiles shown in the figures, ``display_t``, ``v`` and ``strain`` (one
  row per display time); attributes ``label``, ``completed``, ``stopped_by``,
  ``summary`` and ``params`` (JSON) and ``run_file`` (the cached run with every sample);
* ``theory``: ``t``, ``fronts/<wave>``, ``partition/left|right`` and the attribute
  ``prediction`` (JSON);
* ``comparison``: ``display_t`` and the attributes ``differences``, ``errors``,
  ``verdict``.

Figures (PNG, each panel drawn by a :mod:`hertzchain.plotting` function on its own
``ax``): ``profiles.png`` (velocity profiles of every model at the display times,
differences to the discrete chain below), ``fronts.png`` (front trajectories beside
the theory's), ``energy.png`` (energy partition over time beside the linear-acoustic
prediction).  ``report.md`` / ``report.html``: the scenario, the verdict, the table of
differences and the figures.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from theory import integrity

from .cache import atomic_path, canonical_json
from .report import Report

__all__ = ["FORMAT", "write_all", "write_hdf5", "save_figures", "write_report", "difference_rows",
           "run_rows", "train_rows", "scenario_rows", "summary_rows", "run_html",
           "comparison_html"]

FORMAT = "hertzchain.compare/1"
"""The ``format`` attribute of ``compare.h5`` (:func:`hertzchain.compare.load` checks it)."""

_WAVES = ("incident", "transmitted", "reflected")


def _json(obj) -> str:
    from ._argtypes import jsonable

    return canonical_json(jsonable(obj))


def write_hdf5(cmp, path: Path) -> Path:
    """Write ``compare.h5`` (module docstring) atomically; return its path."""
    res = cmp.run
    with integrity.sealed_hdf5(path) as f:
        f.attrs["format"] = FORMAT
        f.attrs["scenario"] = canonical_json(cmp.scenario.to_dict())
        f.attrs["comparison"] = _json(cmp.to_dict())
        f.attrs["units"] = canonical_json({
            "t": "s", "display_t": "s", "v": "m/s", "strain": "m (overlap - static overlap)",
            "energy": "1 (over the incident energy of the same kind)",
            "fronts": "grain index (0-based)", "peaks": "m/s", "partition": "1"})
        for name, s in cmp.series.items():
            mrun = getattr(res, name)
            g = f.create_group(name)
            g.attrs["label"] = s.label
            g.attrs["completed"] = bool(s.completed)
            g.attrs["stopped_by"] = s.stopped_by
            g.attrs["summary"] = _json(mrun.summary)
            g.attrs["params"] = _json(mrun.params)
            g.attrs["speeds"] = _json(s.speeds)
            g.attrs["run_file"] = str(mrun.path or "")
            g.create_dataset("t", data=s.times)
            for grp, data in (("energy", s.energy), ("fronts", s.fronts), ("peaks", s.peaks)):
                h = g.create_group(grp)
                for key, arr in data.items():
                    h.create_dataset(key, data=np.asarray(arr, dtype=float))
            idx = [i for i in cmp.display if i < mrun.v.shape[0]]
            g.create_dataset("display_t", data=s.times[idx])
            for key, arr in (("v", mrun.v[idx]), ("strain", mrun.strain[idx])):
                g.create_dataset(key, data=arr, compression="gzip", fletcher32=True)
        if res.theory is not None:
            g = f.create_group("theory")
            g.attrs["prediction"] = _json(res.theory.to_dict())
            g.create_dataset("t", data=cmp.times)
            fr = res.theory.fronts(cmp.times)
            h = g.create_group("fronts")
            for key in _WAVES:
                h.create_dataset(key, data=fr[key])
            part = res.theory.partition(cmp.times)
            h = g.create_group("partition")
            for key, arr in part.items():
                h.create_dataset(key, data=arr)
        g = f.create_group("comparison")
        g.create_dataset("display_t", data=cmp.times[cmp.display])
        g.attrs["differences"] = _json(cmp.differences)
        g.attrs["errors"] = _json(cmp.errors)
        g.attrs["verdict"] = cmp.verdict()
    return path


def _new_figure(nrows: int, ncols: int, figsize):
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    return fig, fig.subplots(nrows, ncols, squeeze=False)


def _save(fig, path: Path) -> Path:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    return path


def save_figures(cmp, out: Path) -> list[tuple[Path, str]]:
    """Save ``profiles.png``, ``fronts.png`` and ``energy.png``; [(path, caption)]."""
    from .plotting import (
        plot_energy_partition,
        plot_fronts,
        plot_profile_difference,
        plot_profiles,
    )

    res = cmp.run
    v_ref = res.incident.velocity
    iface = res.interface
    disc = res.discrete if "discrete" in cmp.series else None
    figs = []
    cols = len(cmp.display)
    fig, axes = _new_figure(2 if disc is not None and len(cmp.series) > 1 else 1, cols,
                            (4.2 * cols, 6.2 if disc is not None else 3.4))
    for c, i in enumerate(cmp.display):
        t = float(cmp.times[i])
        profiles = {s.label: getattr(res, name).v[i] for name, s in cmp.series.items()}
        plot_profiles(axes[0, c], profiles, interface=iface, v_ref=v_ref,
                      title=f"t = {t * 1e3:.4g} ms")
        if axes.shape[0] > 1:
            diffs = {s.label: getattr(res, name).v[i] - disc.v[i]
                     for name, s in cmp.series.items() if name != "discrete"}
            plot_profile_difference(axes[1, c], diffs, interface=iface, v_ref=v_ref)
    figs.append((_save(fig, out / "profiles.png"),
                 "Grain velocity / incident peak velocity of every model at the display "
                 "times (before, during, after the interface; dotted: the interface); "
                 "below: model − discrete."))
    fig, axes = _new_figure(1, 1, (7.5, 4.6))
    th = res.theory
    # models other than the discrete chain: only up to the comparison time (ends)
    upto = {name: (slice(None) if name == "discrete" else slice(0, cmp.i_compare + 1))
            for name in cmp.series}
    plot_fronts(axes[0, 0], {s.label: (s.times[upto[n]],
                                       {w: x[upto[n]] for w, x in s.fronts.items()})
                             for n, s in cmp.series.items()},
                theory=None if th is None else (cmp.times, th.fronts(cmp.times)),
                theory_speeds=None if th is None else _theory_speeds(th),
                interface=iface)
    figs.append((_save(fig, out / "fronts.png"),
                 "Front trajectories (peak of the leading pulse of ½mv²) of the incident, "
                 "transmitted and reflected waves; lines: the theory (speeds in the "
                 "legend, m/s)."))
    if iface is not None:
        fig, axes = _new_figure(1, 1, (7.5, 4.6))
        plot_energy_partition(
            axes[0, 0], {s.label: (s.times[upto[n]], s.energy["total_left"][upto[n]],
                                   s.energy["total_right"][upto[n]])
                         for n, s in cmp.series.items()},
            theory=None if th is None else (cmp.times, th.partition(cmp.times)["left"],
                                            th.partition(cmp.times)["right"]),
            t_compare=cmp.t_compare)
        figs.append((_save(fig, out / "energy.png"),
                     "Total energy left (incident, then reflected) and right (transmitted) "
                     "of the interface over the incident energy; dashed: the linear-"
                     "acoustic prediction (Eqs. 9–13, theory.table2_prediction)."))
    return figs


def _theory_speeds(th) -> dict[str, float]:
    out = {"incident": th.speed_in}
    if th.has_interface:
        out.update(transmitted=th.speed_tr, reflected=th.speed_re)
    return out


def _num(x, fmt: str = ".5g") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—"
    return format(x, fmt) if isinstance(x, int | float) else str(x)


_ROWS = (
    ("Et_tr", "E_T / E_in, total", ".5f", ".1e"),
    ("Et_re", "E_R / E_in, total", ".5f", ".1e"),
    ("Ek_tr", "E_T / E_in, kinetic", ".5f", ".1e"),
    ("Ek_re", "E_R / E_in, kinetic", ".5f", ".1e"),
    ("Ep_tr", "E_T / E_in, potential", ".5f", ".1e"),
    ("Ep_re", "E_R / E_in, potential", ".5f", ".1e"),
    ("speed_incident", "incident front speed (m/s)", ".2f", "+.2%"),
    ("speed_transmitted", "transmitted front speed (m/s)", ".2f", "+.2%"),
    ("speed_reflected", "reflected front speed (m/s)", ".2f", "+.2%"),
    ("speed_transmitted_at_measured_amplitude",
     "transmitted speed at the measured amplitude (m/s)", ".2f", "+.2%"),
    ("speed_reflected_at_measured_amplitude",
     "reflected speed at the measured amplitude (m/s)", ".2f", "+.2%"),
    ("peak_transmitted", "leading transmitted peak v (m/s)", ".4g", "+.1e"),
    ("peak_reflected", "leading reflected peak v (m/s)", ".4g", "+.1e"),
    ("front_transmitted", "transmitted front at t_compare (grain)", ".2f", "+.2f"),
    ("front_reflected", "reflected front at t_compare (grain)", ".2f", "+.2f"),
    ("arrival_time", "arrival time of the transmitted front (s)", ".5g", "+.2e"),
    ("front_at_arrival", "transmitted front then (grain)", ".2f", "+.2f"),
    ("travel_time", "travel time of the leading wave in the window (s)", ".5g", "+.2%"),
    ("peak_velocity", "leading peak velocity at the window's end (m/s)", ".4g", "+.2%"),
    ("leading_peak", "leading peak velocity of the striker's train (m/s)", ".4g", "+.2%"),
    ("wave_count", "waves of the train above 5 % of the leading one", ".0f", "+.0f"),
    ("train_leading", "leading wave of the train: v_max of its energy's exact wave (m/s)",
     ".4g", "+.2%"),
)

_MODELS = ("continuum", "theory", "theory_strong")
"""The models compared with the discrete chain, in the order of the tables."""


def difference_rows(cmp) -> list[list[str]]:
    """Rows of the difference table: quantity, discrete, then value and Δ per model."""
    models = [m for m in _MODELS if m in cmp.differences]
    rows = []
    whole = cmp.run.interface is None
    for key, text, vfmt, dfmt in _ROWS:
        if whole and key[:2] in ("Et", "Ek", "Ep"):
            if key.endswith("_tr"):
                continue
            text = text.replace("E_R / E_in", "E (whole chain) / E_in")
        cells = [(cmp.differences[m].get(key)) for m in models]
        if all(c is None for c in cells):
            continue
        disc = next((c[0] for c in cells if c is not None), None)
        if key == "arrival_time" or key == "front_at_arrival":
            text = text.replace("transmitted front", f"transmitted front at "
                                f"{cmp.arrival_distance:.0f} grains past the interface")
        row = [text, _num(disc, vfmt)]
        for c in cells:
            row += ["—", "—"] if c is None else [_num(c[1], vfmt), _num(c[2], dfmt)]
        rows.append(row)
    for name, prof in cmp.profile_errors.items():
        for p in prof:
            rows.append([f"v at t = {p['t'] * 1e3:.4g} ms: L2 (relative) / L∞ (of the "
                         f"incident peak)", "—"]
                        + sum(([f"{p['l2']:.2e}", f"{p['linf']:.2e}"] if m == name
                               else ["—", "—"] for m in models), []))
    return rows


def run_rows(cmp) -> list[list[str]]:
    """Rows of the discrete run's own numbers: quantity, value, when/how it is measured."""
    disc = cmp.run.discrete
    if disc is None:
        return []
    s = disc.summary
    at = cmp.measured_at
    rows = []
    for key in ("Et_tr", "Et_re", "Ek_tr", "Ek_re", "Ep_tr", "Ep_re", "Ed"):
        if key in s:
            rows.append([key, _num(s[key], ".5f"), at["run_ratios"] or "—"])
    for key in ("front_speed_tr", "front_speed_re"):
        if key in s:
            rows.append([f"{key} (m/s)", _num(s[key], ".2f"),
                         s.get(f"{key}_note") or at["run_front_speeds"]])
    for key in ("transmitted", "reflected", "n_transmitted_pulses"):
        if key in s:
            rows.append([key, _num(s[key]), s.get("labels_note") or at["run_labels"]])
    if "incident_strain" in s:
        rows.append(["incident_strain (r − δ0)/d", _num(s["incident_strain"], ".4g"),
                     s.get("incident_strain_note") or "hertzchain.measure.incident_strain"])
    if "train_waves" in s:
        rows += train_rows(s)
    return rows


def train_rows(summary: dict) -> list[list[str]]:
    """The wave train of a run summary as rows: quantity, value, how it is measured.

    One row "none" (with ``train_note``) where no train was measured; else the count
    and, per wave (front first), its peak velocity, amplitude, speed and energy.
    """
    how = (f"solitary waves of the final state, t = {summary.get('t', math.nan):.6g} s "
           "(hertzchain.measure.wave_train): the exact lattice wave of each pulse's energy")
    count = summary.get("train_waves")
    if not count:
        return [["train_waves", "none", summary.get("train_note") or "not measured"]]
    rows = [["train_waves", str(count), how]]
    for j in range(count):
        vals = ", ".join(f"{label} {_num(summary[key][j], fmt)}" for key, label, fmt in (
            ("train_velocity_max", "v_max (m/s)", ".5g"),
            ("train_amplitude", "amplitude (m)", ".4g"),
            ("train_speed", "speed (m/s)", ".5g"),
            ("train_energy", "energy (J)", ".4g"),
            ("train_position", "at grain", ".2f")))
        rows.append([f"train wave {j + 1}", vals, "front first"])
    return rows


def write_report(cmp, out: Path, figs: list[tuple[Path, str]]) -> tuple[Path, Path]:
    """Write ``report.md`` and ``report.html``."""
    sc = cmp.scenario
    res = cmp.run
    rep = Report(f"Discrete, continuum and theory: {sc.name or 'scenario'}")
    secs = ", ".join(f"{s.n} grains (α_ρ = {s.alpha_rho:g}, α_kn = {s.alpha_kn:g})"
                     if s.material is None else f"{s.n} grains ({s.material})"
                     for s in sc.chain.sections)
    rep.paragraph(
        f"Chain: {secs}; δ0/d = {sc.chain.delta0_over_d:g}; initial state: "
        f"{sc.initial.kind}; incident peak velocity {res.incident.velocity:.4g} m/s, "
        f"strain {res.incident.strain:.3g}.  Models: "
        + ", ".join(s.label for s in cmp.series.values())
        + (", theory" if res.theory is not None else "")
        + f".  All start from the same grain state and are compared at "
          f"{cmp.times.size} common times; the comparison time is "
          f"t = {cmp.t_compare * 1e3:.4g} ms.")
    incomplete = [m for m in res.models if not m.completed]
    for m in incomplete:
        rep.paragraph(f"**The {m.name} model did not complete** ({m.stopped_by}): it is "
                      "not compared.")
    rep.heading("Verdict")
    rep.paragraph(cmp.verdict())
    if cmp.unverified:
        rep.paragraph(f"**Not verified to rtol**: the discrete run's "
                      f"{', '.join(cmp.unverified)} is false; `hertzchain compare` exits 4 "
                      "(docs/guide/exit_status.md).")
    if res.theory is not None or res.skipped:
        rep.heading("Models")
        lines = []
        if res.theory is not None:
            lines.append(f"Theory: {cmp.theory_label('theory').removeprefix('the ')}"
                         + (f" — window: {cmp.theory_window}" if cmp.theory_window else ""))
            if res.theory.strong is not None:
                lines.append(f"Interface: {cmp.theory_label('theory_strong')[4:]} "
                             "(theory.strong_interface.predict_strong; column "
                             "theory_strong)")
            for name in ("theory", "theory_strong"):
                if cmp.notes.get(name):
                    lines.append(f"Not compared ({name}): {cmp.notes[name]}")
        for m, why in res.skipped.items():
            lines.append(f"Not run: the {m} — {why}")
        for line in lines:
            rep.paragraph(line)
    models = [m for m in _MODELS if m in cmp.differences]
    if models:
        rep.heading("Differences to the discrete chain")
        header = ["quantity", "discrete at t_compare"]
        for m in models:
            header += [m, f"Δ {m}"]
        rep.table(header, difference_rows(cmp),
                  caption=f"Energy ratios, fronts and peaks at the comparison time "
                  f"t_compare = {cmp.t_compare * 1e3:.4g} ms (one common sample of every "
                  f"model); speeds fitted over the samples from t_cross = "
                  f"{cmp.t_cross * 1e3:.4g} ms to t_compare; Δ: model − discrete (speeds "
                  "relative); theory speeds at its predicted amplitudes and at the "
                  "discrete chain's measured ones; — : outside its measurement window "
                  "(why: the JSON's 'unmeasured')")
    rows = run_rows(cmp)
    if rows:
        rep.heading("The discrete run's own numbers")
        rep.table(["quantity", "value", "measured"], rows,
                  caption="The discrete run's summary (hertzchain run), each in its own "
                  "window (hertzchain.measure): the same names, other times than "
                  "t_compare")
    for path, caption in figs:
        rep.figure(path, caption)  # (a path as save_figures returned it)
    return rep.write(out)


def write_all(cmp, out: Path, *, figures: bool = True, report: bool = True
              ) -> dict[str, Any]:
    """Write everything into ``out``; return the paths."""
    out.mkdir(parents=True, exist_ok=True)
    paths: dict[str, Any] = {"hdf5": write_hdf5(cmp, out / "compare.h5")}
    figs = save_figures(cmp, out) if figures else []
    paths["figures"] = [p for p, _ in figs]
    if report:
        paths["report"] = list(write_report(cmp, out, figs))
    return paths


# -- Jupyter display ------------------------------------------------------------------
def scenario_rows(scenario) -> list[tuple[str, Any, str]]:
    """(key, value, unit) of every scenario key that differs from its default.

    Keys as in the TOML file (``chain.delta0_over_d``, ``chain.sections.0.n``), units
    from the scenario schema (:data:`hertzchain.scenario.SCHEMA`).
    """
    from .scenario import SCHEMA

    d = scenario.to_dict()
    rows: list[tuple[str, Any, str]] = []
    if d.get("name"):
        rows.append(("name", d["name"], ""))

    def table(prefix: str, schema: str, values: dict) -> None:
        for key in SCHEMA[schema]:
            if key.name not in values:
                continue
            value = values[key.name]
            default = key.default
            if value == default or value is None or (value == [] and not default) or (
                    key.name == "seed" and not any(values.get(f"disorder_{q}") for q in
                                                   ("mass", "stiffness", "diameter"))):
                continue
            rows.append((f"{prefix}{key.name}", value, key.unit))

    for name in ("chain", "initial", "run"):
        table(f"{name}.", name, d.get(name, {}))
        if name == "chain":
            for i, sec in enumerate(d["chain"].get("sections", [])):
                table(f"chain.sections.{i}.", "chain.sections", sec)
    rows.append(("models", ", ".join(scenario.models.names), ""))
    return rows


def summary_rows(summary: dict) -> list[tuple[str, Any, str]]:
    """(key, value, unit) of the quantities a summary has: no NaN, None or empty note.

    A quantity outside its window (NaN, a label None) is left out; its ``*_note``,
    which says why, is kept.  Units from :data:`hertzchain.measure.SUMMARY_UNITS`; the
    train's per-wave lists are :func:`train_rows`' (left out here).
    """
    from .measure import SUMMARY_UNITS, TRAIN_KEYS

    rows = []
    for key, value in summary.items():
        if (key in TRAIN_KEYS or key in ("train_waves", "train_note") or value == ""
                or value is None or (isinstance(value, float) and math.isnan(value))):
            continue
        rows.append((key, value, SUMMARY_UNITS.get(key, "")))
    return rows


def run_html(result) -> str:
    """A :class:`hertzchain.models.Run` as HTML: parameters, summary, train (escaped)."""
    from discrete.display import html_table

    summary = result.summary()
    name = result.scenario.name or "scenario"
    parts = [html_table(f"{name}: parameters", scenario_rows(result.scenario)),
             html_table(f"{name}: summary", summary_rows(summary))]
    if "train_waves" in summary:
        parts.append(html_table(f"{name}: wave train", train_rows(summary),
                                header=["quantity", "value", "measured"]))
    return "\n".join(parts)


def comparison_html(cmp) -> str:
    """A :class:`hertzchain.compare.Comparison` as HTML: verdict, differences, run numbers."""
    from discrete.display import html_table

    models = [m for m in _MODELS if m in cmp.differences]
    header = ["quantity", "discrete"]
    for m in models:
        header += [m, f"Δ {m}"]
    name = cmp.scenario.name or "scenario"
    parts = [html_table(f"{name}: parameters", scenario_rows(cmp.scenario)),
             html_table(f"{name}: differences to the discrete chain at t_compare = "
                        f"{cmp.t_compare * 1e3:.4g} ms", difference_rows(cmp),
                        header=header, note=cmp.verdict())]
    rows = run_rows(cmp)
    if rows:
        parts.append(html_table(f"{name}: the discrete run's own numbers", rows,
                                header=["quantity", "value", "measured"]))
    return "\n".join(parts)
