"""Problems from dicts and numpy arrays: the same as their TOML twins."""

import json
import os
import shutil
import tomllib

import numpy as np
import pytest

import stamp
from conftest import MESHES, assert_same_history

SPHERE = MESHES / "sphere-ss.toml"


def table(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


def same_results(a, b):
    assert_same_history(a.history, b.history)
    np.testing.assert_array_equal(a.nodes, b.nodes)
    np.testing.assert_array_equal(a.cells, b.cells)
    np.testing.assert_array_equal(a.displacement(), b.displacement())
    sa, sb = dict(a.summary), dict(b.summary)
    for key in ("pid", "started", "seconds", "problem"):
        sa.pop(key), sb.pop(key)
    assert sa == sb


@pytest.fixture(scope="module")
def from_toml():
    return stamp.Problem.from_toml(SPHERE).solve(quiet=True)


def test_the_files_table_as_a_dict_gives_the_same_results(from_toml):
    r = stamp.Problem(table(SPHERE), name="sphere-ss").solve(quiet=True)
    same_results(r, from_toml)


def rectangle_groups(nodes, n):
    """The built-in rectangle's groups (mesh.rs) of an (n+1) x (n+1) grid, as index arrays."""
    idx = lambda i, j: j * (n + 1) + i
    chain = lambda ids: np.array([[a, b] for a, b in zip(ids[:-1], ids[1:])])
    return {
        "bottom": {"segments": chain([idx(i, 0) for i in range(n + 1)])},
        "right": {"segments": chain([idx(n, j) for j in range(n + 1)])},
        "top": {"segments": chain([idx(i, n) for i in range(n, -1, -1)])},
        "left": {"segments": chain([idx(0, j) for j in range(n, -1, -1)])},
        "corner_ll": {"nodes": [idx(0, 0)]},
        "corner_lr": {"nodes": [idx(n, 0)]},
        "corner_ur": {"nodes": [idx(n, n)]},
        "corner_ul": {"nodes": [idx(0, n)]},
        "center": {"nodes": np.array([idx(n // 2, n // 2)], dtype=np.int32)},
    }


def test_a_mesh_of_numpy_arrays_gives_the_results_of_its_toml_twin(from_toml):
    """sphere-ss.toml's rectangle given as arrays (nodes, cells, groups) instead."""
    n = 10
    x = np.linspace(0.0, 20.0, n + 1)
    xy = np.array([[xi, yj] for yj in x for xi in x])
    quads = np.array([[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i] for j in range(n) for i in range(n)])
    t = table(SPHERE)
    t["mesh"] = {"nodes": xy, "cells": quads, "groups": rectangle_groups(xy, n)}
    p = stamp.Problem(t, name="sphere-ss")
    assert "rectangle" not in p.toml and "nodes" not in p.toml
    same_results(p.solve(quiet=True), from_toml)


def square_of_triangles(n, size=20.0):
    """An n x n grid of squares on [0, size]^2, each cut into two triangles along a diagonal
    (alternating), with its four sides as segment groups."""
    x = np.linspace(0.0, size, n + 1)
    xy = np.array([[xi, yj] for yj in x for xi in x])
    idx = lambda i, j: j * (n + 1) + i
    tris = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            tris += [[a, b, c], [a, c, d]] if (i + j) % 2 == 0 else [[a, b, d], [b, c, d]]
    sides = {
        "left": [idx(0, j) for j in range(n, -1, -1)],
        "bottom": [idx(i, 0) for i in range(n + 1)],
        "right": [idx(n, j) for j in range(n + 1)],
        "top": [idx(i, n) for i in range(n, -1, -1)],
    }
    segments = {k: np.array(list(zip(v[:-1], v[1:]))) for k, v in sides.items()}
    return xy, np.array(tris), segments


def write_msh(path, xy, tris, segments):
    """The mesh as a gmsh MSH 4.1 ASCII file: one surface (physical "plate"), a curve per side."""
    names = list(segments)
    lines = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names) + 1)]
    lines += [f'1 {k + 1} "{name}"' for k, name in enumerate(names)] + [f'2 {len(names) + 1} "plate"', "$EndPhysicalNames"]
    lines += ["$Entities", f"0 {len(names)} 1 0"]
    lines += [f"{k + 1} 0 0 0 20 20 0 1 {k + 1} 0" for k in range(len(names))]
    lines += [f"1 0 0 0 20 20 0 1 {len(names) + 1} 0", "$EndEntities"]
    n = len(xy)
    lines += ["$Nodes", f"1 {n} 1 {n}", f"2 1 0 {n}"] + [str(i + 1) for i in range(n)]
    lines += [f"{float(x)!r} {float(y)!r} 0" for x, y in xy] + ["$EndNodes"]
    count = len(tris) + sum(len(s) for s in segments.values())
    lines += ["$Elements", f"{len(names) + 1} {count} 1 {count}", f"2 1 2 {len(tris)}"]
    lines += [f"{k + 1} {a + 1} {b + 1} {c + 1}" for k, (a, b, c) in enumerate(tris)]
    tag = len(tris)
    for k, name in enumerate(names):
        lines.append(f"1 {k + 1} 1 {len(segments[name])}")
        for a, b in segments[name]:
            tag += 1
            lines.append(f"{tag} {a + 1} {b + 1}")
    lines.append("$EndElements")
    path.write_text("\n".join(lines) + "\n")


def test_triangles_given_as_arrays_are_cut_as_the_gmsh_reader_cuts_them(tmp_path):
    """A triangle mesh as arrays and the same mesh as a .msh file named by a TOML problem."""
    xy, tris, segments = square_of_triangles(6)
    write_msh(tmp_path / "tri.msh", xy, tris, segments)
    text = SPHERE.read_text().replace(
        'rectangle = { x = [0.0, 20.0], y = [0.0, 20.0], n = [10, 10] }', 'file = "tri.msh"'
    )
    assert 'file = "tri.msh"' in text
    (tmp_path / "tri.toml").write_text(text)
    want = stamp.Problem.from_toml(tmp_path / "tri.toml").solve(quiet=True)
    t = table(tmp_path / "tri.toml")
    t["mesh"] = {"nodes": xy, "cells": tris, "groups": {**{k: {"segments": v} for k, v in segments.items()}, "plate": {"cells": np.arange(len(tris))}}}
    got = stamp.Problem(t, name="tri").solve(quiet=True)
    assert got.cells.shape == (3 * len(tris), 4)
    same_results(got, want)


def test_a_mesh_file_in_a_dict_is_relative_to_the_working_directory(tmp_path, from_toml, monkeypatch):
    xy, tris, segments = square_of_triangles(4)
    write_msh(tmp_path / "tri-plate.msh", xy, tris, segments)
    t = table(SPHERE)
    t["mesh"] = {"file": "tri-plate.msh"}
    monkeypatch.chdir(tmp_path)
    r = stamp.Problem(t).solve(quiet=True)
    assert r.summary["cells"] == 3 * len(tris)
    monkeypatch.chdir(MESHES)
    with pytest.raises(stamp.StampError, match=r"mesh\.file: .*plate\.msh does not exist"):
        stamp.Problem(t).solve(quiet=True)


def test_numpy_values_work_as_numbers_and_lists(from_toml):
    t = table(SPHERE)
    t["plate"]["E"] = np.float64(2.1e5)
    t["punch"][0]["center"] = np.array([0.0, 0.0, 200.5])
    t["punch"][0]["force"] = np.float32(500.0)
    t["solver"]["steps"] = np.int64(5)
    t["boundary"] = tuple(t["boundary"])
    r = stamp.Problem(t, name="sphere-ss").solve(quiet=True)
    same_results(r, from_toml)


def test_write_replaces_a_previous_runs_files(tmp_path, from_toml):
    t = table(SPHERE)
    t["solver"] = {"steps": 2}
    fewer = stamp.Problem(t, name="sphere-ss").solve(quiet=True)
    out = tmp_path / "out"
    from_toml.write(out)
    assert (out / "sphere-ss_0005.vtu").exists()
    written = fewer.write(out)
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == sorted(os.path.basename(p) for p in written)
    assert json.loads((out / "summary.json").read_text())["targets"] == [0.5, 1.0]


def test_solve_writes_into_out_as_stamp_run_does(tmp_path):
    r = stamp.Problem.from_toml(SPHERE).solve(out=tmp_path / "o", quiet=True)
    assert r.out_dir == tmp_path / "o" or str(r.out_dir) == str(tmp_path / "o")
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["status"] == "converged"
