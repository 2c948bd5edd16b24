#!/usr/bin/env python3
"""Independent check of a .vtu file written by stamp, with VTK's own XML reader (what ParaView uses).

Usage: python3 tests/check_vtu.py FILE.vtu [EXPECTED.json]

Prints a JSON summary: number of points and cells, the cell types, the bounds, and for every point
and cell array its number of components, number of tuples, sum and sum of absolute values (a
checksum). With EXPECTED.json (the same layout, any subset of keys), asserts that the file matches
(counts exactly, sums to a relative 1e-12) and exits with status 1 and a message if it does not.
"""
import json
import math
import sys

import vtk


def arrays(data):
    out = {}
    for i in range(data.GetNumberOfArrays()):
        a = data.GetArray(i)
        v = [a.GetComponent(t, c) for t in range(a.GetNumberOfTuples()) for c in range(a.GetNumberOfComponents())]
        out[a.GetName()] = {
            "components": a.GetNumberOfComponents(),
            "tuples": a.GetNumberOfTuples(),
            "sum": math.fsum(v),
            "abs_sum": math.fsum(abs(x) for x in v),
        }
    return out


def summary(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0:
        raise SystemExit(f"{path}: VTK reader error code {reader.GetErrorCode()}")
    grid = reader.GetOutput()
    types = sorted({grid.GetCellType(i) for i in range(grid.GetNumberOfCells())})
    pts = [x for i in range(grid.GetNumberOfPoints()) for x in grid.GetPoint(i)]
    conn = []
    for c in range(grid.GetNumberOfCells()):
        ids = grid.GetCell(c).GetPointIds()
        conn.extend(ids.GetId(k) for k in range(ids.GetNumberOfIds()))
    return {
        "points": grid.GetNumberOfPoints(),
        "cells": grid.GetNumberOfCells(),
        "cell_types": types,
        "bounds": list(grid.GetBounds()),
        "points_sum": math.fsum(pts),
        "connectivity_sum": int(sum(conn)),
        "point_arrays": arrays(grid.GetPointData()),
        "cell_arrays": arrays(grid.GetCellData()),
    }


def close(a, b):
    return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12)


def compare(got, want, where="file"):
    errors = []
    for key, w in want.items():
        if key not in got:
            errors.append(f"{where}: missing {key!r}")
            continue
        g = got[key]
        if isinstance(w, dict):
            errors += compare(g, w, f"{where}.{key}")
        elif isinstance(w, float):
            if not close(g, w):
                errors.append(f"{where}.{key}: {g!r} != expected {w!r}")
        elif g != w:
            errors.append(f"{where}.{key}: {g!r} != expected {w!r}")
    return errors


def main():
    if len(sys.argv) not in (2, 3):
        raise SystemExit(__doc__)
    got = summary(sys.argv[1])
    print(json.dumps(got, indent=1, sort_keys=True))
    if len(sys.argv) == 3:
        with open(sys.argv[2]) as f:
            want = json.load(f)
        errors = compare(got, want)
        if errors:
            print("\n".join(errors), file=sys.stderr)
            sys.exit(1)


if __name__ == "__main__":
    main()
