#!/usr/bin/python3
"""3D reference for meshes/laminate-sphere.toml: a simply supported square cross-ply plate
[0/90/90/0] (40 x 40, h = 1, plies of 0.25) pressed by a rigid sphere (R = 200) moved down 0.5.

Run with the Debian Python and GetFEM (apt-get install -y python3-getfem):

    /usr/bin/python3 verification/3d/laminate_sphere_getfem.py --n 12 --nzp 1
    /usr/bin/python3 verification/3d/laminate_sphere_getfem.py --n 12 --nzp 1 --json  # one JSON line

Model (quarter x1, x2 in [0, 20], x3 in [-1/2, 1/2]; a cross-ply stack is symmetric about the
planes x1 = 0 and x2 = 0, so the quarter with symmetry conditions is exact):
* Pagano's ply (J. Compos. Mater. 4 (1970) 20-34): E1/E2 = 25, G12 = G13 = 0.5 E2, G23 = 0.2 E2,
  nu12 = nu13 = nu23 = 0.25, E3 = E2, here E2 = 1e4 (--e2). Each ply's orthotropic stiffness
  C = inverse of the compliance in the ply's axes (1 along the fibres), turned about x3 by the
  ply's angle: C_ijkl = R_ia R_jb R_kc R_ld C'_abcd, R's columns the ply's axes in x1, x2, x3.
* 3D Saint Venant-Kirchhoff S = C : E (E Green-Lagrange), total Lagrangian, in GetFEM's weak-form
  language: (F (C : E)) : Grad(Test_u), one term per ply on the ply's elements.
* Q2 hexahedra (27 nodes), n x n in the plane, --nzp through each ply.
* Supports as stamp's (and verification/3d/sphere_plate_getfem.py): u1 = 0 on x1 = 0, u2 = 0 on
  x2 = 0, u3 = 0 on the whole faces x1 = 20 and x2 = 20, by Lagrange multipliers on the traces.
* Frictionless contact of the top face with the rigid sphere, centre (0, 0, 200.5 - d), radius
  200, exact gap g = |X + u - C| - R, penalty p = kp neg_part(g) at the Gauss points of the top
  face (--penalty kp, default 1e6).
* Newton (GetFEM's, MUMPS) on the travel d = 0.1, 0.2, ..., 0.5, started from a linear
  extrapolation of the last two converged states.

Prints per travel the punch force on the quarter (stamp's `force` of history.csv), the centre
deflection u3(0, 0, 0), the contact radius on the x1 axis; then, at the last travel, for each
probe point (x1, x2) of --probe (default 0,0 1.25,0.25 0.25,1.25,
those of meshes/laminate-sphere.toml) the 3D fields through the thickness at the
rows of stamp's [[output.thickness_probe]] (points_per_layer evenly spaced in each ply, faces
included, one row per ply at an interface): x3, layer, u1, u2, u3, s11, s22, s33, s12, s13, s23
(second Piola-Kirchhoff stresses in x1, x2, x3, from each ply's law and the strains of the
element of that ply, as stamp writes them). --json prints one JSON object instead.
Cost on 2 shared cores (load 4 to 6): n = 8 (8406 unknowns) 111 s, n = 12 (17766) 368 s,
n = 16 (30582) 633 s, n = 20 (46854) 812 s. verification/3d/laminate_compare.py puts the runs beside stamp's.
"""
import argparse
import json
import sys
import time

import numpy as np
import getfem as gf

gf.util_trace_level(0)

H, A, R, Z0 = 1.0, 20.0, 200.0, 200.5
ANGLES = [0.0, 90.0, 90.0, 0.0]          # from the bottom up
TRAVELS = [0.1, 0.2, 0.3, 0.4, 0.5]


def parse():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=12, help="elements along each in-plane side of the quarter")
    ap.add_argument("--nzp", type=int, default=1, help="elements through each ply")
    ap.add_argument("--grade", type=float, default=1.0,
                    help="in-plane grading: spacing at the centre / mean spacing (1 = uniform)")
    ap.add_argument("--e2", type=float, default=1.0e4, help="the ply's E2")
    ap.add_argument("--penalty", type=float, default=1e6, help="contact penalty kp")
    ap.add_argument("--tol", type=float, default=1e-6, help="Newton: absolute residual norm")
    ap.add_argument("--probe", nargs="*", default=["0,0", "1.25,0.25", "0.25,1.25"],
                    help="points x1,x2 of the fields through the thickness")
    ap.add_argument("--points-per-layer", type=int, default=9)
    ap.add_argument("--json", action="store_true")
    return ap.parse_args()


