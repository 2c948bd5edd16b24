"""Shared helpers: the repository, the `stamp` program built from it, and running it."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
MESHES = REPO / "meshes"


def stamp_program():
    """The `stamp` program of this repository (cargo build --release -p stamp-cli), or $STAMP."""
    path = pathlib.Path(os.environ.get("STAMP", REPO / "target" / "release" / "stamp"))
    if not path.exists():
        pytest.fail(f"{path} is missing: build it with `cargo build --release -p stamp-cli` (or set STAMP)")
    return path


def run_cli(*args, cwd=None):
    """Run `stamp ARGS`; (exit status, stdout, stderr)."""
    p = subprocess.run([str(stamp_program()), *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=600)
    return p.returncode, p.stdout, p.stderr


def read_history(path):
    """history.csv as a dict of float64 columns."""
    lines = pathlib.Path(path).read_text().strip("\n").split("\n")
    header = lines[0].split(",")
    rows = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    return {h: rows[:, k] for k, h in enumerate(header)}


def assert_same_history(got, want, rtol=1e-12):
    """Every column of `want` is in `got`, equal to rtol (relative to the column's largest value)."""
    assert list(got) == list(want)
    for name, w in want.items():
        g = np.asarray(got[name], dtype=float)
        assert g.shape == w.shape, name
        scale = max(np.max(np.abs(w)), 1e-300) if w.size else 1.0
        assert np.max(np.abs(g - w), initial=0.0) <= rtol * scale, f"{name}: {g} != {w}"
