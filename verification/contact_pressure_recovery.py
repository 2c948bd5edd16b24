#!/usr/bin/env python3
"""The recovered contact pressure against the nodal one, on gmsh triangles (cut into
quadrilaterals) and on rectangles: docs/verification/contact-pressure.md, "The recovered pressure".

    python3 verification/contact_pressure_recovery.py NAME=RUN_DIR ... [--pair TRI=RECT ...]

Each RUN_DIR is the output folder of `stamp run` on a variant of meshes/sphere-ss-full.toml (one
punch, every node a candidate). Its last .vtu is read with VTK: the reference positions (its
points), `contact_pressure` (q, nodal) and `contact_pressure_recovered` (what stamp
wrote). From q and the mesh the script also makes the other recoveries of src/contact/recover.rs
(the consistent L2 projection M p = f over the cells with a loaded node, solved densely here, and
2 or 3 passes of the smoothing) to compare them, and checks that its one-pass smoothing is the
written field.

Per mesh, inside 0.35 and 0.8 of the contact radius a (the largest radius of a loaded node): the
coefficient of variation as the rms deviation from a smooth radial fit (least squares in 1, r^2,
r^4, r^6) over the mean; the lowest value over the mesh over the peak (undershoot); the integral
over the sum of the nodal forces.
Per pair: the relative L2 difference over the disk r < a of the two meshes' fields, sampled on a
grid of spacing 0.05 and interpolated bilinearly in each mesh's cells.
"""
import sys
import glob
import os
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy, numpy_to_vtk

FRACTIONS = (0.35, 0.8)
G = 1 / np.sqrt(3)
GAUSS = [(-G, -G), (G, -G), (G, G), (-G, G)]
XI = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)


def last_vtu(d):
    files = sorted(glob.glob(os.path.join(d, "*_[0-9][0-9][0-9][0-9].vtu")))
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(files[-1])
    r.Update()
    return r.GetOutput()


def cell_masses(x, cells):
    """Consistent mass matrices of the bilinear cells (2 x 2 Gauss points)."""
    m = np.zeros((len(cells), 4, 4))
    xc = x[cells]  # (c, 4, 2)
    for s, t in GAUSS:
        n = 0.25 * (1 + XI[:, 0] * s) * (1 + XI[:, 1] * t)
        dn = np.stack([0.25 * XI[:, 0] * (1 + XI[:, 1] * t), 0.25 * XI[:, 1] * (1 + XI[:, 0] * s)], axis=1)
        j = np.einsum("cad,ae->cde", xc, dn)
        det = j[:, 0, 0] * j[:, 1, 1] - j[:, 0, 1] * j[:, 1, 0]
        m += det[:, None, None] * np.outer(n, n)[None]
    return m


def apply(m, cells, v):
    out = np.zeros_like(v)
    np.add.at(out, cells, np.einsum("cab,cb->ca", m, v[cells]))
    return out


