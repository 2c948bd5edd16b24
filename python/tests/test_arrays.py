"""The shapes and dtypes of the results."""

import numpy as np
import pytest

import stamp
from conftest import MESHES


@pytest.fixture(scope="module")
def four():
    """Four surfaces through the thickness, one punch."""
    return stamp.Problem.from_toml(MESHES / "sphere-ss-4surfaces.toml").solve(quiet=True)


@pytest.fixture(scope="module")
def two():
    """The paper's plate, two punches."""
    return stamp.Problem.from_toml(MESHES / "squeeze.toml").solve(quiet=True)


@pytest.mark.parametrize("which, surfaces", [("two", 2), ("four", 4)])
def test_shapes_and_dtypes(request, which, surfaces):
    r = request.getfixturevalue(which)
    n, m = r.summary["nodes"], r.summary["cells"]
    assert r.nodes.shape == (n, 2) and r.nodes.dtype == np.float64
    assert r.cells.shape == (m, 4) and r.cells.dtype == np.int64
    assert r.cells.min() == 0 and r.cells.max() == n - 1
    assert r.displacement().shape == (n, surfaces, 3) and r.displacement().dtype == np.float64
    for name in r.punches:
        q = r.contact_pressure(name)
        assert q.shape == (n,) and q.dtype == np.float64 and q.min() >= 0.0
    cells = r.cell_data()
    assert list(cells) == r.summary["cell_arrays"]
    assert all(v.dtype == np.float64 for v in cells.values())
    stresses = [k for k in cells if k.startswith("stress_")]
    assert all(cells[k].shape == (m, 6) for k in stresses), "the six 3D stresses per cell"
    assert all(v.shape == (m,) for k, v in cells.items() if k not in stresses)
    # the six 3D stresses at every surface for plates of three or more surfaces
    assert stresses == ([f"stress_layer0_surface{s}" for s in range(surfaces)] if surfaces > 2 else [])
    points = r.point_data()
    assert list(points) == r.summary["point_arrays"]
    assert points["displacement"].shape == (n, 3) and points["lambda"].shape == (n,)
    h = r.history
    assert h["step"].dtype == np.int64 and all(v.dtype == np.float64 for k, v in h.items() if k != "step")
    assert len(h["step"]) == len(h["load_factor"]) >= len(r.steps)
    assert [s for s, _ in r.steps] == [s["step"] for s in r.summary["steps"]]


def test_steps_count_from_the_end_and_unknown_ones_are_refused(two):
    k = len(two.steps)
    np.testing.assert_array_equal(two.displacement(-1), two.displacement(k - 1))
    np.testing.assert_array_equal(two.displacement(0), two.displacement(-k))
    assert not np.array_equal(two.displacement(0), two.displacement(-1))
    with pytest.raises(IndexError):
        two.displacement(k)
    with pytest.raises(IndexError):
        two.cell_data(-k - 1)
    with pytest.raises(KeyError, match='no punch named "cone"'):
        two.contact_pressure("cone")


def test_the_two_punches_press_on_their_own_faces(two):
    """squeeze.toml: the sphere on the top face, the plane below; each pressure is its own."""
    total = two.point_data()["contact_pressure"]
    np.testing.assert_allclose(two.contact_pressure("sphere") + two.contact_pressure("plane"), total, rtol=1e-15, atol=0)
    assert two.contact_pressure("sphere").max() > 0 and two.contact_pressure("plane").max() > 0
