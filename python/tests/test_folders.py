"""Output folders: a result written into its own folder keeps its files."""

import json
import tomllib

import pytest

import stamp
from conftest import MESHES

SPHERE = MESHES / "sphere-ss.toml"


def table(**solver):
    with open(SPHERE, "rb") as f:
        t = tomllib.load(f)
    t["solver"].update(solver)
    return t


def files(d):
    """The outputs in folder `d` (not the lock and manifest): name -> bytes."""
    return {p.name: p.read_bytes() for p in d.iterdir() if not p.name.startswith(".")}


def test_writing_a_result_into_its_own_folder_keeps_its_files(tmp_path, monkeypatch):
    out = tmp_path / "results"
    r = stamp.Problem.from_toml(SPHERE).solve(out=out, quiet=True)
    before = files(out)
    assert "summary.json" in before and "sphere-ss.pvd" in before and len(before) > 5
    written = r.write(out)
    assert sorted(p.rsplit("/", 1)[-1] for p in written) == sorted(before)
    assert files(out) == before
    # the same folder named otherwise (relative, through ..)
    monkeypatch.chdir(tmp_path)
    r.write("results/../results/.")
    assert files(out) == before
    # another folder: copied, the originals kept
    copied = r.write(tmp_path / "copy")
    assert len(copied) == len(before)
    assert files(tmp_path / "copy") == before and files(out) == before


def test_a_result_whose_files_another_run_replaced_is_not_written(tmp_path):
    out = tmp_path / "results"
    first = stamp.Problem(table(), name="sphere-ss").solve(out=out, quiet=True)
    second = stamp.Problem(table(steps=2), name="sphere-ss").solve(out=out, quiet=True)
    for where in (out, tmp_path / "copy"):
        with pytest.raises(stamp.StampError, match="removed or rewritten since the solve"):
            first.write(where)
    assert json.loads((out / "summary.json").read_text())["targets"] == [0.5, 1.0]
    second.write(tmp_path / "copy")
    assert json.loads((tmp_path / "copy" / "summary.json").read_text())["targets"] == [0.5, 1.0]
