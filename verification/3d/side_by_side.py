#!/usr/bin/python3
"""stamp against a 3D reference (GetFEM) on meshes/sphere-ss-displacement.toml, on this machine.

    cargo build --release -p stamp-cli
    /usr/bin/python3 verification/3d/side_by_side.py                 # the default sequences
    /usr/bin/python3 verification/3d/side_by_side.py --stamp-n 10 20 40 80 160 --getfem-n 6 8 12 16 24
    /usr/bin/python3 verification/3d/side_by_side.py --stamp-surfaces 4 --stamp-n 20 40 80 160 --getfem-n 12 16 24 32
    /usr/bin/python3 verification/3d/side_by_side.py --stamp-predictor coarse --stamp-n 20 40 80 100

Needs GetFEM for the Debian Python (apt-get install -y python3-getfem). Not part of the test suite.

For each mesh it runs the code, measures the wall time of the whole run (5 load steps to a travel
of 0.9) and reads the punch force on the quarter plate at travel 0.9 (stamp: history.csv;
GetFEM: verification/3d/sphere_plate_getfem.py --json, 3D Saint Venant-Kirchhoff, Q2 hexahedra,
--nz through the thickness). Each sequence is extrapolated to zero mesh size from its three finest
meshes, F(l) = F0 + C l^p (p fitted; l = 20 / n, the element side; p = 2 when the three are not
monotone). Then it prints per mesh the
wall time, the force and its error against the extrapolated 3D force and against the code's own
extrapolated force, and for each code the shortest measured wall time within 0.5 % of (a) its own
limit, (b) the 3D limit; if no measured mesh gets there, the time is estimated from the fitted
error law and a power law of time against 1/l fitted on the two finest meshes (marked "est.").
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
TOML = os.path.join(REPO, "meshes", "sphere-ss-displacement.toml")
SIDE = 20.0


def run_stamp(exe, n, workdir, extra="", surfaces=2, predictor="secant"):
    """Run stamp on an n x n quarter mesh with `surfaces` surfaces through the thickness ([plate]
    surfaces) and [solver] predictor; return (wall time, force at travel 0.9, unknowns)."""
    text = open(TOML).read()
    text = text.replace("n = [10, 10]", "n = [%d, %d]" % (n, n)).replace("plot = true", "plot = false")
    if predictor != "secant":
        text = text.replace("[solver]\n", "[solver]\npredictor = \"%s\"\n" % predictor, 1)
    if surfaces != 2:
        extra = (extra + "\n" if extra else "") + "surfaces = %d" % surfaces
    if extra:
        text = text.replace("nu = 0.3\n", "nu = 0.3\n" + extra + "\n", 1)
    path = os.path.join(workdir, "stamp_n%d.toml" % n)
    open(path, "w").write(text)
    t0 = time.time()
    r = subprocess.run([exe, "run", path], cwd=workdir, capture_output=True, text=True)
    wall = time.time() - t0
    if r.returncode != 0:
        sys.exit("stamp run failed on n = %d:\n%s" % (n, r.stderr[-2000:]))
    rows = list(csv.DictReader(open(os.path.join(workdir, "stamp_n%d-out" % n, "history.csv"))))
    last = rows[-1]
    if abs(float(last["sphere_travel"]) - 0.9) > 1e-9:
        sys.exit("stamp on n = %d stopped at travel %s" % (n, last["sphere_travel"]))
    return wall, float(last["sphere_force"]), (n + 1) ** 2 * 3 * surfaces


def run_getfem(n, nz, penalty):
    """Run the 3D model; return (wall time, force at travel 0.9, unknowns)."""
    cmd = ["/usr/bin/python3", os.path.join(HERE, "sphere_plate_getfem.py"), "--n", str(n), "--nz", str(nz),
           "--penalty", str(penalty), "--json"]
    t0 = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.time() - t0
    if r.returncode != 0:
        sys.exit("GetFEM failed on n = %d:\n%s" % (n, r.stderr[-2000:]))
    d = json.loads(r.stdout.strip().splitlines()[-1])
    return wall, d["steps"][-1]["force"], d["unknowns"]


def extrapolate(ls, fs):
    """F0, C, p of F = F0 + C l^p through the last three points (p by bisection on the ratio)."""
    (l1, l2, l3), (f1, f2, f3) = ls[-3:], fs[-3:]
    target = (f1 - f2) / (f2 - f3)

    def ratio(p):
        return (l1 ** p - l2 ** p) / (l2 ** p - l3 ** p)

    lo, hi = 0.1, 6.0
    if not (min(ratio(lo), ratio(hi)) <= target <= max(ratio(lo), ratio(hi))):
        # not monotone in the asymptotic range: fall back to p = 2
        p = 2.0
    else:
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            if (ratio(mid) - target) * (ratio(lo) - target) > 0:
                lo = mid
            else:
                hi = mid
        p = 0.5 * (lo + hi)
    c = (f2 - f3) / (l2 ** p - l3 ** p)
    return f3 - c * l3 ** p, c, p


def time_to(runs, f0, c, p, goal, tol=0.005):
    """Shortest measured time within tol of goal, else an estimate from the fits."""
    ok = [w for (n, w, f, u) in runs if abs(f - goal) <= tol * abs(goal)]
    if ok:
        return min(ok), "measured"
    # the fitted error law |F0 + C l^p - goal| <= tol |goal| needs l <= l*
    bias = f0 - goal
    room = tol * abs(goal) - abs(bias)
    if room <= 0:
        return math.inf, "never (the limit itself is %.2f %% off)" % (100 * bias / goal)
    lstar = (room / abs(c)) ** (1.0 / p)
    (n1, w1, _, _), (n2, w2, _, _) = runs[-2], runs[-1]
    q = math.log(w2 / w1) / math.log(n2 / n1)
    nstar = SIDE / lstar
    return w2 * (nstar / n2) ** q, "est. (n = %.0f, time ~ n^%.2f)" % (nstar, q)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--stamp", default=os.path.join(REPO, "target", "release", "stamp"))
    ap.add_argument("--stamp-n", type=int, nargs="+", default=[10, 20, 40, 80])
    ap.add_argument("--stamp-surfaces", type=int, default=2, help="[plate] surfaces of stamp's runs (2: the paper's plate)")
    ap.add_argument("--stamp-predictor", default="secant", choices=["secant", "coarse"], help="[solver] predictor of stamp's runs (coarse: every step from the mesh with half the n)")
    ap.add_argument("--getfem-n", type=int, nargs="+", default=[6, 8, 12, 16])
    ap.add_argument("--nz", type=int, default=2)
    ap.add_argument("--penalty", type=float, default=1e6)
    a = ap.parse_args()
    if len(a.stamp_n) < 3 or len(a.getfem_n) < 3:
        sys.exit("--stamp-n and --getfem-n need three meshes or more each (the limits are extrapolated from the three finest)")

    work = tempfile.mkdtemp(prefix="side_by_side_")
    st = []
    for n in a.stamp_n:
        w, f, u = run_stamp(a.stamp, n, work, surfaces=a.stamp_surfaces, predictor=a.stamp_predictor)
        st.append((n, w, f, u))
        print("stamp  n = %4d: %7d unknowns, %8.2f s, force %.4f" % (n, u, w, f), flush=True)
    gf = []
    for n in a.getfem_n:
        w, f, u = run_getfem(n, a.nz, a.penalty)
        gf.append((n, w, f, u))
        print("3D     n = %4d: %7d unknowns, %8.2f s, force %.4f" % (n, u, w, f), flush=True)

    s0, sc, sp = extrapolate([SIDE / r[0] for r in st], [r[2] for r in st])
    g0, gc, gp = extrapolate([SIDE / r[0] for r in gf], [r[2] for r in gf])
    print()
    print("extrapolated force at travel 0.9: stamp %.3f (error ~ l^%.2f), 3D %.3f (error ~ l^%.2f); "
          "stamp's limit is %+.2f %% off the 3D limit" % (s0, sp, g0, gp, 100 * (s0 - g0) / g0))
    print()
    print("| code | n x n | unknowns | wall time (s) | force at 0.9 | error vs 3D limit | error vs own limit |")
    print("|---|---|---|---|---|---|---|")
    for name, runs, own in (("stamp", st, s0), ("3D GetFEM", gf, g0)):
        for (n, w, f, u) in runs:
            print("| %s | %d | %d | %.2f | %.3f | %+.2f %% | %+.2f %% |"
                  % (name, n, u, w, f, 100 * (f - g0) / g0, 100 * (f - own) / own))
    print()
    ts_own, how_s_own = time_to(st, s0, sc, sp, s0)
    tg_own, how_g_own = time_to(gf, g0, gc, gp, g0)
    ts_3d, how_s_3d = time_to(st, s0, sc, sp, g0)
    print("time to within 0.5 %% of the code's own limit: stamp %.2f s (%s), 3D %.2f s (%s): ratio %.1f"
          % (ts_own, how_s_own, tg_own, how_g_own, tg_own / ts_own))
    print("time to within 0.5 %% of the 3D limit: stamp %s (%s), 3D %.2f s (%s)"
          % ("%.2f s" % ts_3d if math.isfinite(ts_3d) else "-", how_s_3d, tg_own, how_g_own))


if __name__ == "__main__":
    main()
