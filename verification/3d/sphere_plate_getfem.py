#!/usr/bin/python3
"""3D reference for meshes/sphere-ss-displacement.toml: a simply supported square plate
(40 x 40, h = 1, E = 2.1e5, nu = 0.3) pressed by a rigid sphere (R = 200) moved down 0.9.

Run with the Debian Python and GetFEM (apt-get install -y python3-getfem):

    /usr/bin/python3 verification/3d/sphere_plate_getfem.py --n 20 --nz 2
    /usr/bin/python3 verification/3d/sphere_plate_getfem.py --n 20 --nz 2 --json   # one JSON line

Model (quarter x1, x2 in [0, 20], x3 in [-1/2, 1/2]):
* 3D Saint Venant-Kirchhoff (S = lambda tr(E) I + 2 mu E, E Green-Lagrange), total Lagrangian,
  written out in GetFEM's generic weak-form language: (F S) : Grad(Test_u).
* Q2 hexahedra (27 nodes), n x n in the plane, nz through the thickness (--kin q2), or Q2 in the
  plane times P1 in x3 with one element through the thickness (--kin lin: a displacement exactly
  linear through the thickness, the plate's kinematics).
* --law svk (default) | plate: `plate` is the plate's material of SPEC section 2 written in 3D:
  in-plane plane-stress constants with nothing of E33 in S_ab, S_a3 = k 2 G E_a3 (k = --kshear,
  default 1), S_33 = lambda (E11 + E22) + (lambda + 2 G) E33 (not symmetric).
* Boundary conditions as stamp's (problem/src/model/build.rs): symmetry_x1 holds v1- and v1+, i.e. the
  whole fibre, so u1 = 0 on the face x1 = 0; symmetry_x2: u2 = 0 on x2 = 0; simply_supported holds
  v3- and v3+, i.e. u3 = 0 on the whole lateral faces x1 = 20 and x2 = 20 (in-plane motions and
  the fibre's rotation stay free). All by Lagrange multipliers on the face traces (nodal, exact).
* Frictionless contact of the top face x3 = 1/2 with the rigid sphere, centre (0, 0, 200.5 - d),
  radius 200, exact gap g = |X + u - C| - R, by a penalty: the pressure p = kp * neg_part(g) at
  the Gauss points (4 x 4) of the top face (--penalty kp, default 1e6; measured on 12 x 12 x 2:
  kp = 1e7 moves the force by +0.01 %, so the penalty error is ~1e-4 of the force).
  --penalty 0 gives an Alart-Curnier augmented Lagrangian with a Q1 pressure field instead (no
  penalty error), but GetFEM's Newton stalls on it at first contact: kept for reference only.
* Newton (GetFEM's, MUMPS) on the travel d in --sub substeps per 0.18 (default 1), started
  from a linear extrapolation of the last two converged states.

Prints per travel 0.18, 0.36, 0.54, 0.72, 0.90 the punch force on the quarter (the integral of p
times the sphere's normal along x3 over the top face, as stamp's `force` of history.csv), the centre deflection (u3 at the mid-plane point (0, 0, 0), and the
mean of the top and bottom face values (stamp's (v3- + v3+)/2)), the contact radius on the x1 axis,
then the number of unknowns (displacements + support multipliers), the Newton iterations and the
wall time. --json prints one JSON object instead; --profile adds p(x1) on the top face along x2 = 0
at the last step. Cost on 2 shared cores: 12 x 12 x 2 (9870 unknowns) ~1 min, 24 x 24 x 2 (36990)
~6 min. Mesh convergence of the force is about l^1.4 (l = 20 / n).
"""
import argparse
import json
import sys
import time

import numpy as np
import getfem as gf

gf.util_trace_level(0)

E_MOD, NU, H, A, R, Z0 = 2.1e5, 0.3, 1.0, 20.0, 200.0, 200.5
TRAVELS = [0.18, 0.36, 0.54, 0.72, 0.90]


