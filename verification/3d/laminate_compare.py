#!/usr/bin/python3
"""stamp against the 3D laminate model on meshes/laminate-sphere.toml: force-indentation curves
and the fields through the thickness under the punch.

    /usr/bin/python3 verification/3d/laminate_sphere_getfem.py --n 8 --json > u8.json   # and 12, 16, 20
    stamp run meshes/laminate-sphere.toml --out s20 --refine=2   # with n = [20, 20]: 20, 40, 80
    stamp run meshes/laminate-sphere.toml --out s40              # n = 40: the probes
    /usr/bin/python3 verification/3d/laminate_compare.py --getfem u8.json u12.json u16.json \\
        --stamp s20 s20/refined s20/refined2 --probe-stamp s40

Each sequence (the 3D meshes in the order given, stamp's likewise, each halving or refining the
element side l) is extrapolated to l = 0 from its last three members, F(l) = F0 + C l^p with p
fitted (p = 2 if the three are not monotone; none if p falls outside (0.5, 6): then the finest
run stands for the limit); the force table gives every run's error against the 3D limit, and
stamp's extrapolated force against it. --stamp-n gives stamp's n when the first is not 20. The probe table compares the finest stamp run's thickness_<probe>_0005.csv
with the finest 3D run's fields at the same rows.
"""
import argparse
import csv
import glob
import json
import math
import os


def extrapolate(ls, fs):
    """F0 and p from three (l, F), F = F0 + C l^p."""
    (l1, l2, l3), (f1, f2, f3) = ls[-3:], fs[-3:]
    d1, d2 = f1 - f2, f2 - f3
    if d1 * d2 <= 0 or abs(d2) < 1e-300:
        p = 2.0
    else:
        # (l1^p - l2^p) / (l2^p - l3^p) = d1 / d2, solved for p by bisection
        lo, hi = 0.1, 8.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            r = (l1 ** mid - l2 ** mid) / (l2 ** mid - l3 ** mid)
            if r > d1 / d2:
                hi = mid
            else:
                lo = mid
        p = 0.5 * (lo + hi)
    if not 0.5 < p < 6.0:
        return None, p  # no clean power law: no extrapolation
    c = d2 / (l2 ** p - l3 ** p)
    return f3 - c * l3 ** p, p


def stamp_run(folder):
    with open(os.path.join(folder, "history.csv")) as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(folder, "summary.json")) as f:
        summ = json.load(f)
    return rows, summ


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--getfem", nargs="+", required=True)
    ap.add_argument("--stamp", nargs="+", required=True)
    ap.add_argument("--stamp-n", nargs="+", type=int, default=None,
                    help="stamp's n per run (default 20, 40, 80, ...)")
    ap.add_argument("--probes", nargs="+", default=["centre=0,0", "x1=1.25,0.25", "x2=0.25,1.25"],
                    help="stamp's probe name = the 3D run's --probe point")
    ap.add_argument("--probe-stamp", default=None,
                    help="the stamp run whose probes are compared (default: the last of --stamp)")
    a = ap.parse_args()
    g = [json.load(open(p)) for p in a.getfem]
    s = [stamp_run(p)[0] for p in a.stamp]
    sn = a.stamp_n or [20 * 2 ** k for k in range(len(s))]
    travels = [st["travel"] for st in g[0]["steps"]]
    print("force on the quarter against the travel; errors in % of the extrapolated 3D force")
    head = "| travel | 3D extrap. (p) |" + "".join(" 3D n=%d |" % r["n"] for r in g) + \
        (" stamp extrap. (p) |" if len(s) >= 3 else "") + "".join(" stamp n=%d |" % n for n in sn)
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for k, t in enumerate(travels):
        gf = [r["steps"][k]["force"] for r in g]
        gl = [20.0 / r["n"] for r in g]
        g0, gp = extrapolate(gl, gf) if len(g) >= 3 else (None, float("nan"))
        line = "| %.1f | %.4f (%.2f) |" % (t, g0, gp) if g0 is not None else \
            "| %.1f | none (p = %.2f): the finest, %.4f |" % (t, gp, gf[-1])
        g0 = gf[-1] if g0 is None else g0
        sf = [float(r[k]["sphere_force"]) for r in s]
        line += "".join(" %.4f (%+.3f %%) |" % (f, 100 * (f / g0 - 1)) for f in gf)
        if len(s) >= 3:
            s0, sp = extrapolate([20.0 / n for n in sn], sf)
            line += (" %.4f (%.2f) %+.3f %% |" % (s0, sp, 100 * (s0 / g0 - 1)) if s0 is not None
                     else " none (p = %.2f) |" % sp)
        line += "".join(" %.4f (%+.3f %%) |" % (f, 100 * (f / g0 - 1)) for f in sf)
        print(line)
    # fields through the thickness at the last travel
    fine = g[-1]
    print("(reference: the extrapolated 3D force, or where the 3D sequence fits no power law "
          "with 0.5 < p < 6, the finest 3D run's)")
    summary = []
    print("\nfields through the thickness at travel %.1f: stamp %s against 3D n=%d"
          % (travels[-1], a.probe_stamp or a.stamp[-1], fine["n"]))
    names = dict(kv.split("=") for kv in a.probes)
    cols = ["u3", "s11", "s22", "s33", "s12", "s13", "s23"]
    for probe, key in names.items():
        files = sorted(glob.glob(os.path.join(a.probe_stamp or a.stamp[-1], "thickness_%s_*.csv" % probe)))
        if not files or key not in fine["probes"]:
            continue
        with open(files[-1]) as f:
            srows = [[float(v) for v in r.values()] for r in csv.DictReader(f)]
        grows = fine["probes"][key]
        sa, ga = [r[4:] for r in srows], [r[4:] for r in grows]
        tmax = max(abs(v[j]) for v in ga for j in (5, 6))
        errs = []
        for j, c in enumerate(cols):
            ref = max(abs(v[j]) for v in ga)
            e = max(abs(x[j] - y[j]) for x, y in zip(sa, ga))
            errs.append((c, 100 * e / ref, 100 * e / tmax if c in ("s13", "s23") else None, ref))
        summary.append((probe, key, errs))
        print("probe %s (x1, x2) = (%s), %s" % (probe, key, os.path.basename(files[-1])))
        print("| x3 | layer |" + "".join(" %s stamp | %s 3D |" % (c, c) for c in cols))
        print("|---|---|" + "---|---|" * len(cols))
        for sr, gr in zip(srows, grows):
            assert abs(sr[0] - gr[0]) < 1e-9 and int(sr[1]) == gr[1]
            if int(round((sr[0] + 0.5) / 0.03125)) % 2:
                continue  # every other row
            line = "| %+.4f | %d |" % (sr[0], sr[1])
            for c in cols:
                i = 4 + cols.index(c)
                line += " %.4g | %.4g |" % (sr[i], gr[i])
            print(line)
    print("\nlargest |stamp - 3D| over the rows, in % of the column's largest |3D| value (that value in "
          "brackets); for s13, s23 also in % of the probe's largest 3D transverse shear")
    for probe, key, errs in summary:
        print("probe %s (%s): " % (probe, key) + ", ".join(
            "%s %.2f %%%s [%.4g]" % (c, e, "" if et is None else " (%.2f %%)" % et, ref)
            for c, e, et, ref in errs))


if __name__ == "__main__":
    main()
