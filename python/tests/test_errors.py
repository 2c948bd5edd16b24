"""Bad input raises stamp.StampError (a ValueError) with the program's message, naming the key."""

import tomllib
import warnings

import numpy as np
import pytest

import stamp
from conftest import MESHES, run_cli

SPHERE = MESHES / "sphere-ss.toml"


def table():
    with open(SPHERE, "rb") as f:
        return tomllib.load(f)


def raised(t, **kw):
    with pytest.raises(stamp.StampError) as e:
        stamp.Problem(t, **kw).solve(quiet=True)
    assert isinstance(e.value, ValueError)
    return str(e.value)


def test_stamp_error_is_a_value_error():
    assert issubclass(stamp.StampError, ValueError)
    assert stamp.StampError.__module__ == "stamp"


@pytest.mark.parametrize(
    "old, new, key, what",
    [
        ("nu = 0.3", "nu = 0.7", "plate.nu", "expected Poisson's ratio in (-1, 0.5), got 0.7"),
        ("steps = 5", "steps = 0", "solver.steps", "expected a whole number from 1 to 100000, got 0"),
        ('group = "top"', 'group = "tpo"', "boundary[3].group", "no group named 'tpo'"),
        ("radius = 200.0", "radius = 200.0\nradios = 3", "punch[0]: unknown field", "`radios`"),
    ],
)
def test_a_bad_file_gives_the_programs_message_and_its_dict_the_same_with_the_key(tmp_path, old, new, key, what):
    text = SPHERE.read_text()
    assert old in text
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace(old, new, 1))
    status, _, err = run_cli("run", "-q", bad, "--out", tmp_path / "out")
    assert status == 1
    with pytest.raises(stamp.StampError) as e:
        stamp.Problem.from_toml(bad).solve(quiet=True)
    # exactly what `stamp run` prints after "error: "
    assert "error: " + str(e.value) + "\n" == err
    # the dict: the same key and message, naming the dict's keys, not lines of a TOML text
    with open(bad, "rb") as f:
        t = tomllib.load(f)
    m = raised(t, name="bad")
    assert key in m and what in m, m
    assert "column" not in m and " | " not in m, m
    assert key in err and what in err


def test_values_that_are_no_toml_name_their_key():
    t = table()
    t["plate"]["E"] = None
    assert raised(t).startswith("plate.E: None is no value")
    t = table()
    t["punch"][0]["center"] = [0.0, 0.0, object()]
    assert "punch[0].center[2]: expected a number" in raised(t)
    t = table()
    t["plate"][3] = 1.0
    assert "plate: keys are strings" in raised(t)


@pytest.mark.parametrize(
    "mesh, message",
    [
        ({"nodes": np.zeros((4, 4)), "cells": [[0, 1, 2, 3]]}, "mesh.nodes: expected an (n, 2) array"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0, 1, 2, 7]]}, "mesh.cells row 0: node index 7 is out of range (mesh.nodes has 4 rows"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0.0, 1.0, 2.0, 3.0]]}, "mesh.cells: expected whole numbers"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0, 1, 2, -1]]}, "mesh.cells: negative index -1"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0, 1, 2, 3, 0]]}, "mesh.cells: expected an (m, 3 or 4) array, got shape (1, 5)"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]]}, "mesh: give both `nodes`"),
        ({"nodes": [[0, 0, 0], [1, 0, 0], [1, 1, 1], [0, 1, 0]], "cells": [[0, 1, 2, 3]]}, "mesh.nodes row 2: z = 1.0"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, np.nan]], "cells": [[0, 1, 2, 3]]}, "mesh.nodes row 3: coordinates must be finite"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0, 1, 2, 3]], "groups": {"left": {"edges": [0]}}}, "mesh.groups.left: expected one of"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0, 1, 2, 3]], "groups": {"p": {"cells": [3]}}}, "mesh.groups.p.cells row 0: cell index 3 is out of range"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0, 1, 2, 3]], "groups": {"s": {"segments": [0, 1]}}}, "mesh.groups.s.segments: expected an (m, 2) array"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0, 1, 2, 3]], "rectangle": {"x": [0, 1], "y": [0, 1], "n": [1, 1]}}, "mesh: give the mesh as arrays (`nodes`, `cells`) or as `file` or `rectangle`, not both"),
        # the mesh checks of the gmsh reader, with the rows
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1]], "cells": [[0, 1, 2, 3], [1, 2, 5, 4]]}, "inverted"),
        ({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0, 1, 2, 3], [0, 1, 2, 3]]}, "elements 1 and 2 are duplicates"),
    ],
)
def test_bad_mesh_arrays_name_the_array_and_row(mesh, message):
    t = table()
    t["mesh"] = mesh
    m = raised(t)
    assert message in m, m


