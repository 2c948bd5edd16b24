//! Laminates in cylindrical bending against the exact 3D solution (N. J. Pagano, J. Compos. Mater.
//! 3 (1969) 398, and for angle plies 4 (1970) 330; tests/common/cylindrical.rs): a plate infinite
//! in x2, simply supported at x1 = 0 and a, q0 sin(pi x1/a) on its top face; Pagano's ply (E1/E2 =
//! 25, G12 = G13 = 0.5 E2, G23 = 0.2 E2, nu = 0.25, E3 = E2), plies of equal thickness. The plate is
//! a strip of n x 1 elements along x1 whose nodes at x2 = 0 and x2 = b are the same nodes (the
//! element's cells renumbered: periodic in x2, so nothing depends on x2).

mod common;
use common::cylindrical::Cylindrical;
use common::pagano::Layer;
use stamp::dofs::DofMap;
use stamp::element::{Element, LocalSystem};
use stamp::linalg::linear_solver::SparseLu;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearSolver};
use stamp_elements::multi_surface::lagrange;
use stamp_elements::orthotropic::rotate;
use stamp_elements::{Kinematics, Laminate, LaminatePlate, Orthotropic, Ply, PlyMaterial};

fn material() -> PlyMaterial {
    PlyMaterial::Orthotropic(Orthotropic::new([25.0, 1.0, 1.0], [0.5, 0.5, 0.2], [0.25; 3]).unwrap())
}

fn stack(angles: &[f64], h: f64) -> Vec<Layer> {
    angles.iter().map(|&a| Layer { thickness: h / angles.len() as f64, c: rotate(&material().stiffness(), a.to_radians()) }).collect()
}

/// An element whose cells are another's renumbered: the strip's nodes on x2 = b are those on x2 = 0.
struct Periodic<E: Element> {
    inner: E,
    cells: Vec<[usize; 4]>,
}

impl<E: Element> Element for Periodic<E> {
    type Workspace = E::Workspace;
    fn dofs_per_node(&self) -> usize {
        self.inner.dofs_per_node()
    }
    fn nodes_per_element(&self) -> usize {
        4
    }
    fn num_elements(&self) -> usize {
        self.cells.len()
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        &self.cells[e]
    }
    fn new_workspace(&self) -> E::Workspace {
        self.inner.new_workspace()
    }
    fn evaluate(&self, e: usize, u: &[f64], ws: &mut E::Workspace, out: &mut LocalSystem, with_tangent: bool) {
        self.inner.evaluate(e, u, ws, out, with_tangent)
    }
}

