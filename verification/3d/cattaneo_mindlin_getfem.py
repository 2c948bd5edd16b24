#!/usr/bin/python3
"""3D reference for verification/cattaneo_mindlin.toml: Cattaneo-Mindlin partial slip. A thick plate
(half-width L = 10, h = 10, E = 2.1e5, nu = 0.3, bottom face x3 = -5 clamped) is pressed by a rigid
sphere (R = 100) moved down d = 0.01 (Hertz: contact radius a ~ 1, so a/h ~ 0.1), then dragged
along x1 by s = 0.0025, below the sliding limit, with Coulomb friction mu = 0.3 between the two.

Run with the Debian Python and GetFEM (apt-get install -y python3-getfem):

    /usr/bin/python3 verification/3d/cattaneo_mindlin_getfem.py            # the default mesh, a table
    /usr/bin/python3 verification/3d/cattaneo_mindlin_getfem.py --json     # one JSON line

Model (half x1 in [-10, 10], x2 in [0, 10], x3 in [-5, 5]; the drag along x1 keeps the plane
x2 = 0 a plane of symmetry):
* 3D Saint Venant-Kirchhoff (S = lambda tr(E) I + 2 mu E, E Green-Lagrange), total Lagrangian, in
  GetFEM's weak-form language, as verification/3d/sphere_plate_getfem.py.
* Q2 hexahedra (27 nodes) on a tensor mesh graded towards the contact: spacing --hf over
  |x1|, x2 and the depth below the top face up to --fine, then growing by --ratio per element.
* Supports: u = 0 on the bottom face x3 = -5, u2 = 0 on x2 = 0 (symmetry), the sides free;
  multipliers on the face traces (exact).
* Contact of the top face x3 = 5 with the exact sphere, centre C = (s, 0, 5 + R - d), gap
  g = |X + u - C| - R, normal n = (X + u - C) / |X + u - C|, and Coulomb friction, both at the
  Gauss points (4 x 4 per face) in the form stamp uses (docs/design.md, "Friction"): an augmented
  Lagrangian with a return map. Per point a normal multiplier lamn, a tangential one lamt and a
  stick anchor wa (im_data); w = u - (C - C0) is the point's displacement relative to the sphere's
  material point (the sphere translates without turning). Pressure p = pos_part(lamn - kp g),
  trial traction tau_tr = P (lamt - kp (w - wa)), P = I - n n^T, friction traction on the plate
  tau = Ball_projection(tau_tr, mu p) (stick inside the ball, slip on it), the bound from the
  current pressure. Newton solves with the multipliers fixed; then lamn <- p, lamt <- tau, until
  the largest penetration and the largest distance of a sticking point from its anchor are below
  --agtol (1e-7). A converged step moves the anchor of a slipping or open point to where it
  stands. kp (--penalty, 1e8 per unit area and length) only sets how fast the updates converge.
* A step whose Newton fails is halved (from the last converged state), at most 20 times.
* Load path as the stamp problem's: d in --press equal steps, then s in --drag equal steps; Newton
  (GetFEM's, MUMPS) from a linear extrapolation of the last two converged states.

Per step: P and Q, the whole sphere's force along x3 and x1 (twice the half model's; Q the
magnitude of the tangential force), the contact area A_c and the sticking area A_s of the whole
face (Gauss points with p > 0, and among them those with |tau_tr| < mu p), a = sqrt(A_c / pi),
c / a = sqrt(A_s / A_c), and the contact and stick radii along the x1 axis (the outermost Gauss
points of the row nearest x2 = 0).
"""
import argparse
import json
import sys
import time

import numpy as np
import getfem as gf

gf.util_trace_level(0)

E_MOD, NU, H, L, R = 2.1e5, 0.3, 10.0, 10.0, 100.0
MU_F, DEPTH, TRAVEL = 0.3, 0.01, 0.0025


def parse():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hf", type=float, default=0.25, help="element size near the contact")
    ap.add_argument("--fine", type=float, default=1.5, help="extent of the fine zone")
    ap.add_argument("--ratio", type=float, default=1.6, help="growth of the element size beyond it")
    ap.add_argument("--penalty", type=float, default=1e8, help="kp = kt, per unit area and length")
    ap.add_argument("--press", type=int, default=4, help="steps of the press")
    ap.add_argument("--drag", type=int, default=5, help="steps of the drag")
    ap.add_argument("--mu", type=float, default=MU_F, help="friction coefficient")
    ap.add_argument("--tol", type=float, default=1e-3, help="Newton: absolute residual norm (forces ~1e3)")
    ap.add_argument("--lsearch", default="default")
    ap.add_argument("--agtol", type=float, default=1e-7,
                    help="augmentation: largest penetration and sticking point's distance from its anchor")
    ap.add_argument("--max-uzawa", type=int, default=30)
    ap.add_argument("--noisy", action="store_true")
    ap.add_argument("--json", action="store_true")
    return ap.parse_args()