def test_a_mesh_given_as_arrays_refuses_the_coarse_predictor():
    t = table()
    n = 2
    t["mesh"] = {"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "cells": [[0, 1, 2, 3]]}
    t["solver"]["predictor"] = "coarse"
    assert "solver.predictor: \"coarse\" needs a coarse mesh" in raised(t)


def test_check_reports_without_solving():
    summary, warnings = stamp.Problem.from_toml(SPHERE).check()
    assert "rectangle x = [0, 20]" in summary and isinstance(warnings, list)
    t = table()
    t["boundary"][0]["group"] = "nowhere"
    with pytest.raises(stamp.StampError, match=r"boundary\[0\]\.group: no group named 'nowhere'"):
        stamp.Problem(t).check()


# values that would make a naive recursive walk overflow the stack (SIGSEGV): each runs in a
# child process, so that a crash fails the test instead of killing pytest
NESTED = {
    "deep list": "v = 0\nfor _ in range(10000):\n    v = [v]\nt['plate']['E'] = v",
    "list in itself": "v = [1.0]\nv.append(v)\nt['punch'][0]['center'] = v",
    "dict in itself": "d = {'a': 1}\nd['self'] = d\nt['output'] = d",
    "tolist gives itself": "class A:\n    dtype = 'f8'\n    def tolist(self):\n        return self\nt['plate']['E'] = A()",
    "tolist gives a list of itself": "class A:\n    dtype = 'f8'\n    def tolist(self):\n        return [self]\nt['plate']['E'] = A()",
}


@pytest.mark.parametrize("case", list(NESTED))
def test_values_nested_too_deep_or_in_themselves_are_refused_naming_the_key(case):
    import subprocess
    import sys
    import textwrap

    code = textwrap.dedent(
        f"""
        import sys, tomllib
        import stamp
        sys.setrecursionlimit(100000)
        with open({str(SPHERE)!r}, "rb") as f:
            t = tomllib.load(f)
        """
    ) + NESTED[case] + textwrap.dedent(
        """
        try:
            stamp.Problem(t)
        except stamp.StampError as e:
            print("StampError:", str(e)[:400])
        else:
            print("accepted")
        """
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, f"exit status {p.returncode}: {p.stderr[-2000:]}"
    out = p.stdout.strip()
    expected = {
        "deep list": ("plate.E[0][0]", "nested more than 64 levels deep"),
        "list in itself": ("punch[0].center[1]", "the list contains itself"),
        "dict in itself": ("output.self", "the dict contains itself"),
        "tolist gives itself": ("plate.E", "A.tolist() gave the A itself"),
        "tolist gives a list of itself": ("plate.E[0][0]", "nested more than 64 levels deep"),
    }[case]
    assert out.startswith("StampError: " + expected[0]) and expected[1] in out, out


def test_values_nested_64_levels_deep_pass_the_walk():
    """The limit is the walk's: 64 levels reach the schema, which names the key."""
    t = table()
    v = 1.0
    for _ in range(63):
        v = [v]
    t["plate"]["E"] = v
    m = raised(t)
    assert "plate.E: invalid type: sequence" in m and "nested" not in m, m


@pytest.mark.parametrize(
    "nodes, message",
    [
        (np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=complex), "mesh.nodes: expected real numbers (x1, x2), got an array of complex numbers"),
        ([["0", "0"], ["1", "0"], ["1", "1"], ["0", "1"]], "mesh.nodes: expected real numbers (x1, x2), got an array of strings"),
        (np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=bool), "mesh.nodes: expected real numbers (x1, x2), got an array of bools"),
        ([[0, 0], [1, 0], [1, 1], [0, None]], "mesh.nodes: expected real numbers (x1, x2), got an array of Python objects"),
        (np.zeros((2, 6)), "mesh.nodes: shape (2, n) with n = 6: expected (n, 2) (or (n, 3) with z = 0); transposed?"),
    ],
)
def test_mesh_nodes_are_real_numbers_in_rows(nodes, message):
    t = table()
    t["mesh"] = {"nodes": nodes, "cells": [[0, 1, 2, 3]]}
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning: refused before numpy drops anything
        m = raised(t)
    assert message in m, m


