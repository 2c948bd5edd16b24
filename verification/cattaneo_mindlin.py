#!/usr/bin/env python3
"""Cattaneo-Mindlin partial slip: stamp's verification/cattaneo_mindlin.toml against the 3D model
verification/3d/cattaneo_mindlin_getfem.py and against Mindlin's half-space solution.

    python3 verification/cattaneo_mindlin.py mesh [--hf 0.25]     # writes verification/cattaneo_mindlin.msh
    stamp run verification/cattaneo_mindlin.toml                  # -> verification/cattaneo_mindlin-out/
    /usr/bin/python3 verification/3d/cattaneo_mindlin_getfem.py --json > cm3d.json
    python3 verification/cattaneo_mindlin.py compare verification/cattaneo_mindlin-out cm3d.json
    python3 verification/cattaneo_mindlin.py mindlin verification/cattaneo_mindlin-out

`mesh` writes the plate's graded quadrilateral mesh (gmsh MSH 4.1, ASCII): x1 in [-10, 10],
x2 in [0, 10], spacing hf up to 1.5 from the contact's centre along each axis, then growing by 1.5
per cell; groups `sym` (the curve x2 = 0), `plate` (every cell) and `center` (the node at 0, 0).

`compare` reads stamp's history.csv (sphere_force_x1, sphere_force_x3) and the .vtu of every step
(sphere_state: 0 open, 1 stick, 2 slip, and the nodes' tributary areas from the cells; forces and
areas of the half model doubled), and the 3D
model's JSON, and prints per step P, Q and the contact radius a = sqrt(A_c / pi) of both (the half
model's areas doubled), their differences, and c/a = sqrt(A_stick / A_c) of both against
Mindlin's (1 - Q / (mu P))^(1/3) with the Q / (mu P) of each model.
"""
import argparse
import base64
import csv
import glob
import json
import os
import re
import struct
import sys
import zlib

import numpy as np

L, MU_F, DEPTH, TRAVEL = 10.0, 0.3, 0.01, 0.0025  # the path of cattaneo_mindlin.toml


def graded(hf, fine, ratio, length):
    """The same grading as verification/3d/cattaneo_mindlin_getfem.py's."""
    pts = [0.0]
    step = hf
    while pts[-1] < length - 1e-12:
        if pts[-1] >= fine - 1e-12:
            step *= ratio
        nxt = pts[-1] + step
        if nxt > length - 0.5 * step:
            nxt = length
        pts.append(nxt)
    return np.array(pts)


def write_mesh(path, hf, fine, ratio):
    xp = graded(hf, fine, ratio, L)
    xs = np.concatenate([-xp[:0:-1], xp])
    ys = xp
    nx, ny = len(xs), len(ys)
    tag = lambda i, j: 1 + i + nx * j  # noqa: E731
    icen = int(np.argmin(np.abs(xs)))
    lines = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat",
             "$PhysicalNames", "3", '0 3 "center"', '1 1 "sym"', '2 2 "plate"', "$EndPhysicalNames",
             "$Entities", "1 1 1 0",
             "1 0 0 0 1 3",
             "1 %.17g 0 0 %.17g 0 0 1 1 0" % (xs[0], xs[-1]),
             "1 %.17g 0 0 %.17g %.17g 0 1 2 0" % (xs[0], xs[-1], ys[-1]),
             "$EndEntities"]
    n = nx * ny
    lines += ["$Nodes", "1 %d 1 %d" % (n, n), "2 1 0 %d" % n]
    lines += [str(k) for k in range(1, n + 1)]
    lines += ["%.17g %.17g 0" % (xs[i], ys[j]) for j in range(ny) for i in range(nx)]
    lines += ["$EndNodes"]
    quads = [(tag(i, j), tag(i + 1, j), tag(i + 1, j + 1), tag(i, j + 1))
             for j in range(ny - 1) for i in range(nx - 1)]
    segs = [(tag(i, 0), tag(i + 1, 0)) for i in range(nx - 1)]
    ne = len(quads) + len(segs) + 1
    lines += ["$Elements", "3 %d 1 %d" % (ne, ne), "0 1 15 1", "1 %d" % tag(icen, 0),
              "1 1 1 %d" % len(segs)]
    e = 2
    for s in segs:
        lines.append("%d %d %d" % (e, *s))
        e += 1
    lines.append("2 1 3 %d" % len(quads))
    for q in quads:
        lines.append("%d %d %d %d %d" % (e, *q))
        e += 1
    lines += ["$EndElements"]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("%s: %d x %d cells, %d nodes, smallest cell %g" % (path, nx - 1, ny - 1, n, hf))


