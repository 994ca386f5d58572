"""Reports: Markdown and HTML rendering, and that every figure shows.

A report's figures must show wherever it is opened from: every image of ``report.html``
is embedded (a base64 PNG, decoded and checked here by its signature, independently of
matplotlib and PIL), and every link of ``report.md`` resolves, relative to the report's
own directory, to that same PNG.  Checked for the report API with paths relative to
the working directory, and for the reports that ``hertzchain reproduce`` and
``hertzchain compare`` write with a relative ``--out``, an absolute one, and from
another working directory.
"""

import base64
import re
import shutil
from pathlib import Path
from urllib.parse import unquote

import matplotlib.pyplot as plt
import pytest

from hertzchain.cli import main
from hertzchain.report import Report, fmt

PNG = b"\x89PNG\r\n\x1a\n"  # the PNG signature (PNG specification, section 5.2)
MD_IMAGE = re.compile(r"^!\[.*\]\((?P<link>[^()\s]+)\)$", re.MULTILINE)
HTML_IMG = re.compile(r"<img\b[^>]*>")
HTML_SRC = re.compile(r"""src=(['"])(?P<src>.*?)\1""")
DATA_PNG = "data:image/png;base64,"


def check_report(directory: Path) -> int:
    """Assert that every figure of ``directory/report.{md,html}`` shows; their count."""
    md = (directory / "report.md").read_text(encoding="utf-8")
    page = (directory / "report.html").read_text(encoding="utf-8")
    linked = []
    for m in MD_IMAGE.finditer(md):
        link = unquote(m["link"])
        assert not Path(link).is_absolute() and "\\" not in link, link
        target = (directory / link).resolve()
        assert target.is_file(), f"report.md links {link!r}: no file {target}"
        linked.append(target.read_bytes())
    embedded = []
    for tag in HTML_IMG.findall(page):
        src = HTML_SRC.search(tag)["src"]
        assert src.startswith(DATA_PNG), f"an image that is not embedded: {src[:80]!r}"
        embedded.append(base64.b64decode(src[len(DATA_PNG):], validate=True))
    assert "src=" not in HTML_IMG.sub("", page)     # no other file referred to
    for data in linked + embedded:
        assert data.startswith(PNG) and len(data) > 100
    assert embedded == linked                        # the same figures, in order
    return len(linked)


def _png(path: Path) -> Path:
    fig, ax = plt.subplots(figsize=(2, 1.5))
    ax.plot([0, 1], [0, 1])
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
    return path


def test_report_markdown_and_html(tmp_path):
    png = _png(tmp_path / "fig.png")
    rep = Report("Test report")
    rep.heading("Table 2")
    rep.paragraph("Numbers next to the paper's.")
    rep.table(["point", "ours", "paper"], [["M", 0.888061234, 0.88806]], caption="cap")
    rep.figure(png, "a line")
    rep.bullets(["one", "two"])
    md, page = rep.write(tmp_path)
    text = md.read_text()
    assert "| M | 0.88806 | 0.88806 |" in text
    assert "![a line](fig.png)" in text
    page_text = page.read_text()
    assert base64.b64encode(png.read_bytes()).decode()[:100] in page_text
    assert "<li>two</li>" in page_text
    assert check_report(tmp_path) == 1


def test_figure_paths_relative_to_the_working_directory(tmp_path, monkeypatch):
    # the report in "out dir/", figures under it and beside it, all given relative to
    # the working directory (as ``hertzchain reproduce --out "out dir"`` gives them)
    monkeypatch.chdir(tmp_path)
    _png(Path("out dir/figures/a.png"))
    _png(Path("elsewhere/b.png"))
    rep = Report("relative")
    rep.figure("out dir/figures/a.png", "under the report")
    rep.figure(Path("elsewhere/b.png"), "beside it")
    monkeypatch.chdir(tmp_path / "elsewhere")           # written from another directory
    md, _ = rep.write(tmp_path / "out dir")
    assert "](figures/a.png)" in md.read_text() and "](../elsewhere/b.png)" in md.read_text()
    assert check_report(tmp_path / "out dir") == 2
    # moved as a whole: still shows
    shutil.copytree(tmp_path / "out dir", tmp_path / "moved")
    assert check_report(tmp_path / "moved") == 2


def test_a_missing_or_bad_figure_is_an_error(tmp_path):
    rep = Report("missing")
    with pytest.raises(FileNotFoundError, match="report figure .*nope.png.* does not exist"):
        rep.figure(tmp_path / "nope.png", "gone")
    (tmp_path / "fake.png").write_text("not an image")
    with pytest.raises(ValueError, match="is not a PNG file"):
        rep.figure(tmp_path / "fake.png", "text")
    png = _png(tmp_path / "late.png")
    rep.figure(png, "removed before writing")
    png.unlink()
    with pytest.raises(FileNotFoundError, match="late.png"):
        rep.write(tmp_path / "out")
    assert not (tmp_path / "out" / "report.md").exists()   # no half report


def test_fmt():
    assert fmt(None) == "—"
    assert fmt(3) == "3"
    assert fmt(1.234567891, 4) == "1.235"
    assert fmt("x") == "x"


# -- the commands' reports, with --out relative, absolute, and from elsewhere ---------
def _outs(tmp_path: Path):
    """(working directory, --out) pairs: relative with a space, absolute, relative with
    '..' from another working directory."""
    work, other = tmp_path / "here", tmp_path / "other" / "deeper"
    work.mkdir()
    other.mkdir(parents=True)
    return [(work, "out rel"), (work, str(tmp_path / "out abs")),
            (other, "../../here/nested/out")]


def test_reproduce_report_shows_its_figures(tmp_path, monkeypatch, capsys):
    for cwd, out in _outs(tmp_path):
        monkeypatch.chdir(cwd)
        assert main(["reproduce", "fig4", "--workers", "1", "--out", out]) == 0
        assert check_report((cwd / out).resolve()) >= 1, out
    capsys.readouterr()


COMPARE_TOML = """name = "report-mono"
[chain]
delta0_over_d = 1e-3
[[chain.sections]]
n = 200
[[chain.sections]]
n = 200
alpha_rho = 2.0
[initial]
kind = "exact_wave"
center = 100
velocity_max = 0.0822
[run]
t_end = 3e-4
[models]
samples = 7
"""


def test_compare_report_shows_its_figures(tmp_path, monkeypatch, capsys):
    toml = tmp_path / "mono.toml"
    toml.write_text(COMPARE_TOML)
    for cwd, out in _outs(tmp_path):
        monkeypatch.chdir(cwd)
        assert main(["compare", str(toml), "--out", out, "--continuum", "off"]) == 0
        assert check_report((cwd / out).resolve()) == 3, out
    capsys.readouterr()