def parse():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=10, help="elements along each in-plane side of the quarter")
    ap.add_argument("--nz", type=int, default=2, help="elements through the thickness (--kin q2)")
    ap.add_argument("--kin", choices=["q2", "lin"], default="q2")
    ap.add_argument("--law", choices=["svk", "plate"], default="svk")
    ap.add_argument("--kshear", type=float, default=1.0, help="shear factor of --law plate")
    ap.add_argument("--pdeg", type=int, default=1, help="degree of the contact pressure field")
    ap.add_argument("--sub", type=int, default=1, help="Newton load substeps per 0.18 of travel")
    ap.add_argument("--grade", type=float, default=1.0,
                    help="in-plane grading: spacing at the centre / mean spacing (1 = uniform)")
    ap.add_argument("--r", type=float, default=0.0, help="augmentation parameter (0: E / l_e)")
    ap.add_argument("--lsearch", default="simplest")
    ap.add_argument("--penalty", type=float, default=1e6,
                    help="pure penalty r * neg_part(gap) instead of the multiplier (0: off)")
    ap.add_argument("--tol", type=float, default=1e-6, help="Newton: absolute residual norm")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--profile", action="store_true", help="print p(x1) on the top face at the last step")
    return ap.parse_args()


def graded(n, g):
    """n + 1 points on [0, A], spacing g * A / n at 0 growing linearly (g = 1: uniform)."""
    s = np.linspace(0.0, 1.0, n + 1)
    return A * (g * s + (1.0 - g) * s * s)