def test_nodes_with_a_zero_z_column_are_taken():
    """As documented (help(stamp.Problem), docs/python.md): (n, 3) with z = 0 is the (n, 2) mesh."""
    from test_dict import rectangle_groups

    xy, cells = square_grid(10)
    xy *= 2.0
    t = table()
    t["mesh"] = {"nodes": xy, "cells": cells, "groups": rectangle_groups(xy, 10)}
    want = stamp.Problem(t).check()
    t["mesh"] = {"nodes": np.hstack([xy, np.zeros((len(xy), 1))]), "cells": cells, "groups": rectangle_groups(xy, 10)}
    assert stamp.Problem(t).check() == want


def test_transposed_cells_are_named_as_such():
    xy, cells = square_grid(3)
    t = table()
    t["mesh"] = {"nodes": xy, "cells": cells.T}
    m = raised(t)
    assert "mesh.cells: shape (4, m) with m = 9: expected (m, 4) or (m, 3); transposed?" in m, m
    # four cells transposed have a valid shape: the mesh's error says what it may be
    xy, cells = square_grid(2)
    t["mesh"] = {"nodes": xy, "cells": cells.T}
    m = raised(t)
    assert "element 1" in m and "mesh.cells has shape (4, 4), also that of 4 cells given transposed" in m, m


def square_grid(n):
    """An n x n grid of unit squares: (nodes, cells)."""
    xy = np.array([[i, j] for j in range(n + 1) for i in range(n + 1)], dtype=float)
    idx = lambda i, j: j * (n + 1) + i
    cells = np.array([[idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)] for j in range(n) for i in range(n)])
    return xy, cells


def test_a_group_named_like_a_gmsh_number_is_refused_not_dropped():
    xy, cells = square_grid(2)
    t = table()
    t["mesh"] = {"nodes": xy, "cells": cells, "groups": {"#1": {"nodes": [0]}}}
    m = raised(t)
    assert "mesh.groups.#1: a group's name cannot start with '#'" in m, m


def test_a_plasticity_dict_with_a_bad_key_is_refused_naming_it():
    t = table()
    del t["plate"]["E"], t["plate"]["nu"]
    t["plate"]["material"] = "steel"
    t["plate"]["surfaces"] = 3
    t["material"] = [{"name": "steel", "E": 2.1e5, "nu": 0.3, "plasticity": {"yield": 250.0, "K": 500.0}}]
    assert 'material[0].plasticity.K: does not belong to hardening = "linear"' in raised(t)
    t["material"][0]["plasticity"] = {"hardening": "swift", "K": 530.0, "n": 0.25}
    assert "material[0].plasticity: missing `e0`" in raised(t)
    t["plate"]["surfaces"] = 2
    t["material"][0]["plasticity"] = {"yield": 250.0}
    assert "plate.surfaces" in raised(t)