class Run:
    def __init__(self, name, d):
        self.name = name
        g = last_vtu(d)
        self.grid = g
        pd = g.GetPointData()
        self.x = vtk_to_numpy(g.GetPoints().GetData())[:, :2].copy()  # the reference positions
        conn = vtk_to_numpy(g.GetCells().GetConnectivityArray())
        self.cells = conn.reshape(-1, 4)
        self.q = vtk_to_numpy(pd.GetArray("contact_pressure")).copy()
        self.written = vtk_to_numpy(pd.GetArray("contact_pressure_recovered")).copy()
        self.m = cell_masses(self.x, self.cells)
        self.area = apply(self.m, self.cells, np.ones(len(self.x)))
        self.f = self.area * self.q
        self.h = np.sqrt(self.area.sum() / len(self.cells))
        self.r = np.hypot(self.x[:, 0], self.x[:, 1])
        self.a = self.r[self.q > 0].max()
        self.fields = {"nodal": self.q}
        p = self.q
        for k in (1, 2, 3):
            p = apply(self.m, self.cells, p) / self.area
            self.fields[f"smoothing x{k}"] = p
        self.fields["projection"], self.proj_integral = self.projection()
        self.fields["written"] = self.written

    def projection(self):
        zone = np.where((self.f[self.cells] != 0).any(axis=1))[0]
        nodes = np.unique(self.cells[zone])
        local = -np.ones(len(self.x), int)
        local[nodes] = np.arange(len(nodes))
        c = local[self.cells[zone]]
        mz = np.zeros((len(nodes), len(nodes)))
        for a in range(4):
            for b in range(4):
                np.add.at(mz, (c[:, a], c[:, b]), self.m[zone, a, b])
        pz = np.linalg.solve(mz, self.f[nodes])
        p = np.zeros(len(self.x))
        p[nodes] = pz
        return p, (mz @ pz).sum()

    def cv(self, v, frac):
        """The rms deviation of v from its least-squares radial fit (1, r^2, r^4, r^6) over the
        nodes with r < frac * a, over its mean there; and the number of those nodes."""
        inside = self.r < frac * self.a
        r, y = self.r[inside], v[inside]
        basis = np.stack([r**0, r**2, r**4, r**6], axis=1)
        coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
        return np.sqrt(np.mean((y - basis @ coef) ** 2)) / np.mean(y), inside.sum()

    def sample(self, key, pts):
        g = vtk.vtkUnstructuredGrid()
        g.DeepCopy(self.grid)
        p = vtk.vtkPoints()
        p.SetData(numpy_to_vtk(np.c_[self.x, np.zeros(len(self.x))].copy(), deep=True))
        g.SetPoints(p)
        arr = numpy_to_vtk(np.ascontiguousarray(self.fields[key]), deep=True)
        arr.SetName("v")
        g.GetPointData().AddArray(arr)
        src = vtk.vtkPolyData()
        sp = vtk.vtkPoints()
        sp.SetData(numpy_to_vtk(np.c_[pts, np.zeros(len(pts))].copy(), deep=True))
        src.SetPoints(sp)
        probe = vtk.vtkProbeFilter()
        probe.SetInputData(src)
        probe.SetSourceData(g)
        probe.Update()
        return vtk_to_numpy(probe.GetOutput().GetPointData().GetArray("v"))


def main():
    runs, pairs = [], []
    args = sys.argv[1:]
    while args:
        a = args.pop(0)
        if a == "--pair":
            pairs.append(args.pop(0).split("="))
        else:
            n, d = a.split("=")
            runs.append(Run(n, d))
    by = {r.name: r for r in runs}
    keys = ["nodal", "smoothing x1", "smoothing x2", "smoothing x3", "projection"]
    for frac in FRACTIONS:
        print(f"CV (rms deviation from a radial fit over the mean) over r < {frac} a:")
        print()
        print("| mesh | nodes | cell size | force | a | nodes inside | " + " | ".join(keys) + " |")
        print("|" + "---|" * (6 + len(keys)))
        for r in runs:
            cols = [f"{100 * r.cv(r.fields[k], frac)[0]:.1f} %" for k in keys]
            print(f"| {r.name} | {len(r.x)} | {r.h:.3f} | {r.f.sum():.2f} | {r.a:.2f} | {r.cv(r.q, frac)[1]} | " + " | ".join(cols) + " |")
        print()
    print("Lowest value over the peak (undershoot below zero):")
    print()
    print("| mesh | " + " | ".join(keys) + " |")
    print("|" + "---|" * (1 + len(keys)))
    for r in runs:
        print(f"| {r.name} | " + " | ".join(f"{r.fields[k].min() / r.fields[k].max():+.3f}" for k in keys) + " |")
    print()
    print("| mesh | written - smoothing x1 (max abs / max) | smoothing integral sum A p / sum f - 1 | projection 1^T M p / sum f - 1 |")
    print("|---|---|---|---|")
    for r in runs:
        d = np.abs(r.written - r.fields["smoothing x1"]).max() / r.q.max()
        s = (r.area * r.written).sum() / r.f.sum() - 1
        print(f"| {r.name} | {d:.1e} | {s:.1e} | {r.proj_integral / r.f.sum() - 1:.1e} |")
    if pairs:
        print()
        print("| triangles / rectangles | " + " | ".join(f"L2 diff {k}" for k in keys) + " |")
        print("|" + "---|" * (1 + len(keys)))
        for t, q in pairs:
            a, b = by[t], by[q]
            rad = min(a.a, b.a)
            s = np.arange(-rad, rad + 1e-9, 0.05)
            xx, yy = np.meshgrid(s, s)
            pts = np.c_[xx.ravel(), yy.ravel()]
            pts = pts[np.hypot(pts[:, 0], pts[:, 1]) < rad]
            cols = []
            for k in keys:
                va, vb = a.sample(k, pts), b.sample(k, pts)
                cols.append(f"{np.linalg.norm(va - vb) / np.linalg.norm(vb):.3f}")
            print(f"| {t} / {q} | " + " | ".join(cols) + " |")


if __name__ == "__main__":
    main()
