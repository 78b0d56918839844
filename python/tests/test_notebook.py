"""The example notebook (issue 36, part 7): ``examples/notebooks/paper.ipynb``
runs from top to bottom in a fresh kernel (nbclient) with no error, and
says what it should: the paper's run converged, the exact delay margin
(0.389 s) between the last delay that still decays and the first that
does not, 200 trials, a law of one's own.

Run by tests/tests/python_package.rs (ATTSYNC_REPO; the kernel inherits
PYTHONPATH, so it imports the package under test)."""

import os
from pathlib import Path

import nbformat
from nbclient import NotebookClient

REPO = Path(os.environ["ATTSYNC_REPO"])
NOTEBOOK = REPO / "examples/notebooks/paper.ipynb"


def text_of(cell) -> str:
    parts = []
    for o in cell.get("outputs", []):
        parts.append(o.get("text", ""))
        parts.append(o.get("data", {}).get("text/plain", ""))
    return "".join(parts)


def test_the_notebook_runs_and_says_what_it_should(tmp_path):
    nb = nbformat.read(NOTEBOOK, as_version=4)
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), "commit it without outputs"
    NotebookClient(nb, timeout=600, kernel_name="python3",
                   resources={"metadata": {"path": str(tmp_path)}}).execute()
    code = [c for c in nb.cells if c.cell_type == "code"]
    out = [text_of(c) for c in code]
    assert out[1].startswith("converged")
    assert "delay margin of the linearisation: 0.389" in out[2]
    # An independent check: the linearisation's root in each run of the
    # sweep changes sign across the margin.
    assert "crosses zero between 0.35 s and 0.45 s" in out[2]
    # The figures are drawn (an image in the outputs of each plotting cell).
    for k in (1, 3, 4, 5):
        assert any("image/png" in o.get("data", {}) for o in code[k].outputs), f"cell {k}: no figure"
    assert out[4].splitlines()[1].split() == ["converged", "200"], out[4]
    assert "built-in" in out[5] and "mine" in out[5]
    # Nothing was written beside the notebook or into the repository.
    assert sorted(p.name for p in NOTEBOOK.parent.iterdir()) == ["paper.ipynb"]
