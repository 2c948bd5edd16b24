"""The package gives the answers `stamp run` gives on the shipped examples, and writes its files."""

import json

import numpy as np
import pytest

import stamp
from conftest import MESHES, assert_same_history, read_history, run_cli

# quick ones: rectangle and gmsh meshes (quadrilaterals; triangles cut), two to four surfaces,
# force- and displacement-driven punches, two punches, friction, a punch that turns
EXAMPLES = ["sphere-ss", "squeeze", "paper-r100", "disk-clamped", "sphere-ss-4surfaces", "stl-die", "sphere-slide-friction", "cylinder-rolling-friction", "sphere-dent-plastic"]


@pytest.fixture(scope="module", params=EXAMPLES)
def pair(request, tmp_path_factory):
    """(the example's name, the CLI's output folder, the package's Result) of one example."""
    name = request.param
    out = tmp_path_factory.mktemp(name) / "cli"
    status, _, err = run_cli("run", "-q", MESHES / f"{name}.toml", "--out", out)
    assert status == 0, err
    return name, out, stamp.Problem.from_toml(MESHES / f"{name}.toml").solve(quiet=True)


def test_history_equals_the_programs(pair):
    _, out, r = pair
    assert_same_history(r.history, read_history(out / "history.csv"))
    assert r.history["step"].dtype == np.int64


def test_summary_equals_the_programs_but_for_time_and_process(pair):
    _, out, r = pair
    cli = json.loads((out / "summary.json").read_text())
    mine = dict(r.summary)
    for key in ("pid", "started", "seconds", "problem"):
        cli.pop(key), mine.pop(key)
    assert mine == cli


def test_step_arrays_equal_the_programs_csv_files(pair):
    """The last written step's contact pressure against pressure_<punch>_<step>.csv."""
    _, out, r = pair
    step = r.steps[-1][0]
    for name in r.punches:
        rows = np.genfromtxt(out / f"pressure_{name}_{step:04d}.csv", delimiter=",", names=True)
        q = r.contact_pressure(name)
        np.testing.assert_array_equal(q[rows["node"].astype(int)], rows["q_n"])
        off = np.ones(len(q), bool)
        off[rows["node"].astype(int)] = False
        assert np.all(q[off] == 0.0)


def test_write_gives_the_programs_files(pair, tmp_path):
    _, out, r = pair
    written = r.write(tmp_path / "py")
    names = sorted(p.split("/")[-1] for p in written)
    cli_names = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert names == cli_names
    assert (tmp_path / "py" / "history.csv").read_text() == (out / "history.csv").read_text()
    # a second write into the same folder after a run with fewer steps leaves none of the first's
    assert json.loads((tmp_path / "py" / "summary.json").read_text())["status"] == "converged"


def test_vtu_arrays_equal_the_packages(pair):
    """The .vtu's point and cell arrays (read by VTK) are the package's point_data and cell_data."""
    pv = pytest.importorskip("pyvista")
    name, out, r = pair
    step = r.steps[-1][0]
    grid = pv.read(out / f"{name}_{step:04d}.vtu")
    np.testing.assert_array_equal(np.asarray(grid.points)[:, :2], r.nodes)
    for k, v in r.cell_data().items():
        np.testing.assert_allclose(grid.cell_data[k], v, rtol=1e-12, atol=1e-12 * np.max(np.abs(v), initial=1e-300))
    for k, v in r.point_data().items():
        w = np.asarray(grid.point_data[k])
        finite = np.isfinite(v)
        np.testing.assert_allclose(w[finite], v[finite], rtol=1e-12, atol=1e-12 * np.max(np.abs(v[finite]), initial=1e-300))
    # the mid-surface displacement is the mean of the faces' in the paper's two-surface plate
    d = r.displacement()
    mid = r.point_data()["displacement"]
    if d.shape[1] == 2:
        np.testing.assert_allclose(mid, d.mean(axis=1), rtol=0, atol=1e-15 * np.max(np.abs(d)))
    np.testing.assert_array_equal(d[:, 0, :], r.point_data()["displacement_bottom"])
    np.testing.assert_array_equal(d[:, -1, :], r.point_data()["displacement_top"])


def test_to_pyvista_is_the_deformed_plate(pair):
    pytest.importorskip("pyvista")
    _, _, r = pair
    g = r.to_pyvista()
    assert (g.n_points, g.n_cells) == (len(r.nodes), len(r.cells))
    np.testing.assert_allclose(g.points[:, :2], r.nodes + r.point_data()["displacement"][:, :2])
    np.testing.assert_allclose(g.points[:, 2], r.point_data()["displacement"][:, 2])
    assert set(r.cell_data()) <= set(g.cell_data.keys())