def graded(n, g):
    """n + 1 points on [0, A], spacing g * A / n at 0 growing linearly (g = 1: uniform)."""
    s = np.linspace(0.0, 1.0, n + 1)
    return A * (g * s + (1.0 - g) * s * s)


def ply_stiffness(e2, angle_deg):
    """The 3 x 3 x 3 x 3 stiffness of Pagano's ply turned by angle about x3."""
    e1, e3 = 25.0 * e2, e2
    g12, g13, g23 = 0.5 * e2, 0.5 * e2, 0.2 * e2
    n12 = n13 = n23 = 0.25
    # Voigt order 11, 22, 33, 23, 13, 12 with engineering shears
    s = np.zeros((6, 6))
    s[:3, :3] = [[1 / e1, -n12 / e1, -n13 / e1],
                 [-n12 / e1, 1 / e2, -n23 / e2],
                 [-n13 / e1, -n23 / e2, 1 / e3]]
    s[3, 3], s[4, 4], s[5, 5] = 1 / g23, 1 / g13, 1 / g12
    cv = np.linalg.inv(s)
    pair = {(0, 0): 0, (1, 1): 1, (2, 2): 2, (1, 2): 3, (2, 1): 3, (0, 2): 4, (2, 0): 4,
            (0, 1): 5, (1, 0): 5}
    c = np.zeros((3, 3, 3, 3))
    for i in range(3):
        for j in range(3):
            for k in range(3):
                for l in range(3):
                    c[i, j, k, l] = cv[pair[(i, j)], pair[(k, l)]]
    t = np.radians(angle_deg)
    rot = np.array([[np.cos(t), -np.sin(t), 0.0], [np.sin(t), np.cos(t), 0.0], [0.0, 0.0, 1.0]])
    return np.einsum("ia,jb,kc,ld,abcd->ijkl", rot, rot, rot, rot, c)