def graded(hf, fine, ratio, length):
    """Points from 0 to length: spacing hf up to `fine`, then growing by `ratio` per element (the
    last element merged into its neighbour when it would come out shorter than the one before)."""
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


def main():
    a = parse()
    t0 = time.time()
    xp = graded(a.hf, a.fine, a.ratio, L)
    xs = np.concatenate([-xp[:0:-1], xp])
    zs = H / 2 - graded(a.hf, a.fine, a.ratio, H)[::-1]
    m = gf.Mesh("cartesian", xs, xp, zs)
    Y0, BOT, TOP = 1, 2, 3
    m.set_region(Y0, m.outer_faces_with_direction([0.0, -1.0, 0.0], 0.01))
    m.set_region(BOT, m.outer_faces_with_direction([0.0, 0.0, -1.0], 0.01))
    m.set_region(TOP, m.outer_faces_with_direction([0.0, 0.0, 1.0], 0.01))

    mfu = gf.MeshFem(m, 3)
    mfu.set_fem(gf.Fem("FEM_QK(3,2)"))
    mfs = gf.MeshFem(m, 1)
    mfs.set_fem(gf.Fem("FEM_QK(3,2)"))
    mim = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(3,5)"))
    mimc = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(3,7)"))
    mimd3 = gf.MeshImData(mimc, TOP, [3])
    mimd1 = gf.MeshImData(mimc, TOP, [1])

    md = gf.Model("real")
    md.add_fem_variable("u", mfu)
    lam = E_MOD * NU / ((1 + NU) * (1 - 2 * NU))
    gmod = E_MOD / (2 * (1 + NU))
    md.add_initialized_data("lam", [lam])
    md.add_initialized_data("mu", [gmod])
    md.add_macro("F", "(Id(3)+Grad_u)")
    md.add_macro("EE", "((Grad_u+Grad_u'+Grad_u'*Grad_u)/2)")
    md.add_macro("SS", "(lam*Trace(EE)*Id(3)+2*mu*EE)")
    md.add_nonlinear_term(mim, "(F*SS):Grad_Test_u")

    md.add_filtered_fem_variable("l2", mfs, Y0)
    md.add_linear_term(mim, "l2*Test_u(2) + u(2)*Test_l2", Y0)
    md.add_filtered_fem_variable("lb", mfu, BOT)
    md.add_linear_term(mim, "lb.Test_u + u.Test_lb", BOT)

    z0 = H / 2 + R
    md.add_initialized_data("C", [0.0, 0.0, z0])
    md.add_initialized_data("C0", [0.0, 0.0, z0])
    md.add_initialized_data("R", [R])
    md.add_initialized_data("kp", [a.penalty])
    md.add_initialized_data("fr", [a.mu])
    md.add_im_data("lamn", mimd1)   # normal multiplier (pressure) of the augmentation
    md.add_im_data("lamt", mimd3)   # tangential multiplier (traction on the plate)
    md.add_im_data("wa", mimd3)     # stick anchor: u - (C - C0) where the point sticks
    md.add_macro("nn", "Normalized(X+u-C)")
    md.add_macro("gap", "(Norm(X+u-C)-R)")
    md.add_macro("p", "pos_part(lamn-kp*gap)")
    md.add_macro("Pt", "(Id(3)-nn@nn)")
    md.add_macro("ww", "(u-(C-C0))")  # relative to the sphere's material point
    md.add_macro("ttr", "(Pt*(lamt-kp*(ww-wa)))")
    md.add_macro("tau", "Ball_projection(ttr,fr*p)")
    md.add_macro("stick", "Heaviside(fr*p-Norm(ttr)-1e-9*fr*p)")
    md.add_nonlinear_term(mimc, "-(p*nn+tau).Test_u", TOP)

    nunk = md.nbdof()
    # paths: (d, s) at each step
    path = [(DEPTH * k / a.press, 0.0) for k in range(1, a.press + 1)]
    path += [(DEPTH, TRAVEL * k / a.drag) for k in range(1, a.drag + 1)]
    rows = []
    stats = {"newton": 0, "uzawa": 0, "cutbacks": 0}

    def state():
        return {v: md.variable(v).copy() for v in ("u", "lamn", "lamt", "wa")}

    def restore(st):
        for v, val in st.items():
            md.set_variable(v, val)

    def solve_at(d, s):
        """Newton and augmented-Lagrangian (Uzawa) updates at the sphere position (d, s) until the
        largest penetration and the largest distance of a sticking point from its anchor are
        below --agtol; False if Newton fails."""
        md.set_variable("C", [s, 0.0, z0 - d])
        for k in range(a.max_uzawa):
            it, conv = md.solve(*(["noisy"] if a.noisy else []), "max_res", a.tol, "max_iter", 40,
                                "lsearch", a.lsearch)
            stats["newton"] += it
            if not conv:
                return False
            pen = md.interpolation("Heaviside(p-1e-12)*neg_part(gap)", mimd1, TOP)
            sd = md.interpolation("stick*Heaviside(p-1e-12)*Norm(Pt*(ww-wa))", mimd1, TOP)
            viol = max(np.abs(pen).max(), np.abs(sd).max())
            md.set_variable("lamn", md.interpolation("p", mimd1, TOP))
            md.set_variable("lamt", md.interpolation("tau", mimd3, TOP))
            stats["uzawa"] += 1
            if viol < a.agtol:
                return True
        return True

    def checkpoint():
        """A converged step: a slipping or open point's anchor moves to where it stands."""
        md.set_variable("wa", md.interpolation("wa+(1-stick)*(ww-wa)", mimd3, TOP))

    prev = (0.0, 0.0)
    u_prev = md.variable("u")
    for k, (d, s) in enumerate(path):
        u_now = md.variable("u")
        if k > 0 and k != a.press:  # linear predictor, not across the kink of the path
            md.set_variable("u", 2.0 * u_now - u_prev)
        u_prev = u_now
        # the step, halved on a failure (restarting from the last converged state)
        conv_state = state()
        if k > 0 and k != a.press:
            conv_state["u"] = u_now
        todo, start = [(d, s)], prev
        while todo:
            tgt = todo[0]
            if solve_at(*tgt):
                checkpoint()
                conv_state = state()
                start = tgt
                todo.pop(0)
            else:
                stats["cutbacks"] += 1
                if stats["cutbacks"] > 20:
                    print("too many cut-backs at d = %g, s = %g" % tgt, file=sys.stderr)
                    sys.exit(2)
                restore(conv_state)
                todo.insert(0, (0.5 * (start[0] + tgt[0]), 0.5 * (start[1] + tgt[1])))
        prev = (d, s)
        f3 = -2.0 * gf.asm_generic(mimc, 0, "(p*nn+tau)(3)", TOP, md)
        f1 = -2.0 * gf.asm_generic(mimc, 0, "(p*nn+tau)(1)", TOP, md)
        ac = 2.0 * gf.asm_generic(mimc, 0, "Heaviside(p-1e-12)", TOP, md)
        ast = 2.0 * gf.asm_generic(mimc, 0, "Heaviside(p-1e-12)*stick", TOP, md)
        # radii along the x1 axis: the row of Gauss points nearest x2 = 0
        xg = md.interpolation("X", mimd3, TOP).reshape(-1, 3)
        pg = md.interpolation("p", mimd1, TOP)
        sg = md.interpolation("stick", mimd1, TOP)
        row = np.abs(xg[:, 1] - xg[:, 1].min()) < 1e-9
        inc = row & (pg > 1e-12)
        ins = inc & (sg > 0.5)
        rc = 0.5 * (xg[inc, 0].max() - xg[inc, 0].min()) if inc.any() else 0.0
        rs = 0.5 * (xg[ins, 0].max() - xg[ins, 0].min()) if ins.any() else 0.0
        rows.append({"d": d, "s": s, "P": float(f3), "Q": float(abs(f1)), "Q_signed": float(f1),
                     "contact_area": float(ac), "stick_area": float(ast),
                     "a": float(np.sqrt(ac / np.pi)),
                     "c_over_a": float(np.sqrt(ast / ac)) if ac > 0 else 0.0,
                     "a_axis": float(rc), "c_axis": float(rs)})
        r_ = rows[-1]
        print("  %8.5f  %9.6f  %10.3f  %10.4f  %7.4f  %7.4f   (Newton %d, updates %d, cut-backs %d, %.0f s)" %
                  (d, s, r_["P"], r_["Q"], r_["a"], r_["c_over_a"], stats["newton"], stats["uzawa"],
                   stats["cutbacks"], time.time() - t0), flush=True, file=sys.stderr if a.json else sys.stdout)
    iters = stats["newton"]
    out = {"hf": a.hf, "fine": a.fine, "ratio": a.ratio, "penalty": a.penalty, "mu": a.mu,
           "elements": [len(xs) - 1, len(xp) - 1, len(zs) - 1], "unknowns": int(nunk),
           "newton": int(iters), "updates": stats["uzawa"], "cutbacks": stats["cutbacks"], "time": time.time() - t0, "steps": rows}
    if a.json:
        print(json.dumps(out))
        return
    print("3D Q2, %d x %d x %d elements, %d unknowns, mu = %g, kp = kt = %g" %
          (len(xs) - 1, len(xp) - 1, len(zs) - 1, nunk, a.mu, a.penalty))
    print("       d          s           P           Q      Q/(mu P)    a       c/a    a_axis  c_axis")
    for r_ in rows:
        print("  %8.5f  %9.6f  %10.3f  %10.4f  %8.5f  %7.4f  %7.4f  %6.3f  %6.3f" %
              (r_["d"], r_["s"], r_["P"], r_["Q"], r_["Q"] / (a.mu * r_["P"]), r_["a"], r_["c_over_a"],
               r_["a_axis"], r_["c_axis"]))
    print("  Newton iterations %d, wall time %.1f s" % (iters, out["time"]))


if __name__ == "__main__":
    main()
