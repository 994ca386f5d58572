"""Write a benchmark's results into its section of ``docs/benchmarks.md``.

Each script that has a section there builds it with :func:`section` (the machine, the
date, the exact command and the script's markdown table) and, given ``--write-docs``,
replaces the text between the section's markers with :func:`write_section`::

    <!-- benchmarks: NAME start (python benchmarks/NAME.py --write-docs) -->
    ...
    <!-- benchmarks: NAME end -->

Everything outside the markers is left as it is; missing or repeated markers are an
error, never a silently appended section.
"""

from __future__ import annotations

import datetime
import os
import platform
import re
import shlex
import subprocess
import sys
from pathlib import Path

from _machine import cpu_name

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs" / "benchmarks.md"

__all__ = ["section", "write_section", "markdown_table", "DOCS"]


def markdown_table(header: list[str], rows: list[list]) -> str:
    """A GitHub-flavoured markdown table (cells converted with ``str``)."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def _revision() -> str:
    try:
        out = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--dirty"],
                             capture_output=True, text=True, timeout=10)
    except OSError:
        return "unknown revision"
    return out.stdout.strip() or "unknown revision"


def section(table: str, *, load: tuple[float, float] | None = None,
            notes: str = "") -> str:
    """The body of a section: machine, date, command and revision, the table, notes.

    Parameters
    ----------
    table : str
        The script's markdown table (:func:`markdown_table`).
    load : (float, float), optional
        One-minute load average before and after the measurement.
    notes : str
        Text after the table (what the columns mean, ratios).
    """
    now = datetime.datetime.now(datetime.UTC)
    cmd = " ".join(["python", "benchmarks/" + Path(sys.argv[0]).name,
                    *map(shlex.quote, sys.argv[1:])])
    head = (f"Machine: {cpu_name()}, Python {platform.python_version()}"
            + (f", load average {load[0]:.1f} before and {load[1]:.1f} after"
               if load else "")
            + f".  Measured {now:%Y-%m-%d %H:%M} UTC on revision {_revision()} with "
            f"`{cmd}`.")
    return "\n\n".join(p for p in (head, table, notes.strip()) if p)


def write_section(name: str, body: str, path: Path = DOCS) -> Path:
    """Replace the text between ``name``'s markers in ``path`` by ``body``.

    Raises
    ------
    ValueError
        The start or end marker is missing or not unique.
    """
    text = path.read_text(encoding="utf-8")
    start = re.compile(rf"^<!-- benchmarks: {re.escape(name)} start\b.*-->$", re.MULTILINE)
    end = re.compile(rf"^<!-- benchmarks: {re.escape(name)} end -->$", re.MULTILINE)
    s, e = list(start.finditer(text)), list(end.finditer(text))
    if len(s) != 1 or len(e) != 1 or e[0].start() < s[0].end():
        raise ValueError(f"{path}: need exactly one '<!-- benchmarks: {name} start ... -->' "
                         f"line followed by one '<!-- benchmarks: {name} end -->' line "
                         f"(found {len(s)} and {len(e)})")
    new = text[:s[0].end()] + "\n\n" + body.strip() + "\n\n" + text[e[0].start():]
    tmp = path.with_name(path.name + f".tmp{os.getpid()}")
    tmp.write_text(new, encoding="utf-8")
    tmp.replace(path)
    print(f"written: section '{name}' of {path.relative_to(ROOT)}", file=sys.stderr)
    return path
