"""The notebooks run from top to bottom (small sizes) with only the public API."""

import json
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NOTEBOOKS = sorted((Path(__file__).parent.parent / "notebooks").glob("*.ipynb"))
# A run's saved text (everything but images and widget state): the notebooks print tables of a
# few kB (10.2 kB for notebook 02, the largest, since its tables gained the viscoelastic and
# Langevin rows: a 10 kB limit failed on it). tqdm without ipywidgets writes text bars
# instead of widgets, a line every 0.1 s into the saved output (1.4 MB in notebook 02 at full
# size): the limit is there to catch those, at twice the largest table.
TEXT_LIMIT = 20_000  # bytes per notebook
COMMITTED_LIMIT = 20_000  # bytes per committed (stripped) .ipynb; all are under 6 kB


def _text_outputs(nb):
    """The text of every output: streams, and the non-image parts of rich outputs."""
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            if "text" in out:
                yield out["text"]
            for mime, data in out.get("data", {}).items():
                if not mime.startswith("image/"):
                    yield data if isinstance(data, str) else json.dumps(data)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs(path, tmp_path, monkeypatch):
    monkeypatch.setenv("GRANULAR_QUICK", "1")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    nb = nbformat.read(path, as_version=4)
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), (
        "outputs must be stripped in git"
    )
    assert path.stat().st_size < COMMITTED_LIMIT
    client = nbclient.NotebookClient(
        nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    errors = [
        o
        for c in nb.cells
        if c.cell_type == "code"
        for o in c.get("outputs", [])
        if o.get("output_type") == "error"
    ]
    assert not errors
    text = list(_text_outputs(nb))
    bars = [t for t in text if "\r" in t and "|" in t]
    assert not bars, f"text progress bars in the output (is ipywidgets installed?): {bars[:3]}"
    assert sum(len(t) for t in text) < TEXT_LIMIT


def test_the_notebooks_are_the_seven_listed():
    assert [p.stem for p in NOTEBOOKS] == [
        "01_quickstart",
        "02_thesis_reproduction",
        "03_langevin_vs_edmd",
        "04_viscoelastic_and_clustering",
        "05_driven_and_forced_gases",
        "06_sheared_gases",
        "07_rough_particles",
    ]
