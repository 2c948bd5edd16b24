"""The README's Python example runs as written and draws its plot."""

import os
import subprocess
import sys

import pytest

from conftest import REPO


def test_the_readmes_sweep_runs_and_writes_its_plot(tmp_path):
    pytest.importorskip("matplotlib")
    text = (REPO / "README.md").read_text()
    section = text.split("## Python\n", 1)[1]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    assert "plt.savefig(\"force-travel.png\"" in code
    env = dict(os.environ, MPLBACKEND="Agg")
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    png = (tmp_path / "force-travel.png").read_bytes()
    assert png.startswith(b"\x89PNG") and len(png) > 10_000
