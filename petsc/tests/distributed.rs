//! Distributed solves on 1, 2 and 4 ranks, checked against known answers.
//!
//! Each test runs this same test binary under `mpirun -n P --oversubscribe` (as root with
//! `--allow-run-as-root`, `OMP_NUM_THREADS=1`), where the ignored test [`child`] runs the case
//! named in `STAMP_PETSC_CHILD` on every rank and prints one `RESULT case rank size key=value ...`
//! line per rank; the parent checks every rank's line. The cases:
//!
//! - `poisson`: the 5-point Laplacian on a 48 x 48 grid of the unit square through the raw
//!   wrappers (MPIAIJ by rows, CG + GAMG); the discrete solution is x(1-x)y(1-y) exactly (the
//!   stencil's second differences are exact on quadratics), so the error is round-off.
//! - `elasticity`: bilinear plane-stress quadrilaterals on [0,2]x[0,1] with a linear displacement
//!   field prescribed on the boundary (the patch test: the interior reproduces it exactly),
//!   solved through [`PetscSolver`] as stamp's Newton hands it the matrix, with CG + GAMG with and
//!   without the rigid-body near-null space, and with the default GMRES + MUMPS.
//! - `unsymmetric`: convection-diffusion A preconditioned by the Laplacian P (today's scheme:
//!   GMRES on A, MUMPS LDL^T of P), against a manufactured solution and faer's LU of A; and the
//!   re-solve's estimates with P's factor, the compliance between sparse vectors (MUMPS's
//!   selected entries of the inverse, the same bits on every rank) and whole columns by the
//!   preconditioner, against faer's LU of P.
//! - `shared`: the same A and P handed over in shares ([`PetscSolver::set_partition`]): each
//!   rank passes its own part of every entry (zeros elsewhere in the common pattern), the rows
//!   owned in scattered blocks; the sum's solution is faer's LU of the whole A, the same on every
//!   rank, twice with other values (no share left over from the first).
//! - `failures`: a Krylov solve that does not converge, an option PETSc does not know, a singular
//!   matrix and a failure on one rank only: each an error on every rank, the same message.

use faer::sparse::{SparseColMat, Triplet};
use stamp::linalg::linear_solver::{LinearSolver, SparseLu};
use stamp_petsc::ksp::Ksp;
use stamp_petsc::matrix::{AijMatrix, RowPattern};
use stamp_petsc::vector::{DVec, Gather};
use stamp_petsc::{Petsc, PetscSolver};
use std::collections::BTreeMap;
use std::process::Command;

const CHILD: &str = "STAMP_PETSC_CHILD";

/// Run `case` on `ranks` processes; the RESULT lines of every rank, sorted by rank.
fn run(case: &str, ranks: usize) -> Vec<BTreeMap<String, String>> {
    let exe = std::env::current_exe().unwrap();
    let out = Command::new("mpirun")
        .args(["-n", &ranks.to_string(), "--oversubscribe", "--allow-run-as-root"])
        .env("OMP_NUM_THREADS", "1")
        .env(CHILD, case)
        .arg(exe)
        .args(["--ignored", "--exact", "child", "--nocapture", "--test-threads=1"])
        .output()
        .expect("mpirun (openmpi-bin) must be installed");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{case} on {ranks} ranks failed:\n{stdout}\n{stderr}");
    let mut lines: Vec<BTreeMap<String, String>> = stdout
        .lines()
        .filter_map(|l| l.find("RESULT ").map(|i| &l[i + 7..]))
        .map(|l| {
            let mut m = BTreeMap::new();
            let mut words = l.split_whitespace();
            m.insert("case".into(), words.next().unwrap().to_string());
            m.insert("rank".into(), words.next().unwrap().to_string());
            m.insert("size".into(), words.next().unwrap().to_string());
            let rest: Vec<&str> = words.collect();
            // key=value pairs; a value may hold spaces up to the next " key="
            let joined = rest.join(" ");
            for part in joined.split(" |") {
                if let Some((k, v)) = part.trim().split_once('=') {
                    m.insert(k.to_string(), v.to_string());
                }
            }
            m
        })
        .filter(|m| m["case"] == case)
        .collect();
    lines.sort_by_key(|m| m["rank"].parse::<usize>().unwrap());
    assert_eq!(lines.len(), ranks, "{case} on {ranks} ranks: one RESULT line per rank expected:\n{stdout}\n{stderr}");
    for (r, m) in lines.iter().enumerate() {
        assert_eq!(m["rank"], r.to_string());
        assert_eq!(m["size"], ranks.to_string(), "{case}: PETSC_COMM_WORLD has the ranks mpirun started");
    }
    lines
}

fn num(m: &BTreeMap<String, String>, key: &str) -> f64 {
    m.get(key).unwrap_or_else(|| panic!("no {key} in {m:?}")).parse().unwrap()
}

#[test]
fn poisson_by_rows_cg_gamg_on_1_2_4_ranks() {
    for ranks in [1, 2, 4] {
        for m in run("poisson", ranks) {
            let err = num(&m, "max_error");
            assert!(err < 1e-10, "{ranks} ranks, rank {}: max error {err:e}", m["rank"]);
            let its = num(&m, "iterations");
            assert!((1.0..=60.0).contains(&its), "{ranks} ranks: {its} CG iterations");
            assert_eq!(m["solver"], "cg + gamg");
        }
    }
}

#[test]
fn elasticity_patch_test_on_1_2_4_ranks() {
    for ranks in [1, 2, 4] {
        let lines = run("elasticity", ranks);
        for m in &lines {
            for key in ["error_gamg_rigid", "error_gamg_plain", "error_default"] {
                let e = num(m, key);
                assert!(e < 1e-9, "{ranks} ranks, rank {}: {key} {e:e}", m["rank"]);
            }
            let (with, without) = (num(m, "iterations_gamg_rigid"), num(m, "iterations_gamg_plain"));
            assert!(with <= without, "{ranks} ranks: GAMG with the rigid-body modes took {with} iterations, without {without}");
            assert_eq!(m["default_solver"], "gmres + cholesky (mumps)");
        }
        // every rank holds the same gathered solution
        let sums: Vec<&String> = lines.iter().map(|m| &m["solution_bits"]).collect();
        assert!(sums.windows(2).all(|w| w[0] == w[1]), "{ranks} ranks: the gathered solutions differ: {sums:?}");
    }
}

#[test]
fn unsymmetric_gmres_preconditioned_by_mumps_ldlt_on_1_2_4_ranks() {
    for ranks in [1, 2, 4] {
        let lines = run("unsymmetric", ranks);
        let bits: Vec<&String> = lines.iter().map(|m| &m["compliance_bits"]).collect();
        assert!(bits.windows(2).all(|w| w[0] == w[1]), "{ranks} ranks: the ranks' compliances differ: {bits:?}");
        for m in lines {
            let (err, vs_faer) = (num(&m, "error"), num(&m, "difference_from_faer"));
            assert!(err < 1e-9 && vs_faer < 1e-9, "{ranks} ranks: error {err:e}, from faer's LU {vs_faer:e}");
            let its = num(&m, "iterations");
            // P is not A: GMRES needs more than one iteration, and few
            assert!((2.0..=40.0).contains(&its), "{ranks} ranks: {its} GMRES iterations");
            assert_eq!(m["solver"], "gmres + cholesky (mumps)");
            let (c, many) = (num(&m, "compliance_error"), num(&m, "many_error"));
            assert!(c < 1e-10 && many < 1e-10, "{ranks} ranks: the compliance off by {c:e}, the preconditioner's columns by {many:e}");
        }
    }
}

#[test]
fn shares_of_the_matrices_summed_on_1_2_4_ranks() {
    for ranks in [1, 2, 4] {
        let lines = run("shared", ranks);
        for m in &lines {
            let (first, second) = (num(m, "difference_from_faer"), num(m, "second_difference_from_faer"));
            assert!(first < 1e-9 && second < 1e-9, "{ranks} ranks: from faer's LU {first:e}, after new values {second:e}");
            assert!((2.0..=40.0).contains(&num(m, "iterations")), "{ranks} ranks: {} GMRES iterations", m["iterations"]);
        }
        let bits: Vec<&String> = lines.iter().map(|m| &m["solution_bits"]).collect();
        assert!(bits.windows(2).all(|w| w[0] == w[1]), "{ranks} ranks: the gathered solutions differ: {bits:?}");
    }
}

#[test]
fn failures_are_errors_on_every_rank_with_one_message() {
    for ranks in [1, 2, 4] {
        let lines = run("failures", ranks);
        for key in ["diverged", "unknown_option", "singular", "one_rank"] {
            let first = &lines[0][key];
            for m in &lines {
                assert_eq!(&m[key], first, "{ranks} ranks: {key} differs between ranks");
            }
        }
        let m = &lines[0];
        assert!(m["diverged"].contains("DIVERGED_ITS"), "{}", m["diverged"]);
        assert!(m["unknown_option"].contains("no_such_pc"), "PETSc's message names the unknown type: {}", m["unknown_option"]);
        assert!(m["singular"].contains("DIVERGED_PC_FAILED") && m["singular"].contains("singular"), "{}", m["singular"]);
        if ranks > 1 {
            assert_eq!(m["one_rank"], format!("rank 1 of {ranks}: disk full"));
        } else {
            assert_eq!(m["one_rank"], "ok");
        }
    }
}

// ---------------------------------------------------------------- the cases, run under mpirun

/// The case named in STAMP_PETSC_CHILD, on every rank (only under mpirun, see the module doc).
#[test]
#[ignore = "run by the other tests under mpirun"]
fn child() {
    let Ok(case) = std::env::var(CHILD) else {
        eprintln!("the child case runs under mpirun with {CHILD} set");
        return;
    };
    let petsc = Petsc::initialize().unwrap();
    let fields = match case.as_str() {
        "poisson" => poisson(&petsc),
        "elasticity" => elasticity(&petsc),
        "unsymmetric" => unsymmetric(&petsc),
        "failures" => failures(&petsc),
        "shared" => shared(&petsc),
        other => panic!("no case {other}"),
    };
    let line: Vec<String> = fields.iter().map(|(k, v)| format!("{k}={v}")).collect();
    println!("RESULT {case} {} {} {}", petsc.rank(), petsc.size(), line.join(" |"));
}

/// This rank's rows of n, split evenly.
fn my_rows(petsc: &Petsc, n: usize) -> (usize, usize) {
    (n * petsc.rank() / petsc.size(), n * (petsc.rank() + 1) / petsc.size())
}

fn poisson(petsc: &Petsc) -> Vec<(String, String)> {
    let m = 48;
    let n = m * m;
    let h = 1.0 / (m + 1) as f64;
    let (lo, hi) = my_rows(petsc, n);
    let (mut row_ptr, mut cols, mut vals) = (vec![0], Vec::new(), Vec::new());
    let mut b = Vec::new();
    let exact = |x: f64, y: f64| x * (1.0 - x) * y * (1.0 - y);
    for k in lo..hi {
        let (i, j) = (k % m, k / m);
        let mut row: Vec<(i32, f64)> = vec![(k as i32, 4.0 / (h * h))];
        if j > 0 {
            row.push(((k - m) as i32, -1.0 / (h * h)));
        }
        if i > 0 {
            row.push(((k - 1) as i32, -1.0 / (h * h)));
        }
        if i + 1 < m {
            row.push(((k + 1) as i32, -1.0 / (h * h)));
        }
        if j + 1 < m {
            row.push(((k + m) as i32, -1.0 / (h * h)));
        }
        row.sort_by_key(|e| e.0);
        cols.extend(row.iter().map(|e| e.0));
        vals.extend(row.iter().map(|e| e.1));
        row_ptr.push(cols.len());
        let (x, y) = ((i + 1) as f64 * h, (j + 1) as f64 * h);
        b.push(2.0 * y * (1.0 - y) + 2.0 * x * (1.0 - x));
    }
    let mut a = AijMatrix::new(petsc, RowPattern { lo, hi, n, row_ptr, cols }).unwrap();
    a.set_values(&vals).unwrap();
    let mut bv = DVec::new(petsc, hi - lo, n).unwrap();
    bv.with_local_mut(|x| x.copy_from_slice(&b)).unwrap();
    let mut xv = DVec::new(petsc, hi - lo, n).unwrap();
    let mut ksp = Ksp::new(petsc).unwrap();
    ksp.set_operators(&a, &a).unwrap();
    ksp.set_type("cg").unwrap();
    ksp.set_pc_type("gamg").unwrap();
    ksp.set_tolerances(1e-13, 0.0, 500).unwrap();
    let report = ksp.solve(&bv, &mut xv).unwrap();
    let mut all = vec![0.0; n];
    Gather::new(petsc, &xv).unwrap().gather(&xv, &mut all).unwrap();
    let err = (0..n).map(|k| (all[k] - exact((k % m + 1) as f64 * h, (k / m + 1) as f64 * h)).abs()).fold(0.0, f64::max) / exact(0.5, 0.5);
    vec![("max_error".into(), format!("{err:e}")), ("iterations".into(), report.iterations.to_string()), ("solver".into(), ksp.describe())]
}

