"""Execute every notebook in ``notebooks/`` at small sizes, so that they never rot.

The notebooks read ``HERTZCHAIN_NOTEBOOK_SMALL`` and shrink their runs; they are stored
without outputs (checked here).  ``pytest --nbmake notebooks/`` runs them at full size.
"""

from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))


def test_there_are_notebooks():
    assert len(NOTEBOOKS) >= 3


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_counts_grains_from_zero(path):
    """Grain axes are labelled as every figure of hertzchain: "grain index", from 0.

    docs/guide/cli.md, "Grain indices": only ``reproduce`` keeps the paper's 1-based
    numbers, labelled as the paper's.
    """
    code = "\n".join(c.source for c in nbformat.read(path, as_version=4).cells
                     if c.cell_type == "code")
    assert '"grain number"' not in code, f"{path.name}: label grains \"grain index $i$\""


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs_at_small_size(path, tmp_path, monkeypatch):
    monkeypatch.setenv("HERTZCHAIN_NOTEBOOK_SMALL", "1")
    monkeypatch.setenv("MPLBACKEND", "agg")
    book = nbformat.read(path, as_version=4)
    code = [c for c in book.cells if c.cell_type == "code"]
    assert code, "no code cells"
    assert not any(c.get("outputs") or c.get("execution_count") for c in code), \
        f"{path.name} must be stored without outputs"
    client = nbclient.NotebookClient(book, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    errors = [o for c in book.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors
