"""stamp: elastic plates pressed by rigid punches (Kulikov & Plotnikova's mixed plate), from Python.

The problem is the problem file's table: read it from TOML with :meth:`Problem.from_toml`, or
give the same table as a dict to :class:`Problem` (every key of docs/problem-file.md works, with
the same checks and messages; the mesh may also be given as numpy arrays). :meth:`Problem.solve`
returns a :class:`Result` whose arrays are numpy arrays.

    >>> import stamp
    >>> r = stamp.Problem.from_toml("meshes/sphere-ss.toml").solve()
    >>> r.history["sphere_force"][-1]

Errors in a problem, its mesh or its solve raise :class:`StampError` (a ``ValueError``) with the
message the ``stamp`` program prints.
"""

import json as _json

import numpy as _np

from . import _stamp
from ._stamp import StampError

__all__ = ["Problem", "Result", "StampError"]

_GROUP_KINDS = ("nodes", "segments", "cells")


def _index_array(value, key, ndim, columns=None):
    """``value`` as an int64 array of ``ndim`` dimensions (``columns`` a set of allowed widths)."""
    try:
        a = _np.asarray(value)
    except Exception as e:  # ragged lists and the like
        raise StampError(f"{key}: expected an array of node or cell indices ({e})") from None
    if a.size == 0 and a.ndim <= ndim:
        a = a.reshape((0,) * (ndim - 1) + ((0,) if ndim == 1 else (min(columns),)))
    if not (_np.issubdtype(a.dtype, _np.integer) or a.size == 0):
        raise StampError(f"{key}: expected whole numbers (indices, 0-based), got an array of {a.dtype}")
    if a.ndim != ndim or (columns is not None and a.shape[1] not in columns):
        if ndim == 2 and a.ndim == 2 and columns is not None and a.shape[0] in columns and a.shape[1] > max(columns):
            want = " or ".join(f"(m, {c})" for c in sorted(columns, reverse=True))
            raise StampError(f"{key}: shape ({a.shape[0]}, m) with m = {a.shape[1]}: expected {want}; transposed? (give {key}.T)")
        want = "a 1-D array" if ndim == 1 else f"an (m, {' or '.join(map(str, sorted(columns)))}) array"
        raise StampError(f"{key}: expected {want}, got shape {a.shape}")
    if a.size and a.min() < 0:
        raise StampError(f"{key}: negative index {a.min()} (indices are 0-based)")
    return _np.ascontiguousarray(a, dtype=_np.int64)


def _mesh_arrays(mesh):
    """Take ``nodes``, ``cells`` and ``groups`` out of the mesh table: (table, nodes, cells, groups)."""
    mesh = dict(mesh)
    nodes, cells, groups = mesh.pop("nodes", None), mesh.pop("cells", None), mesh.pop("groups", None)
    if nodes is None or cells is None:
        raise StampError("mesh: give both `nodes` (an (n, 2) array) and `cells` (an (m, 3) or (m, 4) array)")
    try:
        xy = _np.asarray(nodes)
    except Exception as e:  # ragged lists and the like
        raise StampError(f"mesh.nodes: expected an (n, 2) array of numbers ({e})") from None
    # real numbers only: numpy would drop a complex number's imaginary part with a mere warning,
    # read strings as numbers and bools as 0 and 1
    if xy.size and xy.dtype.kind not in "iuf":
        what = {"b": "bools", "c": "complex numbers", "U": "strings", "S": "bytes", "O": "Python objects"}.get(xy.dtype.kind, str(xy.dtype))
        raise StampError(f"mesh.nodes: expected real numbers (x1, x2), got an array of {what} ({xy.dtype})")
    xy = xy.astype(_np.float64)
    if xy.ndim != 2 or xy.shape[1] not in (2, 3):
        if xy.ndim == 2 and xy.shape[0] in (2, 3) and xy.shape[1] > 3:
            raise StampError(f"mesh.nodes: shape ({xy.shape[0]}, n) with n = {xy.shape[1]}: expected (n, 2) (or (n, 3) with z = 0); transposed? (give mesh.nodes.T)")
        raise StampError(f"mesh.nodes: expected an (n, 2) array (or (n, 3) with z = 0), got shape {xy.shape}")
    if xy.shape[1] == 3:
        if _np.any(xy[:, 2] != 0):
            row = int(_np.flatnonzero(xy[:, 2] != 0)[0])
            raise StampError(f"mesh.nodes row {row}: z = {xy[row, 2]}: the plate lies in the x1-x2 plane (z = 0 everywhere)")
        xy = xy[:, :2]
    if not _np.all(_np.isfinite(xy)):
        row = int(_np.flatnonzero(~_np.isfinite(xy).all(axis=1))[0])
        raise StampError(f"mesh.nodes row {row}: coordinates must be finite, got {xy[row].tolist()}")
    quads = _index_array(cells, "mesh.cells", 2, {3, 4})
    listed = []
    if groups is not None:
        if not isinstance(groups, dict):
            raise StampError(f"mesh.groups: expected a dict of groups, got {type(groups).__name__}")
        for name, g in groups.items():
            key = f"mesh.groups.{name}"
            if not isinstance(name, str) or not name:
                raise StampError(f"mesh.groups: a group's name is a non-empty string, got {name!r}")
            if not isinstance(g, dict) or len(g) != 1 or next(iter(g)) not in _GROUP_KINDS:
                raise StampError(f"{key}: expected one of {{'nodes': indices}}, {{'segments': (k, 2) indices}} or {{'cells': indices}}, got {g!r:.80}")
            kind, value = next(iter(g.items()))
            if kind == "segments":
                v = _index_array(value, f"{key}.segments", 2, {2}).ravel()
            else:
                v = _index_array(value, f"{key}.{kind}", 1)
            listed.append((name, kind, v))
    return mesh, _np.ascontiguousarray(xy), quads, listed


class Problem:
    """A problem: the plate, its mesh, supports, loads, punches and solver settings.

    ``Problem(table, name="problem")`` builds it from a dict with the problem file's keys (see
    docs/problem-file.md: ``mesh``, ``plate``, ``boundary``, ``load``, ``punch``, ``solver``,
    ``output``, ``units``, ``title``); the dict is turned into the same TOML table and checked by
    the same code, so a bad value raises :class:`StampError` with the message ``stamp run`` gives
    for it, naming the key (``in the table: plate.nu: ...``, no line numbers). Values may be numbers,
    strings, bools, lists, tuples, dicts and numpy arrays or scalars.

    The mesh is ``{"file": "plate.msh"}`` (a gmsh file, relative to the working directory),
    ``{"rectangle": {...}}``, or arrays::

        {"nodes": xy,            # (n, 2) float: x1, x2 (an (n, 3) array with z = 0 is taken too)
         "cells": quads,         # (m, 4) or (m, 3) int: node indices, 0-based
         "groups": {"edge": {"nodes": ids},          # a point group (supports, point loads)
                    "side": {"segments": pairs},     # a curve group: (k, 2) node pairs (line loads)
                    "plate": {"cells": ids}}}        # a surface group (pressures, punch zones)

    Coordinates are real numbers (complex numbers, strings and bools are refused, not converted);
    a group's name cannot start with ``#`` (the key of a gmsh group by number). Triangles are cut
    into three quadrilaterals each, as the gmsh reader cuts them; the mesh is checked as a gmsh
    file is (orientation, overlaps, hanging nodes). Errors about the arrays name the row; an array
    of shape (3 or 4, m) is named as transposed.

    ``name`` names the problem in messages and its output files (``name_0001.vtu``); relative
    paths in the table (a mesh ``file``, an STL punch's ``file``) start in its folder, the working
    directory for a plain name.
    """

    def __init__(self, table, *, name="problem"):
        if isinstance(table, _stamp._Problem):
            self._p = table
            return
        if not isinstance(table, dict):
            raise TypeError(f"Problem(table): expected a dict, got {type(table).__name__}")
        table = dict(table)
        mesh = table.get("mesh")
        if isinstance(mesh, dict) and any(k in mesh for k in ("nodes", "cells", "groups")):
            table["mesh"], nodes, cells, groups = _mesh_arrays(mesh)
            try:
                self._p = _stamp.problem_from_dict(table, str(name), nodes, cells, groups)
            except StampError as e:
                # (3 or 4, 3 or 4): the shape of a few cells given transposed too
                if str(e).startswith("mesh:") and cells.shape[0] in (3, 4) and cells.shape[1] in (3, 4):
                    raise StampError(f"{e} (mesh.cells has shape {cells.shape}, also that of {cells.shape[0]} cells given transposed: if so, give mesh.cells.T)") from None
                raise
        else:
            self._p = _stamp.problem_from_dict(table, str(name))

    @classmethod
    def from_toml(cls, path):
        """Read a problem file (TOML); relative paths in it start at its folder."""
        return cls(_stamp.problem_from_toml(str(path)))

    @property
    def toml(self):
        """The problem as TOML text (for a dict: the table it became)."""
        return self._p.toml

    @property
    def name(self):
        """The path or name that names the problem in messages and output files."""
        return self._p.path

    def check(self):
        """Build the problem and run ``stamp check``'s checks without solving.

        Returns ``(summary, warnings)``: the model's summary text and a list of warnings; an error
        raises :class:`StampError`.
        """
        return self._p.check()

    def solve(self, out=None, quiet=False):
        """Solve the problem and return a :class:`Result`.

        Progress goes to stderr as with ``stamp run`` (a progress bar on a terminal, a line per
        converged step otherwise) and the table of the steps to stdout; ``quiet=True`` prints
        nothing but warnings. The outputs (``stamp run``'s files) are written into ``out`` if
        given, else into a temporary folder removed with the result (see :meth:`Result.write`).

        The GIL is released while solving. Ctrl-C (SIGINT) stops the solve after the Newton
        iteration in progress and raises ``KeyboardInterrupt``; the converged steps stay written
        in ``out``. A failed solve raises :class:`StampError` with the program's message.
        """
        return Result(self._p.solve(None if out is None else str(out), bool(quiet)))

    def __repr__(self):
        return f"<stamp.Problem {self.name!r}>"


class Result:
    """The results of :meth:`Problem.solve`.

    Steps are the written steps (the load targets, or every step with ``output.every_step``), as
    listed in ``summary["steps"]`` and the .pvd; ``step=-1`` is the last. Node and cell arrays
    follow :attr:`nodes` and :attr:`cells`.
    """

    def __init__(self, native):
        self._r = native
        self._summary = None

    @property
    def summary(self):
        """summary.json as a dict (per step in ``summary["steps"]``: the punches' ``reaction``, the
        supports' ``support_reaction`` and, per ``[[boundary]]`` group, ``support_reactions``)."""
        if self._summary is None:
            self._summary = _json.loads(self._r.summary_json)
        return self._summary

    @property
    def history(self):
        """history.csv as a dict of numpy arrays, one per column (``step`` int64, the rest float64):
        ``load_factor``, ``path``, ``<punch>_travel``, ``<punch>_force``, ``<punch>_contact_area``,
        ``<punch>_max_pressure``, ``<point group>_u1/_u2/_u3``, ``<punch>_force_x1/_x2/_x3`` (and
        ``<punch>_dissipation`` with friction) and last, per ``[[boundary]]`` group, its support
        reaction ``<group>_reaction_x1/_x2/_x3``; a row per converged step."""
        lines = self._r.history_csv.strip("\n").split("\n")
        header = lines[0].split(",")
        rows = [line.split(",") for line in lines[1:]]
        out = {}
        for k, name in enumerate(header):
            if name == "step":
                out[name] = _np.array([int(r[k]) for r in rows], dtype=_np.int64)
            else:
                out[name] = _np.array([float(r[k]) for r in rows], dtype=_np.float64)
        return out

    @property
    def nodes(self):
        """(n, 2) float64: the nodes of the mesh solved (the given nodes used by a cell or group,
        in order, then those made by cutting triangles)."""
        return self._r.nodes

    @property
    def cells(self):
        """(m, 4) int64: the quadrilaterals solved, 0-based node indices, counter-clockwise."""
        return self._r.cells

    @property
    def punches(self):
        """The punches' names."""
        return self._r.punches

    @property
    def steps(self):
        """[(step number, load factor)] of the written steps."""
        return self._r.steps

    @property
    def out_dir(self):
        """The folder the outputs were written into (a temporary one unless ``out`` was given)."""
        return self._r.out_dir

    def _step(self, step):
        n = len(self._r.steps)
        i = step + n if step < 0 else step
        if not 0 <= i < n:
            raise IndexError(f"step {step}: the run wrote {n} steps")
        return i

    def displacement(self, step=-1):
        """(n, surfaces, 3) float64: the displacement (v1, v2, v3) of every surface through the
        thickness at every node, bottom face first, top face last (2 surfaces for the paper's
        plate)."""
        return self._r.displacement(self._step(step))

    def contact_pressure(self, name, step=-1):
        """(n,) float64: the contact pressure q_n of punch ``name`` at every node (0 where it
        cannot touch), as in its pressure CSV."""
        return self._r.contact_pressure(name, self._step(step))

    def cell_data(self, step=-1):
        """The .vtu's cell arrays as a dict of float64 arrays: the membrane forces N11, N22, N12,
        moments M11, M22, M12, shear forces Q1, Q2 and T33 at the cell centres ((m,) each); with
        three or more surfaces (or layers) also ``stress_layer<L>_surface<S>``, the six 3D
        stresses s11, s22, s33, s12, s13, s23 at each surface of each layer ((m, 6))."""
        return self._r.cell_data(self._step(step))

    def point_data(self, step=-1):
        """The .vtu's point arrays as a dict: ``displacement`` (mid-surface), ``displacement_bottom``,
        ``displacement_top`` ((n, 3) float64), ``lambda``, ``contact_pressure``, ``gap``, ``active``,
        ``loaded`` ((n,) float64)."""
        return self._r.point_data(self._step(step))

    def to_pyvista(self, step=-1):
        """The plate deformed by its mid-surface displacement as a ``pyvista.UnstructuredGrid`` of
        quadrilaterals, with the .vtu's point and cell arrays (needs ``pip install pyvista``)."""
        try:
            import pyvista as pv
        except ImportError:
            raise ImportError("Result.to_pyvista needs pyvista: pip install pyvista") from None
        i = self._step(step)
        point, cell = self._r.point_data(i), self._r.cell_data(i)
        xyz = _np.zeros((len(self.nodes), 3))
        xyz[:, :2] = self.nodes
        xyz += point["displacement"]
        quads = self.cells
        connectivity = _np.hstack([_np.full((len(quads), 1), 4, dtype=_np.int64), quads]).ravel()
        grid = pv.UnstructuredGrid(connectivity, _np.full(len(quads), pv.CellType.QUAD, dtype=_np.uint8), xyz)
        for k, v in point.items():
            grid.point_data[k] = v
        for k, v in cell.items():
            grid.cell_data[k] = v
        return grid

    def write(self, dir):
        """Write ``stamp run``'s output files (summary.json, history.csv, .pvd/.vtu, CSV, plots) into
        ``dir``; the previous run's files there are removed first, as ``stamp run --out dir`` does.
        Returns the paths written."""
        return [str(p) for p in self._r.write(str(dir))]

    def __repr__(self):
        return f"<stamp.Result {self.summary.get('status')}, {len(self.steps)} steps written>"
