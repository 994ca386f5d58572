"""Reports: ``report.md`` and ``report.html`` (figures embedded) from collected sections.

A :class:`Report` collects, item by item, headings, paragraphs, tables and figures; the
HTML version embeds each PNG as base64 so it is a single self-contained file, and the
Markdown version links each PNG relative to the report's own directory, so both can be
opened from anywhere and the directory can be moved as a whole.

A figure is given as an ordinary path (absolute, or relative to the working directory
at the time :meth:`Report.figure` is called) and must be an existing PNG file: a missing
or unreadable figure is an error, never an empty image or a dead link.
"""

from __future__ import annotations

import base64
import html
import os
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import quote

from .cache import atomic_path

__all__ = ["Report", "fmt"]

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
"""The eight bytes every PNG file starts with (PNG specification, section 5.2)."""


def _png_bytes(path: Path, *, head_only: bool = False) -> bytes:
    """The bytes of the PNG file ``path`` (only its signature if ``head_only``).

    Raises
    ------
    FileNotFoundError
        ``path`` does not exist.
    ValueError
        ``path`` is not a PNG file.
    """
    try:
        with open(path, "rb") as f:
            data = f.read(len(_PNG_SIGNATURE)) if head_only else f.read()
    except FileNotFoundError:
        raise FileNotFoundError(f"report figure {str(path)!r} does not exist") from None
    if not data.startswith(_PNG_SIGNATURE):
        raise ValueError(f"report figure {str(path)!r} is not a PNG file (it does not "
                         "start with the PNG signature)")
    return data


def fmt(value, digits: int = 5) -> str:
    """Format a number for a table: ``digits`` significant figures, '—' for None."""
    if value is None:
        return "—"
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    return f"{value:.{digits}g}"


@dataclass
class _Table:
    header: list[str]
    rows: list[list]
    caption: str = ""


@dataclass
class _Figure:
    path: Path
    """Absolute path of the PNG file."""
    caption: str


@dataclass
class Report:
    """Accumulates the content of a reproduction report.

    Parameters
    ----------
    title : str
        Title of the report.
    """

    title: str
    blocks: list = field(default_factory=list)

    def heading(self, text: str, level: int = 2) -> None:
        """Add a heading of the given level (1–4)."""
        self.blocks.append(("h", level, text))

    def paragraph(self, text: str) -> None:
        """Add a paragraph (plain text, Markdown emphasis allowed)."""
        self.blocks.append(("p", text))

    def bullets(self, items: list[str]) -> None:
        """Add a bullet list."""
        self.blocks.append(("ul", list(items)))

    def table(self, header: list[str], rows: list[list], caption: str = "") -> None:
        """Add a table; numbers are formatted with :func:`fmt`."""
        self.blocks.append(("table", _Table(list(header), [list(r) for r in rows], caption)))

    def figure(self, path: str | os.PathLike, caption: str) -> None:
        """Add a PNG figure.

        Parameters
        ----------
        path : path-like
            The PNG file: absolute, or relative to the current working directory (as
            any path), resolved now.
        caption : str
            Caption and alternative text.

        Raises
        ------
        FileNotFoundError
            The file does not exist.
        ValueError
            It is not a PNG file.
        """
        absolute = Path(os.path.abspath(path))
        _png_bytes(absolute, head_only=True)
        self.blocks.append(("fig", _Figure(absolute, caption)))

    # -- rendering ---------------------------------------------------------------
    def to_markdown(self, base: str | os.PathLike) -> str:
        """Render as Markdown for a file in the directory ``base``.

        Figures are linked relative to ``base`` (forward slashes, percent-encoded),
        so the links hold wherever the report is opened from.
        """
        base = os.path.abspath(base)
        out = [f"# {self.title}", ""]
        for block in self.blocks:
            kind = block[0]
            if kind == "h":
                out += ["#" * block[1] + " " + block[2], ""]
            elif kind == "p":
                out += [block[1], ""]
            elif kind == "ul":
                out += [f"- {item}" for item in block[1]] + [""]
            elif kind == "table":
                t = block[1]
                if t.caption:
                    out += [f"*{t.caption}*", ""]
                out.append("| " + " | ".join(t.header) + " |")
                out.append("|" + "---|" * len(t.header))
                out += ["| " + " | ".join(fmt(c) for c in row) + " |" for row in t.rows]
                out.append("")
            elif kind == "fig":
                f = block[1]
                link = quote(Path(os.path.relpath(f.path, base)).as_posix())
                out += [f"![{f.caption}]({link})", "", f"*{f.caption}*", ""]
        return "\n".join(out)

    def to_html(self, base: str | os.PathLike | None = None) -> str:
        """Render as a single HTML page with the figures embedded as base64 PNG.

        ``base`` (the directory of the page) is accepted for symmetry with
        :meth:`to_markdown`; the page refers to no file.

        Raises
        ------
        FileNotFoundError, ValueError
            A figure has gone missing or is no longer a PNG file.
        """
        esc = html.escape
        out = ["<!DOCTYPE html><html><head><meta charset='utf-8'>",
               f"<title>{esc(self.title)}</title><style>body{{font-family:sans-serif;"
               "max-width:70em;margin:auto}table{border-collapse:collapse}"
               "td,th{border:1px solid #999;padding:2px 6px;text-align:right}"
               "img{max-width:100%}</style></head><body>", f"<h1>{esc(self.title)}</h1>"]
        for block in self.blocks:
            kind = block[0]
            if kind == "h":
                out.append(f"<h{block[1]}>{esc(block[2])}</h{block[1]}>")
            elif kind == "p":
                out.append(f"<p>{esc(block[1])}</p>")
            elif kind == "ul":
                out.append("<ul>" + "".join(f"<li>{esc(i)}</li>" for i in block[1]) + "</ul>")
            elif kind == "table":
                t = block[1]
                cap = f"<caption>{esc(t.caption)}</caption>" if t.caption else ""
                head = "".join(f"<th>{esc(h)}</th>" for h in t.header)
                body = "".join(
                    "<tr>" + "".join(f"<td>{esc(fmt(c))}</td>" for c in row) + "</tr>"
                    for row in t.rows)
                out.append(f"<table>{cap}<tr>{head}</tr>{body}</table>")
            elif kind == "fig":
                f = block[1]
                data = base64.b64encode(_png_bytes(f.path)).decode("ascii")
                out.append(f"<figure><img src='data:image/png;base64,{data}' "
                           f"alt='{esc(f.caption)}'><figcaption>{esc(f.caption)}"
                           "</figcaption></figure>")
        out.append("</body></html>")
        return "\n".join(out)

    def write(self, directory: str | os.PathLike) -> tuple[Path, Path]:
        """Write ``report.md`` and ``report.html`` into ``directory`` (atomically).

        Both are rendered before either is written: a missing figure
        (FileNotFoundError) leaves no report behind.

        Returns
        -------
        (Path, Path)
            ``directory/report.md`` and ``directory/report.html``.
        """
        base = Path(directory)
        md, page = base / "report.md", base / "report.html"
        texts = self.to_markdown(base), self.to_html(base)
        for path, text in zip((md, page), texts, strict=True):
            with atomic_path(path) as tmp:
                tmp.write_text(text, encoding="utf-8")
        return md, page
