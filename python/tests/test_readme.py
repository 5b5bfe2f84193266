"""The README's Python example runs as written (matplotlib without a display)."""

import pathlib
import re

import numpy as np
import pytest

README = pathlib.Path(__file__).resolve().parents[2] / "README.md"


def test_the_readme_example_runs_and_draws_a_shadow(tmp_path, monkeypatch):
    pytest.importorskip("trimesh")
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert len(blocks) == 1, "the README holds one Python example"
    monkeypatch.chdir(tmp_path)
    names = {}
    exec(compile(blocks[0], "README.md", "exec"), names)
    assert (tmp_path / "lightmap.png").stat().st_size > 10_000
    v = names["v"]
    # The torus shadows the floor under it (a ring of umbra) and leaves the corners lit.
    assert v.shape == (128, 128) and v.min() == 0.0 and v[0, 0] == v[-1, -1] == 1.0
    assert 0 < np.mean((v > 0) & (v < 1)) < 0.5
