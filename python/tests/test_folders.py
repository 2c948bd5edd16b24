"""Output folders: a result written into its own folder keeps its files; one run at a time writes
into a folder, also within one process."""

import json
import threading
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


def test_two_threads_solving_into_one_folder_one_is_refused(tmp_path):
    """The folder lock holds within a process too: the second solve is refused as a second
    `stamp run` would be, instead of both reporting "converged" over each other's files."""
    t = table()
    t["mesh"]["rectangle"]["n"] = [20, 20]
    t["solver"] = {"steps": 20, "max_increment": 0.05}
    t["output"] = {"vtu": True, "csv": False, "plot": False}
    p = stamp.Problem(t, name="plate")
    out = tmp_path / "shared"
    start = threading.Barrier(2)
    outcomes = [None, None]

    def solve(k):
        start.wait()
        try:
            outcomes[k] = p.solve(out=out, quiet=True)
        except stamp.StampError as e:
            outcomes[k] = e

    threads = [threading.Thread(target=solve, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    done = [o for o in outcomes if isinstance(o, stamp.Result)]
    refused = [o for o in outcomes if isinstance(o, stamp.StampError)]
    assert len(done) == 1 and len(refused) == 1, outcomes
    message = str(refused[0])
    assert str(out) in message and "in use" in message and "another run of this process" in message, message
    assert done[0].summary["status"] == "converged"
    # the .pvd lists the files that are there
    pvd = (out / "plate.pvd").read_text()
    listed = [part.split('"')[0] for part in pvd.split('file="')[1:]]
    assert len(listed) == len(done[0].steps) > 0 and all((out / f).exists() for f in listed), listed
    # the folder is free again: a later solve into it runs
    assert p.solve(out=out, quiet=True).summary["status"] == "converged"