def main():
    a = parse()
    t0 = time.time()
    nply = len(ANGLES)
    tp = H / nply
    nz = nply * a.nzp
    xs = graded(a.n, a.grade)
    m = gf.Mesh("cartesian", xs, xs, np.linspace(-H / 2, H / 2, nz + 1))
    X0, Y0, XA, TOP = 1, 2, 3, 5
    m.set_region(X0, m.outer_faces_with_direction([-1.0, 0.0, 0.0], 0.01))
    m.set_region(Y0, m.outer_faces_with_direction([0.0, -1.0, 0.0], 0.01))
    m.set_region(XA, np.hstack([m.outer_faces_with_direction([1.0, 0.0, 0.0], 0.01),
                                m.outer_faces_with_direction([0.0, 1.0, 0.0], 0.01)]))
    m.set_region(TOP, m.outer_faces_with_direction([0.0, 0.0, 1.0], 0.01))
    eps = 1e-6 * tp
    for k in range(nply):
        z0 = -H / 2 + k * tp
        cvs = m.convexes_in_box([-1.0, -1.0, z0 - eps], [A + 1.0, A + 1.0, z0 + tp + eps])
        m.set_region(10 + k, np.array(cvs, dtype=int).reshape(1, -1))

    fem_u = gf.Fem("FEM_QK(3,2)")
    mfu = gf.MeshFem(m, 3)
    mfu.set_fem(fem_u)
    mfs = gf.MeshFem(m, 1)
    mfs.set_fem(fem_u)
    mim = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(3,5)"))
    mimc = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(3,7)"))

    md = gf.Model("real")
    md.add_fem_variable("u", mfu)
    cs = [ply_stiffness(a.e2, ang) for ang in ANGLES]
    md.add_macro("F", "(Id(3)+Grad_u)")
    md.add_macro("EE", "((Grad_u+Grad_u'+Grad_u'*Grad_u)/2)")
    for k in range(nply):
        md.add_initialized_data("C%d" % k, cs[k].flatten(order="F"), [3, 3, 3, 3])
        md.add_nonlinear_term(mim, "(F*(C%d:EE)):Grad_Test_u" % k, 10 + k)
    for name, comp, reg in (("l1", 1, X0), ("l2", 2, Y0), ("l3", 3, XA)):
        md.add_filtered_fem_variable(name, mfs, reg)
        md.add_linear_term(mim, "%s*Test_u(%d) + u(%d)*Test_%s" % (name, comp, comp, name), reg)
    md.add_initialized_data("C", [0.0, 0.0, Z0])
    md.add_initialized_data("R", [R])
    md.add_initialized_data("kp", [a.penalty])
    md.add_macro("gap", "(Norm(X+u-C)-R)")
    md.add_macro("p", "(kp*neg_part(gap))")
    md.add_nonlinear_term(mimc, "-p*Normalized(X+u-C).Test_u", TOP)

    nunk = md.nbdof()
    rows = []
    iters = 0
    u_prev = md.variable("u")
    for k, d in enumerate(TRAVELS):
        md.set_variable("C", [0.0, 0.0, Z0 - d])
        if k > 0:
            u_now = md.variable("u")
            md.set_variable("u", 2.0 * u_now - u_prev)
            u_prev = u_now
        it, conv = md.solve("max_res", a.tol, "max_iter", 60, "lsearch", "simplest")
        iters += it
        if not conv:
            print("Newton did not converge at travel %g" % d, file=sys.stderr)
            sys.exit(2)
        force = -gf.asm_generic(mimc, 0, "p*Normalized(X+u-C)(3)", TOP, md)
        w0 = md.interpolation("u(3)", np.array([[0.0, 0.0, 0.0]]).T, m)
        xa = np.linspace(0.0, A * 0.75, 3001)
        ga = md.interpolation("gap", np.vstack([xa, 0 * xa, H / 2 + 0 * xa]), m)
        cr = float(xa[np.nonzero(ga < 0)[0].max()]) if (ga < 0).any() else 0.0
        rows.append({"travel": d, "force": float(force), "w_mid": float(w0[0]), "contact_radius": cr})

    # fields through the thickness at the last travel, in the rows of stamp's thickness probe
    probes = {}
    npl = a.points_per_layer
    for spec in a.probe:
        x1, x2 = (float(v) for v in spec.split(","))
        x1c, x2c = min(max(x1, 1e-9), A - 1e-9), min(max(x2, 1e-9), A - 1e-9)
        table = []
        for k in range(nply):
            z0 = -H / 2 + k * tp
            zs = np.linspace(z0, z0 + tp, npl)
            zin = np.clip(zs, z0 + 1e-7 * tp, z0 + tp - 1e-7 * tp)   # inside ply k's elements
            pts = np.vstack([x1c + 0 * zs, x2c + 0 * zs, zin])
            uu = np.array([md.interpolation("u(%d)" % (c + 1), pts, m) for c in range(3)]).T
            ee = np.array([md.interpolation("EE(%d,%d)" % (i + 1, j + 1), pts, m)
                           for i in range(3) for j in range(3)]).T.reshape(-1, 3, 3)
            ss = np.einsum("ijkl,pkl->pij", cs[k], ee)
            for q in range(npl):
                s = ss[q]
                table.append([float(zs[q]), k] + [float(v) for v in uu[q]] +
                             [float(s[0, 0]), float(s[1, 1]), float(s[2, 2]), float(s[0, 1]),
                              float(s[0, 2]), float(s[1, 2])])
        probes[spec] = table

    out = {"n": a.n, "nzp": a.nzp, "grade": a.grade, "e2": a.e2, "penalty": a.penalty, "unknowns": int(nunk),
           "newton": int(iters), "time": time.time() - t0, "steps": rows, "probes": probes}
    if a.json:
        print(json.dumps(out))
        return
    print("3D cross-ply [0/90/90/0], %d x %d x %d Q2 elements, %d unknowns" % (a.n, a.n, nz, nunk))
    print("  travel      force (quarter)   w(0,0,0)     contact radius")
    for r_ in rows:
        print("  %6.2f  %18.6f  %11.7f  %8.4f" % (r_["travel"], r_["force"], r_["w_mid"],
                                                r_["contact_radius"]))
    for spec, table in probes.items():
        print("  probe (%s) at travel %g:" % (spec, TRAVELS[-1]))
        print("  %9s %5s %11s %11s %11s %11s %11s %11s %11s %11s %11s" %
              ("x3", "layer", "u1", "u2", "u3", "s11", "s22", "s33", "s12", "s13", "s23"))
        for row in table:
            print("  %9.5f %5d " % (row[0], row[1]) + " ".join("%11.4e" % v for v in row[2:]))
    print("  Newton iterations %d, wall time %.1f s" % (iters, out["time"]))


if __name__ == "__main__":
    main()