/// A compressed-column matrix from (row, column, value) triplets (duplicates summed).
fn csc(n: usize, t: &[(usize, usize, f64)]) -> SparseColMat<usize, f64> {
    let t: Vec<Triplet<usize, usize, f64>> = t.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
    SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
}

fn elasticity(petsc: &Petsc) -> Vec<(String, String)> {
    let (nx, ny) = (32usize, 16usize);
    let (lx, ly) = (2.0, 1.0);
    let node = |i: usize, j: usize| j * (nx + 1) + i;
    let xy = |n: usize| ((n % (nx + 1)) as f64 * lx / nx as f64, (n / (nx + 1)) as f64 * ly / ny as f64);
    let nn = (nx + 1) * (ny + 1);
    // the prescribed linear field
    let field = |x: f64, y: f64| [1e-3 * (0.3 + 2.0 * x - 0.7 * y), 1e-3 * (-0.2 + 0.5 * x + 1.1 * y)];
    let boundary = |n: usize| {
        let (i, j) = (n % (nx + 1), n / (nx + 1));
        i == 0 || j == 0 || i == nx || j == ny
    };
    // equations: the dofs of interior nodes
    let mut eq = vec![usize::MAX; 2 * nn];
    let mut neq = 0;
    for n in 0..nn {
        if !boundary(n) {
            eq[2 * n] = neq;
            eq[2 * n + 1] = neq + 1;
            neq += 2;
        }
    }
    // plane stress, E = 1, nu = 0.3; 2 x 2 Gauss
    let (e, nu) = (1.0, 0.3);
    let c = e / (1.0 - nu * nu);
    let d = [[c, c * nu, 0.0], [c * nu, c, 0.0], [0.0, 0.0, c * (1.0 - nu) / 2.0]];
    let mut k_ff = Vec::new();
    let mut rhs = vec![0.0; neq];
    let g = 1.0 / 3f64.sqrt();
    for ej in 0..ny {
        for ei in 0..nx {
            let ns = [node(ei, ej), node(ei + 1, ej), node(ei + 1, ej + 1), node(ei, ej + 1)];
            let mut ke = [[0.0; 8]; 8];
            for (xi, eta) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
                let dn = [[-(1.0 - eta) / 4.0, -(1.0 - xi) / 4.0], [(1.0 - eta) / 4.0, -(1.0 + xi) / 4.0], [(1.0 + eta) / 4.0, (1.0 + xi) / 4.0], [-(1.0 + eta) / 4.0, (1.0 - xi) / 4.0]];
                let mut jac = [[0.0; 2]; 2];
                for a in 0..4 {
                    let (x, y) = xy(ns[a]);
                    for r in 0..2 {
                        jac[0][r] += dn[a][r] * x;
                        jac[1][r] += dn[a][r] * y;
                    }
                }
                // jac[c][r] = d x_c / d xi_r
                let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
                let inv = [[jac[1][1] / det, -jac[0][1] / det], [-jac[1][0] / det, jac[0][0] / det]];
                let mut bm = [[0.0; 8]; 3];
                for a in 0..4 {
                    let dx = dn[a][0] * inv[0][0] + dn[a][1] * inv[1][0];
                    let dy = dn[a][0] * inv[0][1] + dn[a][1] * inv[1][1];
                    bm[0][2 * a] = dx;
                    bm[1][2 * a + 1] = dy;
                    bm[2][2 * a] = dy;
                    bm[2][2 * a + 1] = dx;
                }
                for p in 0..8 {
                    for q in 0..8 {
                        let mut s = 0.0;
                        for r in 0..3 {
                            for t in 0..3 {
                                s += bm[r][p] * d[r][t] * bm[t][q];
                            }
                        }
                        ke[p][q] += s * det;
                    }
                }
            }
            for p in 0..8 {
                let gp = 2 * ns[p / 2] + p % 2;
                if eq[gp] == usize::MAX {
                    continue;
                }
                for q in 0..8 {
                    let gq = 2 * ns[q / 2] + q % 2;
                    if eq[gq] == usize::MAX {
                        let (x, y) = xy(ns[q / 2]);
                        rhs[eq[gp]] -= ke[p][q] * field(x, y)[q % 2];
                    } else {
                        k_ff.push((eq[gp], eq[gq], ke[p][q]));
                    }
                }
            }
        }
    }
    let k = csc(neq, &k_ff);
    let exact: Vec<f64> = (0..2 * nn).filter(|&g| eq[g] != usize::MAX).map(|g| { let (x, y) = xy(g / 2); field(x, y)[g % 2] }).collect();
    let error = |x: &[f64]| x.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / 1e-3;
    let rigid: Vec<Vec<f64>> = (0..3)
        .map(|m| {
            (0..2 * nn)
                .filter(|&g| eq[g] != usize::MAX)
                .map(|g| {
                    let (x, y) = xy(g / 2);
                    match (m, g % 2) {
                        (0, 0) | (1, 1) => 1.0,
                        (2, 0) => -y,
                        (2, 1) => x,
                        _ => 0.0,
                    }
                })
                .collect()
        })
        .collect();
    let mut out = Vec::new();
    // GAMG with and without the rigid-body modes (the options database is shared: one solver
    // after the other, each reading it at its set-up)
    for (name, modes) in [("gamg_rigid", true), ("gamg_plain", false)] {
        let mut s = PetscSolver::with_options(petsc, "-ksp_type cg -pc_type gamg -ksp_rtol 1e-13").unwrap();
        if modes {
            s.set_near_null_space(rigid.clone());
        }
        s.factorize(k.as_ref()).unwrap();
        let mut x = rhs.clone();
        s.solve_in_place(&mut x).unwrap();
        out.push((format!("error_{name}"), format!("{:e}", error(&x))));
        out.push((format!("iterations_{name}"), s.iterations().to_string()));
    }
    // back to the default scheme: GMRES + MUMPS (A symmetric: P = A)
    petsc.insert_options("-ksp_type gmres -pc_type cholesky -ksp_rtol 1e-12").unwrap();
    let mut s = PetscSolver::new(petsc);
    s.factorize_preconditioned(k.as_ref(), Some(k.as_ref())).unwrap();
    let mut x = rhs.clone();
    s.solve_in_place(&mut x).unwrap();
    out.push(("error_default".into(), format!("{:e}", error(&x))));
    out.push(("default_solver".into(), s.describe()));
    let bits = x.iter().fold(0u64, |h, v| h.rotate_left(5) ^ v.to_bits());
    out.push(("solution_bits".into(), format!("{bits:x}")));
    out
}

