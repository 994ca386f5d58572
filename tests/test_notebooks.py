"""Execute every notebook in ``notebooks/`` at small sizes, so that they never rot.

The notebooks read ``HERTZCHAIN_NOTEBOOK_SMALL`` and shrink their runs; they are stored
without outputs (checked here).  ``pytest --nbmake notebooks/`` runs them at full size.
Also checked: notebooks number grains from 0 (docs/guide/cli.md), and the docs gallery
(``docs/examples``, executed by every docs build) runs every shipped law and chain
example.
"""

from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
GALLERY = sorted((ROOT / "docs" / "examples").glob("plot_*.py"))


def test_there_are_notebooks():
    assert len(NOTEBOOKS) >= 3


def test_gallery_runs_every_law_and_chain_example():
    """Every shipped example of a contact law, a kind of chain or a striker is run by a
    gallery example (docs/examples, executed at every docs build).

    The shipped examples (``hertzchain/scenarios/examples/``) are one per law and chain
    kind (docs/guide/laws_and_chains.md); the measurement examples (``measure_*``) are
    left out.  A new law or chain kind shipped without a gallery example fails here.
    """
    from hertzchain.scenario import shipped_scenarios

    kinds = [name for name, path in shipped_scenarios().items()
             if path.parent.name == "examples" and not name.startswith("measure_")]
    assert kinds, "no shipped law or chain examples found"
    text = "\n".join(p.read_text(encoding="utf-8") for p in GALLERY)
    missing = [name for name in kinds if f'"{name}"' not in text]
    assert not missing, f"shipped examples no gallery example runs: {missing}"


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
