"""Rich display of results in Jupyter (``_repr_html_``): compact tables with units.

:func:`html_table` is the one HTML writer of the packages' result objects: a titled
table of (name, value, unit) rows, every piece of text escaped
(:func:`html.escape`), numbers to six significant digits, NaN and None as "n/a".
:func:`simulation_html` and :func:`run_info_html` describe a
:class:`discrete.Simulation` and a :class:`discrete.RunInfo`;
:mod:`hertzchain.compare_output` uses the same writer for a
:class:`hertzchain.models.Run` and a :class:`hertzchain.compare.Comparison`.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence
from numbers import Integral, Real

import numpy as np

__all__ = ["html_table", "html_value", "simulation_html", "run_info_html"]


def html_value(value) -> str:
    """A value as escaped HTML text: floats to 6 significant digits, NaN/None as "n/a".

    Lists and arrays are written element by element, separated by commas.
    """
    if value is None:
        return "n/a"
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, Integral):
        return str(int(value))
    if isinstance(value, Real):
        x = float(value)
        return "n/a" if math.isnan(x) else html.escape(f"{x:.6g}")
    if isinstance(value, list | tuple | np.ndarray):
        return ", ".join(html_value(v) for v in value)
    return html.escape(str(value))


def html_table(title: str, rows: Iterable[Sequence], *, header: Sequence[str] | None = None,
               note: str = "") -> str:
    """A compact HTML table: a caption ``title``, then one row per entry of ``rows``.

    Each row is (name, value[, unit, ...]): the name and units as escaped text, the
    values by :func:`html_value`.  ``header``: column titles (default name, value,
    unit); ``note``: a line of escaped text below the table.
    """
    rows = [list(r) for r in rows]
    width = max([len(r) for r in rows] + [len(header or ())] + [2])
    header = list(header) if header is not None else ["quantity", "value", "unit"][:width]
    out = ['<table class="hertzchain">',
           f"<caption>{html.escape(str(title))}</caption>",
           "<thead><tr>" + "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
           + "</tr></thead>", "<tbody>"]
    for r in rows:
        cells = [html.escape(str(r[0]))] + [html_value(v) for v in r[1:2]] \
            + [html.escape(str(v)) for v in r[2:]]
        cells += [""] * (width - len(cells))
        out.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    out.append("</tbody></table>")
    if note:
        out.append(f"<p>{html.escape(note)}</p>")
    return "\n".join(out)


def simulation_html(sim) -> str:
    """The parameters and present state of a :class:`discrete.Simulation`, as HTML.

    Parameters: grains, law, integrator, dt, drag; state: t, steps, the wave energy
    E (kinetic + contact energy, docs/physics.md §6), the energy dissipated, the
    energy-balance drift, the largest |v| and the snapshots taken.
    """
    ch = sim.chain
    params = [("grains", int(ch.n), "1"), ("contact law", sim.law.describe(), ""),
              ("integrator", sim.integrator, ""), ("dt", float(sim.dt), "s"),
              ("drag", float(sim.drag), "1/s"),
              ("diameter", float(np.max(ch.diameter)), "m"),
              ("static overlap δ0 (largest)", float(np.max(ch.delta0)), "m")]
    state = [("t", float(sim.t), "s"), ("steps", int(sim.steps), "1"),
             ("energy E", float(sim.energy()), "J"),
             ("energy dissipated", float(sim.dissipated()), "J"),
             ("energy drift", float(sim.energy_drift), "1"),
             ("largest |v|", float(np.max(np.abs(sim.v))) if ch.n else 0.0, "m/s"),
             ("snapshots", [s.label for s in sim.record.snapshots] or "none", "")]
    return html_table("discrete.Simulation", [*params, *state])


def run_info_html(info) -> str:
    """A :class:`discrete.RunInfo` (one call of ``Simulation.run``) as HTML."""
    return html_table("discrete.RunInfo", [
        ("steps", int(info.steps), "1"), ("t", float(info.t), "s"),
        ("stopped by", info.stopped_by, ""), ("energy drift", float(info.energy_drift), "1"),
        ("modified-energy drift", float(info.shadow_drift), "1")])