fn unsymmetric(petsc: &Petsc) -> Vec<(String, String)> {
    // 1D convection-diffusion on 3000 points: A = -u'' + c u' (centred), P = -u''
    let n = 3000;
    let h = 1.0 / (n + 1) as f64;
    let conv = 20.0;
    let (mut ta, mut tp) = (Vec::new(), Vec::new());
    for i in 0..n {
        ta.push((i, i, 2.0 / (h * h)));
        tp.push((i, i, 2.0 / (h * h)));
        if i > 0 {
            ta.push((i, i - 1, -1.0 / (h * h) - conv / (2.0 * h)));
            tp.push((i, i - 1, -1.0 / (h * h)));
        }
        if i + 1 < n {
            ta.push((i, i + 1, -1.0 / (h * h) + conv / (2.0 * h)));
            tp.push((i, i + 1, -1.0 / (h * h)));
        }
    }
    let (a, p) = (csc(n, &ta), csc(n, &tp));
    let exact: Vec<f64> = (0..n).map(|i| ((i + 1) as f64 * h * 7.0).sin()).collect();
    // b = A exact
    let mut b = vec![0.0; n];
    for &(i, j, v) in &ta {
        b[i] += v * exact[j];
    }
    let mut s = PetscSolver::new(petsc);
    s.factorize_preconditioned(a.as_ref(), Some(p.as_ref())).unwrap();
    let mut x = b.clone();
    s.solve_in_place(&mut x).unwrap();
    // twice: the second factorisation reuses the pattern
    s.factorize_preconditioned(a.as_ref(), Some(p.as_ref())).unwrap();
    let mut x2 = b.clone();
    s.solve_in_place(&mut x2).unwrap();
    let mut lu = SparseLu::new();
    lu.factorize(a.as_ref()).unwrap();
    let mut y = b.clone();
    lu.solve_in_place(&mut y).unwrap();
    let max = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert_eq!(x, x2, "the same matrix twice: the same answer");
    assert_eq!(s.timings().factorizations, 2);
    // the estimates of the re-solve of the linearised contact problem, with MUMPS's factor of P:
    // the compliance a_i^T P^-1 b_j between sparse vectors (selected entries of the inverse),
    // and whole columns P^-1 b (the preconditioner alone), against faer's LU of P
    let sparse = |k: usize| -> Vec<(usize, f64)> { (0..1 + k % 3).map(|q| ((k * 997 + q * 131) % n, 1.0 + 0.25 * q as f64 - 0.1 * k as f64)).collect() };
    let (va, vb): (Vec<_>, Vec<_>) = ((0..7).map(sparse).collect(), (7..12).map(sparse).collect());
    let c = s.compliance(&va, &vb).unwrap().expect("MUMPS gives selected entries of the inverse");
    let mut plu = SparseLu::new();
    plu.factorize(p.as_ref()).unwrap();
    let (mut worst, mut scale, mut many_error) = (0.0f64, 0.0f64, 0.0f64);
    let mut columns = vec![0.0; n * vb.len()];
    for (j, g) in vb.iter().enumerate() {
        let mut z = vec![0.0; n];
        for &(e, v) in g {
            z[e] += v;
            columns[j * n + e] += v;
        }
        plu.solve_in_place(&mut z).unwrap();
        for (i, f) in va.iter().enumerate() {
            let want: f64 = f.iter().map(|&(e, v)| v * z[e]).sum();
            worst = worst.max((c[(i, j)] - want).abs());
            scale = scale.max(want.abs());
        }
        if j == vb.len() - 1 {
            s.solve_many_approx(&mut columns, vb.len()).unwrap();
            let zmax = z.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            many_error = max(&columns[j * n..], &z) / zmax;
        }
    }
    let bits = c.iter().fold(0u64, |h, x| (h ^ x.to_bits()).wrapping_mul(0x0100_0000_01b3));
    vec![
        ("error".into(), format!("{:e}", max(&x, &exact))),
        ("difference_from_faer".into(), format!("{:e}", max(&x, &y))),
        ("iterations".into(), (s.iterations() / 2).to_string()),
        ("solver".into(), s.describe()),
        ("compliance_error".into(), format!("{:e}", worst / scale)),
        ("compliance_bits".into(), bits.to_string()),
        ("many_error".into(), format!("{many_error:e}")),
    ]
}