/// The compared values: (name, x1, x3, ply, what) with what = 6 for w, else the stress component
/// [s11, s22, s33, s23, s13, s12].
type Point = (&'static str, f64, f64, usize, usize);

/// The points of a stack (x1 as a fraction of a; the FE stresses are those at the centre of the
/// element next to x1, compared with the exact ones there): w at the centre of the mid-plane, s11
/// (and for angle plies s22, s12) on both faces at the centre, the transverse shears at the
/// support x1 = 0 at the mid-plane (for two plies, the mid-plane is their interface: there each
/// ply's law gives its own value, and the points are the middles of the plies instead).
fn points(angles: &[f64]) -> Vec<Point> {
    let l = angles.len();
    let top = l - 1;
    let mut p = vec![("w", 0.5, 0.0, 0, 6), ("s11 top", 0.5, 0.5, top, 0), ("s11 bottom", 0.5, -0.5, 0, 0)];
    let angled = angles.iter().any(|a| a % 90.0 != 0.0);
    if angled {
        p.extend([("s22 top", 0.5, 0.5, top, 1), ("s22 bottom", 0.5, -0.5, 0, 1), ("s12 top", 0.5, 0.5, top, 5), ("s12 bottom", 0.5, -0.5, 0, 5)]);
    }
    let shear: Vec<(f64, usize)> = if l % 2 == 1 { vec![(0.0, l / 2)] } else { vec![(-0.25, l / 2 - 1), (0.25, l / 2)] };
    for (z, k) in shear {
        p.push(if z < 0.0 { ("s13 lower", 0.0, z, k, 4) } else if z > 0.0 { ("s13 upper", 0.0, z, k, 4) } else { ("s13", 0.0, z, k, 4) });
        if angled {
            p.push(if z < 0.0 { ("s23 lower", 0.0, z, k, 3) } else { ("s23 upper", 0.0, z, k, 3) });
        }
    }
    p
}

/// The FE strip (n elements along x1, N surfaces per ply, linear kinematics, h = 1, a = S, q0 = 1
/// upwards) and the exact solution at the points: (FE, exact) for each point.
fn fe<const N: usize, const P: usize, const D: usize>(angles: &[f64], sr: f64, n: usize) -> Vec<(f64, f64)> {
    assert!(n % 2 == 0);
    let (a, h) = (sr, 1.0);
    let lam = Laminate::new(angles.iter().map(|&angle| Ply { thickness: h / angles.len() as f64, material: material(), angle }).collect()).unwrap();
    let le = a / n as f64;
    let mesh = QuadMesh::rectangle(0.0, a, 0.0, le, n, 1).unwrap();
    let plate = LaminatePlate::<N, P, D>::new(&mesh, lam.clone(), Kinematics::Linear).unwrap();
    // the top row's nodes n + 1 + i are the bottom row's i
    let fold = |node: usize| node % (n + 1);
    let cells = mesh.cells.iter().map(|c| c.map(fold)).collect();
    let m = lam.surfaces_in_dof_order(N).len();
    let mut dofs = DofMap::new(n + 1, 3 * m).unwrap();
    let comps = |c: &[usize]| (0..m).flat_map(|s| c.iter().map(move |&i| 3 * s + i)).collect::<Vec<_>>();
    dofs.fix(&[0, n], &comps(&[2])).unwrap(); // the supports: u3 = 0 on the whole fibre
    // u1 = u2 = 0 at the centre (the exact fields are odd about it): no rigid translation
    dofs.fix(&[n / 2], &comps(&[0, 1])).unwrap();
    let mut model = Model::new(Periodic { inner: plate, cells }, dofs).unwrap();
    // consistent nodal forces of q0 sin(pi x1/a) on the top face (slot 1), 3 Gauss points per element
    let g3 = [(-0.774_596_669_241_483_4, 5.0 / 9.0), (0.0, 8.0 / 9.0), (0.774_596_669_241_483_4, 5.0 / 9.0)];
    let pi = std::f64::consts::PI;
    for e in 0..n {
        for &(s, ws) in &g3 {
            let x = (e as f64 + 0.5 * (s + 1.0)) * le;
            let q = (pi * x / a).sin() * ws * 0.5 * le * le;
            for (node, shape) in [(e, 0.5 * (1.0 - s)), (e + 1, 0.5 * (1.0 + s))] {
                model.add_load(node * 3 * m + 3 + 2, shape * q).unwrap();
            }
        }
    }
    let mut newton = NewtonRaphson::new(SparseLu::new(), NewtonSettings::default());
    let mut u = vec![0.0; model.dofs.num_dofs()];
    newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
    let exact = Cylindrical::new(stack(angles, h), a, 1.0);
    let plate = &model.element.inner;
    let cells = &model.element.cells;
    let mut ws = plate.new_workspace();
    points(angles)
        .iter()
        .map(|&(_, xf, x3, k, what)| {
            if what == 6 {
                // u3 at the centre node, at height x3 in ply k
                let node = n / 2;
                let k = lam.ply_at(x3);
                let b = lam.boundaries();
                let zs: Vec<f64> = (0..N).map(|s| b[k] + (b[k + 1] - b[k]) * s as f64 / (N - 1) as f64).collect();
                let (l, _) = lagrange(&zs, x3);
                let w: f64 = lam.ply_slots(N, k).iter().zip(&l).map(|(&sl, &ls)| ls * u[node * 3 * m + 3 * sl + 2]).sum();
                return (w, exact.displacement(0.5 * a, x3)[2]);
            }
            let e = if xf > 0.0 { n / 2 - 1 } else { 0 };
            let xc = (e as f64 + 0.5) * le;
            let v: Vec<f64> = cells[e].iter().flat_map(|&nd| u[nd * 3 * m..(nd + 1) * 3 * m].to_vec()).collect();
            let s = plate.stresses_at(e, k, x3 * h, &v, &mut ws);
            (0.25 * s.iter().map(|g| g[what]).sum::<f64>(), exact.stress(k, xc, x3 * h)[what])
        })
        .collect()
}

/// The exact solution obeys 3D elasticity: the stresses from its state equal each ply's law
/// applied to the strains of its displacement (central differences), equilibrium holds (central
/// differences of the stresses), the bottom face is free and the top carries q0 sin(pi x1/a); for
/// cross plies it is the square plate's solution (tests/common/pagano.rs) for b = 1000 a.
#[test]
fn exact_solution_is_3d_elasticity() {
    for angles in [&[0.0, 90.0, 0.0][..], &[0.0, 90.0][..], &[30.0, -30.0][..], &[15.0, -15.0][..]] {
        let a = 4.0;
        let ex = Cylindrical::new(stack(angles, 1.0), a, 1.0);
        let d = 1e-4;
        for &(x, z) in &[(0.3, -0.3), (1.1, -0.05), (1.7, 0.2), (2.9, 0.45)] {
            let k = ex.stack.layer_at(z);
            let du = |i: usize, dx: f64, dz: f64| (ex.displacement(x + dx, z + dz)[i] - ex.displacement(x - dx, z - dz)[i]) / (2.0 * d);
            let e = [du(0, d, 0.0), 0.0, du(2, 0.0, d), du(1, 0.0, d), du(0, 0.0, d) + du(2, d, 0.0), du(1, d, 0.0)];
            let c = &ex.layers[k].c;
            let s = ex.stress(k, x, z);
            let ds = |i: usize, dx: f64, dz: f64| (ex.stress(k, x + dx, z + dz)[i] - ex.stress(k, x - dx, z - dz)[i]) / (2.0 * d);
            let scale = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..6 {
                let law: f64 = (0..6).map(|j| c[i][j] * e[j]).sum();
                assert!((law - s[i]).abs() < 1e-6 * scale, "{angles:?} ({x}, {z}): s[{i}] {} against the law {law}", s[i]);
            }
            // s11,1 + s13,3 = 0, s12,1 + s23,3 = 0, s13,1 + s33,3 = 0
            for (r, (i, j)) in [(0, 4), (5, 3), (4, 2)].into_iter().enumerate() {
                let div = ds(i, d, 0.0) + ds(j, 0.0, d);
                assert!(div.abs() < 1e-5 * scale, "{angles:?} ({x}, {z}): equilibrium {r} off by {div}");
            }
        }
        for x in [0.5, 2.0] {
            let (bottom, top) = (ex.stress(0, x, -0.5), ex.stress(angles.len() - 1, x, 0.5));
            for i in 2..5 {
                let want = if i == 2 { (std::f64::consts::PI * x / a).sin() } else { 0.0 };
                assert!(bottom[i].abs() < 1e-9 && (top[i] - want).abs() < 1e-9, "{angles:?}: face tractions {bottom:?} {top:?}");
            }
        }
        if angles.iter().all(|t| t % 90.0 == 0.0) {
            let plate = common::pagano::Pagano::new(stack(angles, 1.0), a, 1000.0 * a, 1.0);
            for z in [-0.5, 0.1, 0.5] {
                let (w, wp) = (ex.displacement(1.0, z)[2], plate.displacement(1.0, 500.0 * a, z)[2]);
                assert!((w / wp - 1.0).abs() < 1e-5, "{angles:?}: w {w} against the long plate's {wp}");
            }
        }
    }
}

/// Against the published values that could be found: the deflection w = 100 E2 h^3 w(a/2) / (q0
/// a^4) of Pagano (1969) as quoted in the comments of the FinEtools Pagano examples (P. Krysl):
/// [0], [0/90], [0/90/0] at S = 4: 1.969, 4.694, 2.906 (the height not stated; the thickness mean
/// here matches within 0.2 %, the mid-plane value of [0/90/0] is 2.887), and their classical
/// plate theory limits 0.494, 2.622, 0.514, which the exact solution approaches at S = 100.
#[test]
fn exact_solution_against_published_deflections() {
    for (angles, thick, thin) in [(&[0.0][..], 1.969, 0.494), (&[0.0, 90.0][..], 4.694, 2.622), (&[0.0, 90.0, 0.0][..], 2.906, 0.514)] {
        let norm = |sr: f64| 100.0 / sr.powi(4);
        let ex = Cylindrical::new(stack(angles, 1.0), 4.0, 1.0);
        // the thickness mean at the centre (Simpson, 200 intervals)
        let mean = (0..=200).map(|i| (if i == 0 || i == 200 { 1.0 } else if i % 2 == 1 { 4.0 } else { 2.0 }) * ex.displacement(2.0, -0.5 + i as f64 / 200.0)[2]).sum::<f64>() / 600.0;
        let w100 = norm(100.0) * Cylindrical::new(stack(angles, 1.0), 100.0, 1.0).displacement(50.0, 0.0)[2];
        println!("{angles:?}: S = 4 mean {:.4} (quoted {thick}), mid-plane {:.4}; S = 100 {w100:.4} (CPT {thin})", norm(4.0) * mean, norm(4.0) * ex.displacement(2.0, 0.0)[2]);
        assert!((norm(4.0) * mean / thick - 1.0).abs() < 2e-3, "{angles:?}: S = 4 mean {} against {thick}", norm(4.0) * mean);
        assert!((w100 - thin).abs() < 6e-4, "{angles:?}: S = 100 {w100} against {thin}");
    }
}

/// The element, mesh-converged: the strip with n = 32 and 64 elements along a, five surfaces per
/// ply, [0/90/0], [0/90] and [30/-30] at S = 4 and 10: w within 0.1 % and the in-plane stresses
/// within 1 % at n = 64, their errors falling like l^2; the transverse shears within 1 %, except
/// in the two-ply stacks at S = 4 (thick plies of h/2), where the five-surface model itself is
/// 1.0 % off in the middle of the plies (its continuum limit, printed for the cross-ply stacks:
/// six surfaces per ply take it below 0.1 %).
#[test]
fn element_converges_to_the_exact_cylindrical_bending() {
    println!("errors in %, n = 32 / 64, five surfaces per ply");
    for angles in [&[0.0, 90.0, 0.0][..], &[0.0, 90.0][..], &[30.0, -30.0][..]] {
        for sr in [4.0, 10.0] {
            let (r32, r64) = (fe::<5, 20, 60>(angles, sr, 32), fe::<5, 20, 60>(angles, sr, 64));
            let err = |r: &[(f64, f64)], i: usize| 100.0 * (r[i].0 / r[i].1 - 1.0);
            let pts = points(angles);
            let line: Vec<String> = pts.iter().enumerate().map(|(i, p)| format!("{} {:+.3} / {:+.3}", p.0, err(&r32, i), err(&r64, i))).collect();
            println!("{angles:?} S = {sr}: {}", line.join(", "));
            for (i, p) in pts.iter().enumerate() {
                let bound = match p.4 {
                    6 => 0.1,
                    3 | 4 if angles.len() == 2 && sr < 5.0 => 1.1,
                    _ => 1.0,
                };
                assert!(err(&r64, i).abs() < bound, "{angles:?}, S = {sr}: {} off by {:.3} %", p.0, err(&r64, i));
                if p.4 == 6 || p.4 == 0 {
                    assert!(err(&r64, i).abs() < 0.4 * err(&r32, i).abs(), "{angles:?}, S = {sr}: {} does not converge like l^2: {:.4} % then {:.4} %", p.0, err(&r32, i), err(&r64, i));
                }
            }
            if angles.iter().all(|t| t % 90.0 == 0.0) {
                let ex = Cylindrical::new(stack(angles, 1.0), sr, 1.0);
                let mut limits = Vec::new();
                for n in [5, 6] {
                    let lw = common::pagano::Layerwise::new(stack(angles, 1.0), n, sr, 1000.0 * sr, 1.0);
                    for p in pts.iter().filter(|p| p.4 == 4) {
                        let e = 100.0 * (lw.stress(p.3, p.1 * sr, 500.0 * sr, p.2)[4] / ex.stress(p.3, p.1 * sr, p.2)[4] - 1.0);
                        limits.push(format!("{} N = {n}: {e:+.3}", p.0));
                        if n == 6 {
                            assert!(e.abs() < 0.1, "{angles:?}, S = {sr}: six surfaces' limit of {} off by {e:.3} %", p.0);
                        }
                    }
                }
                println!("    continuum limit: {}", limits.join(", "));
            }
        }
    }
}