def main():
    a = parse()
    t0 = time.time()
    nz = 1 if a.kin == "lin" else a.nz
    xs = graded(a.n, a.grade)
    m = gf.Mesh("cartesian", xs, xs, np.linspace(-H / 2, H / 2, nz + 1))
    # regions
    X0, Y0, XA, TOP = 1, 2, 3, 5
    m.set_region(X0, m.outer_faces_with_direction([-1.0, 0.0, 0.0], 0.01))
    m.set_region(Y0, m.outer_faces_with_direction([0.0, -1.0, 0.0], 0.01))
    # the two supported faces form ONE region: separate multipliers would hold u3 twice on the
    # corner edge x1 = x2 = 20 (a singular system)
    m.set_region(XA, np.hstack([m.outer_faces_with_direction([1.0, 0.0, 0.0], 0.01),
                                m.outer_faces_with_direction([0.0, 1.0, 0.0], 0.01)]))
    m.set_region(TOP, m.outer_faces_with_direction([0.0, 0.0, 1.0], 0.01))

    fem_u = gf.Fem("FEM_QK(3,2)") if a.kin == "q2" else gf.Fem("FEM_PRODUCT(FEM_QK(2,2),FEM_PK(1,1))")
    mfu = gf.MeshFem(m, 3)
    mfu.set_fem(fem_u)
    mfs = gf.MeshFem(m, 1)  # scalar trace space for the support multipliers
    mfs.set_fem(fem_u)
    mfp = gf.MeshFem(m, 1)
    mfp.set_fem(gf.Fem("FEM_QK(3,%d)" % a.pdeg) if a.kin == "q2" or a.pdeg == 1
                else gf.Fem("FEM_PRODUCT(FEM_QK(2,2),FEM_PK(1,1))"))
    mim = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(3,5)"))
    mimc = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(3,7)"))

    md = gf.Model("real")
    md.add_fem_variable("u", mfu)
    lam = E_MOD * NU / ((1 + NU) * (1 - 2 * NU))
    mu = E_MOD / (2 * (1 + NU))
    md.add_initialized_data("lam", [lam])
    md.add_initialized_data("mu", [mu])
    md.add_initialized_data("q12", [NU * E_MOD / (1 - NU * NU)])
    md.add_initialized_data("ks", [a.kshear])
    md.add_initialized_data("Pp", np.diag([1.0, 1.0, 0.0]).flatten(), [3, 3])
    md.add_initialized_data("Q3", np.diag([0.0, 0.0, 1.0]).flatten(), [3, 3])
    md.add_macro("F", "(Id(3)+Grad_u)")
    md.add_macro("EE", "((Grad_u+Grad_u'+Grad_u'*Grad_u)/2)")
    if a.law == "svk":
        md.add_macro("SS", "(lam*Trace(EE)*Id(3)+2*mu*EE)")
    else:
        md.add_macro("T2", "Trace(Pp*EE)")
        md.add_macro("SS", "(Pp*(q12*T2*Id(3)+2*mu*EE)*Pp + ks*2*mu*(Pp*EE*Q3+Q3*EE*Pp)"
                     " + Q3*(lam*T2+(lam+2*mu)*Trace(Q3*EE)))")
    md.add_nonlinear_term(mim, "(F*SS):Grad_Test_u")

    # supports: u1 = 0 on x1 = 0, u2 = 0 on x2 = 0, u3 = 0 on x1 = 20 and x2 = 20
    for name, comp, regs in (("l1", 1, [X0]), ("l2", 2, [Y0]), ("l3", 3, [XA])):
        md.add_filtered_fem_variable(name, mfs, regs[0])
        md.add_linear_term(mim, "%s*Test_u(%d) + u(%d)*Test_%s" % (name, comp, comp, name), regs[0])

    # contact
    if a.penalty == 0:
        md.add_filtered_fem_variable("p", mfp, TOP)
    md.add_initialized_data("C", [0.0, 0.0, Z0])
    md.add_initialized_data("R", [R])
    le = A / a.n
    md.add_initialized_data("r", [a.r if a.r > 0 else E_MOD / le])
    md.add_macro("gap", "(Norm(X+u-C)-R)")
    if a.penalty == 0:
        md.add_nonlinear_term(mimc, "-p*Normalized(X+u-C).Test_u", TOP)
        md.add_nonlinear_term(mimc, "-(1/r)*(p-pos_part(p-r*gap))*Test_p", TOP)
    else:
        md.add_initialized_data("kp", [a.penalty])
        md.add_macro("p", "(kp*neg_part(gap))")
        md.add_nonlinear_term(mimc, "-p*Normalized(X+u-C).Test_u", TOP)

    nunk = md.nbdof()
    rows = []
    d = 0.0
    nsteps = len(TRAVELS) * a.sub
    iters = 0
    for k in range(1, nsteps + 1):
        d = 0.18 * k / a.sub
        md.set_variable("C", [0.0, 0.0, Z0 - d])
        if k > 1:  # linear predictor from the last two converged states
            u_now = md.variable("u")
            md.set_variable("u", 2.0 * u_now - u_prev)
            u_prev = u_now
        else:
            u_prev = md.variable("u")
        it, conv = md.solve("max_res", a.tol, "max_iter", 60, "lsearch", a.lsearch)
        iters += it
        if not conv:
            print("Newton did not converge at travel %g" % d, file=sys.stderr)
            sys.exit(2)
        if k % a.sub == 0:
            force = gf.asm_generic(mimc, 0, "p*Normalized(X+u-C)(3)", TOP, md) * -1.0
            pts = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -H / 2], [0.0, 0.0, H / 2]]).T
            u3 = md.interpolation("u(3)", pts, m)
            # contact radius on the x1 axis: last point of the top face where p > 0
            xa = np.linspace(0.0, A * 0.75, 3001)
            ga = md.interpolation("gap", np.vstack([xa, 0 * xa, H / 2 + 0 * xa]), m)
            cr = float(xa[np.nonzero(ga < 0)[0].max()]) if (ga < 0).any() else 0.0
            rows.append({"travel": round(d, 10), "force": float(force), "w_mid": float(u3[0]),
                         "w_faces": float(0.5 * (u3[1] + u3[2])), "contact_radius": cr})
    out = {"n": a.n, "nz": nz, "kin": a.kin, "law": a.law, "kshear": a.kshear, "pdeg": a.pdeg,
           "grade": a.grade, "unknowns": int(nunk), "newton": int(iters),
           "time": time.time() - t0, "steps": rows}
    if a.profile:
        xa = np.linspace(0.0, A * 0.75, 601)
        out["profile_x1"] = xa.tolist()
        out["profile_p"] = md.interpolation("p", np.vstack([xa, 0 * xa, H / 2 + 0 * xa]), m).tolist()
    if a.json:
        print(json.dumps(out))
        return
    print("3D %s, kinematics %s, %d x %d x %d elements, %d unknowns" % (a.law, a.kin, a.n, a.n, nz, nunk))
    print("  travel      force (quarter)   w(0,0,0)     (w- + w+)/2   contact radius")
    for r_ in rows:
        print("  %6.2f  %18.6f  %11.7f  %11.7f  %8.4f" % (r_["travel"], r_["force"], r_["w_mid"],
                                                        r_["w_faces"], r_["contact_radius"]))
    print("  Newton iterations %d, wall time %.1f s" % (iters, out["time"]))


if __name__ == "__main__":
    main()