/// 1D convection-diffusion on n points: A = -u'' + c u' (centred) and P = -u'', as triplets.
fn convection_diffusion(n: usize, conv: f64) -> (Vec<(usize, usize, f64)>, Vec<(usize, usize, f64)>) {
    let h = 1.0 / (n + 1) as f64;
    let (mut ta, mut tp) = (Vec::new(), Vec::new());
    for i in 0..n {
        ta.push((i, i, 2.0 / (h * h)));
        tp.push((i, i, 2.0 / (h * h)));
        if i > 0 {
            ta.push((i, i - 1, -1.0 / (h * h) - conv / (2.0 * h)));
            tp.push((i, i - 1, -1.0 / (h * h)));
        }
        if i + 1 < n {
            ta.push((i, i + 1, -1.0 / (h * h) + conv / (2.0 * h)));
            tp.push((i, i + 1, -1.0 / (h * h)));
        }
    }
    (ta, tp)
}

fn shared(petsc: &Petsc) -> Vec<(String, String)> {
    let n = 3000;
    let (rank, size) = (petsc.rank(), petsc.size());
    let (ta, tp) = convection_diffusion(n, 20.0);
    // this rank's share of each entry: the off-diagonal entries whole on rank (i + j) % size,
    // the diagonal in equal parts on every rank; zeros keep the common pattern
    let share = |t: &[(usize, usize, f64)]| -> Vec<(usize, usize, f64)> {
        t.iter().map(|&(i, j, v)| (i, j, if i == j { v / size as f64 } else if (i + j) % size == rank { v } else { 0.0 })).collect()
    };
    // equations owned in blocks of 7, dealt round the ranks in turn
    let owners: Vec<u32> = (0..n).map(|i| ((i / 7) % size) as u32).collect();
    let b: Vec<f64> = (0..n).map(|i| ((i + 1) as f64 * 0.01).sin()).collect();
    let mut s = PetscSolver::new(petsc);
    s.set_partition(Some(owners));
    let mut lu = SparseLu::new();
    let max = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut out = Vec::new();
    for (round, scale) in [(0, 1.0), (1, 3.0)] {
        let scaled = |t: &[(usize, usize, f64)]| -> Vec<(usize, usize, f64)> { t.iter().map(|&(i, j, v)| (i, j, if i == j { v * scale } else { v })).collect() };
        let (a, p) = (scaled(&ta), scaled(&tp));
        s.factorize_preconditioned(csc(n, &share(&a)).as_ref(), Some(csc(n, &share(&p)).as_ref())).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&mut x).unwrap();
        lu.factorize(csc(n, &a).as_ref()).unwrap();
        let mut y = b.clone();
        lu.solve_in_place(&mut y).unwrap();
        let key = if round == 0 { "difference_from_faer" } else { "second_difference_from_faer" };
        out.push((key.to_string(), format!("{:e}", max(&x, &y))));
        if round == 1 {
            let bits = x.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, v| (h ^ v.to_bits()).wrapping_mul(0x0100_0000_01b3));
            out.push(("solution_bits".into(), format!("{bits:x}")));
        }
    }
    out.push(("iterations".into(), (s.iterations() / 2).to_string()));
    out
}

