import base64

import matplotlib.pyplot as plt

from hertzchain.report import Report, fmt


def test_report_markdown_and_html(tmp_path):
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    png = tmp_path / "fig.png"
    fig.savefig(png)
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


def test_fmt():
    assert fmt(None) == "—"
    assert fmt(3) == "3"
    assert fmt(1.234567891, 4) == "1.235"
    assert fmt("x") == "x"