def _decode(text, dtype):
    """One inline DataArray of VTK XML: raw base64, or a zlib-compressed one (UInt64 header)."""
    text = text.strip()
    first = base64.b64decode(text[:32])
    nblocks = struct.unpack("<Q", first[:8])[0]
    hlen = (3 + nblocks) * 8
    hchars = 4 * ((hlen + 2) // 3)
    header = struct.unpack("<%dQ" % (3 + nblocks), base64.b64decode(text[:hchars])[:hlen])
    data = base64.b64decode(text[hchars:])
    out, pos = [], 0
    for size in header[3:]:
        out.append(zlib.decompress(data[pos:pos + size]))
        pos += size
    return np.frombuffer(b"".join(out), dtype=dtype)


def read_vtu(path, name):
    """Points, quadrilateral connectivity and one point array of a stamp .vtu (zlib, inline)."""
    text = open(path).read()
    types = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4", "UInt8": "u1", "UInt64": "<u8"}

    def array(section, attr):
        sec = re.search(r"<%s>(.*?)</%s>" % (section, section), text, re.S).group(1)
        for m in re.finditer(r"<DataArray([^>]*)>(.*?)</DataArray>", sec, re.S):
            if attr is None or 'Name="%s"' % attr in m.group(1):
                return _decode(m.group(2), types[re.search(r'type="(\w+)"', m.group(1)).group(1)])
        raise KeyError("%s: no %s in <%s>" % (path, attr, section))

    pts = array("Points", None).reshape(-1, 3)
    conn = array("Cells", "connectivity").astype(int)
    offs = array("Cells", "offsets").astype(int)
    return pts, conn, offs, array("PointData", name).astype(float)


def tributary(pts, conn, offs):
    """int N_i dA for bilinear quadrilaterals (one quarter of each cell's area on the rectangles)."""
    w = np.zeros(len(pts))
    start = 0
    for end in offs:
        c = conn[start:end]
        start = end
        x, y = pts[c, 0], pts[c, 1]
        area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
        w[c] += area / len(c)
    return w


def stamp_rows(folder):
    with open(os.path.join(folder, "history.csv")) as f:
        hist = list(csv.DictReader(f))
    vtus = sorted(glob.glob(os.path.join(folder, "*.vtu")))
    vtus = [v for v in vtus if re.search(r"(\d+)\.vtu$", v)]
    vtus.sort(key=lambda v: int(re.search(r"(\d+)\.vtu$", v).group(1)))
    rows = []
    for h, v in zip(hist, vtus):
        pts, conn, offs, st = read_vtu(v, "sphere_state")
        w = tributary(pts, conn, offs)
        ac = 2.0 * w[st > 0.5].sum()
        ast = 2.0 * w[np.abs(st - 1.0) < 0.5].sum()
        on_axis = np.abs(pts[:, 1]) < 1e-12
        xa = pts[on_axis & (st > 0.5), 0]
        xs = pts[on_axis & (np.abs(st - 1.0) < 0.5), 0]
        t = float(h["load_factor"])
        d, s = (DEPTH * t / 0.5, 0.0) if t <= 0.5 else (DEPTH, TRAVEL * (t - 0.5) / 0.5)
        rows.append({"d": d, "s": s, "P": 2.0 * float(h["sphere_force_x3"]), "Q": 2.0 * abs(float(h["sphere_force_x1"])),
                     "a": float(np.sqrt(ac / np.pi)), "c_over_a": float(np.sqrt(ast / ac)) if ac > 0 else 0.0,
                     "a_axis": 0.5 * float(xa.max() - xa.min()) if len(xa) else 0.0,
                     "c_axis": 0.5 * float(xs.max() - xs.min()) if len(xs) else 0.0, "vtu": v})
    return hist, rows


def compare(folder, json_path):
    ref = json.loads(open(json_path).read().strip().splitlines()[-1])
    hist, rows = stamp_rows(folder)
    # the 3D model's steps, each with stamp's step at the same (d, s) (stamp may take more steps)
    key = lambda r: (round(r["d"] / DEPTH, 6), round(r["s"] / TRAVEL, 6))  # noqa: E731
    by_key = {key(r): r for r in rows}
    steps = [g for g in ref["steps"] if key(g) in by_key]
    rows = [by_key[key(g)] for g in steps]
    if not steps:
        sys.exit("no step of stamp's run is at a (d, s) of the 3D model's")
    print("3D: Q2, %s elements, %d unknowns, kp = kt = %g, %.0f s" %
          (ref["elements"], ref["unknowns"], ref["penalty"], ref["time"]))
    print("| d | s | P stamp | P 3D | diff | Q stamp | Q 3D | diff | Q/(mu P) | a stamp | a 3D |"
          " c/a stamp | c/a 3D | Mindlin (1 - Q/(mu P))^(1/3) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r, g in zip(rows, steps):
        qs, qg = r["Q"], g["Q"]
        dq = "%+.2f %%" % (100 * (qs / qg - 1)) if qg > 0 else "-"
        ratio_g = qg / (MU_F * g["P"])
        ratio_s = qs / (MU_F * r["P"])
        mind = "%.3f (3D) / %.3f (stamp)" % ((1 - ratio_g) ** (1 / 3), (1 - ratio_s) ** (1 / 3)) if g["s"] > 0 else "1"
        print("| %.4f | %.4f | %.2f | %.2f | %+.2f %% | %.2f | %.2f | %s | %.3f | %.3f | %.3f | %.3f | %.3f | %s |" %
              (g["d"], g["s"], r["P"], g["P"], 100 * (r["P"] / g["P"] - 1), qs, qg, dq, ratio_g,
               r["a"], g["a"], r["c_over_a"], g["c_over_a"], mind))


def mindlin(folder):
    """stamp's drag against Mindlin's half-space: Q for the travel s with stamp's P and Hertz's
    a = sqrt(R d) = 1, and c/a against (1 - Q / (mu P))^(1/3)."""
    e_mod, nu, a_hertz = 2.1e5, 0.3, 1.0
    g_mod = e_mod / (2 * (1 + nu))
    _, rows = stamp_rows(folder)
    print("| travel s | P | Q stamp | Q / (mu P) | Q Mindlin | stamp / Mindlin | c/a stamp | (1 - Q / (mu P))^(1/3) |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        if r["s"] <= 0:
            continue
        s0 = 3 * MU_F * r["P"] * (2 - nu) / (16 * g_mod * a_hertz)
        q_m = MU_F * r["P"] * (1 - (1 - min(r["s"] / s0, 1.0)) ** 1.5)
        qr = r["Q"] / (MU_F * r["P"])
        print("| %.4f | %.1f | %.1f | %.3f | %.1f | %+.1f %% | %.3f | %.3f |" %
              (r["s"], r["P"], r["Q"], qr, q_m, 100 * (r["Q"] / q_m - 1), r["c_over_a"], max(1 - qr, 0) ** (1 / 3)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    m = sub.add_parser("mesh")
    m.add_argument("--hf", type=float, default=0.25)
    m.add_argument("--fine", type=float, default=1.5)
    m.add_argument("--ratio", type=float, default=1.5)
    m.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "cattaneo_mindlin.msh"))
    mi = sub.add_parser("mindlin")
    mi.add_argument("folder")
    c = sub.add_parser("compare")
    c.add_argument("folder")
    c.add_argument("json")
    a = ap.parse_args()
    if a.cmd == "mesh":
        write_mesh(a.out, a.hf, a.fine, a.ratio)
    elif a.cmd == "mindlin":
        mindlin(a.folder)
    else:
        compare(a.folder, a.json)


if __name__ == "__main__":
    main()