fn failures(petsc: &Petsc) -> Vec<(String, String)> {
    let n = 400;
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i, i, 2.0));
        if i > 0 {
            t.push((i, i - 1, -1.0));
            t.push((i - 1, i, -1.0));
        }
    }
    let a = csc(n, &t);
    let b: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
    let err = |r: stamp::error::Result<()>| match r {
        Ok(()) => "ok".to_string(),
        Err(e) => e.to_string().replace('\n', " "),
    };
    let mut out = Vec::new();
    // a Krylov solve without a preconditioner, two iterations allowed
    let mut s = PetscSolver::with_options(petsc, "-ksp_type gmres -pc_type none -ksp_max_it 2").unwrap();
    let mut x = b.clone();
    let r = s.factorize(a.as_ref()).and_then(|_| s.solve_in_place(&mut x));
    out.push(("diverged".into(), err(r)));
    drop(s);
    // a preconditioner PETSc does not know
    let mut s = PetscSolver::with_options(petsc, "-ksp_max_it 200 -pc_type no_such_pc").unwrap();
    out.push(("unknown_option".into(), err(s.factorize(a.as_ref()))));
    drop(s);
    // a singular matrix: a row and column of zeros
    petsc.insert_options("-pc_type lu").unwrap();
    let t0: Vec<(usize, usize, f64)> = t.iter().map(|&(i, j, v)| if i == 7 || j == 7 { (i, j, 0.0) } else { (i, j, v) }).collect();
    let mut s = PetscSolver::new(petsc);
    let mut x = b.clone();
    let r = s.factorize(csc(n, &t0).as_ref()).and_then(|_| s.solve_in_place(&mut x));
    out.push(("singular".into(), err(r)));
    // rank 1 alone fails: every rank learns it
    let local: Result<(), String> = if petsc.rank() == 1 { Err("disk full".into()) } else { Ok(()) };
    out.push(("one_rank".into(), match petsc.agree(local) { Ok(()) => "ok".into(), Err(e) => e }));
    out
}
