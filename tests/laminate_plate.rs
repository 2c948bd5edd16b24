//! The laminated plate (`stamp_elements::LaminatePlate`): a stack of multi-surface plies sharing
//! their interface surfaces, each with its 3D law turned by its angle. Checked: the tangent and
//! the residual against central differences on an unsymmetric orthotropic stack at a
//! large-displacement state (both kinematics); rigid motions strain- and force-free; the energy of
//! any homogeneous deformation is the anisotropic Saint Venant-Kirchhoff energy of every ply (on a
//! distorted element whose local frame is turned from x1, so the ply angle is taken from x1); one
//! isotropic ply is the multi-surface plate; a stack of identical isotropic plies reproduces the
//! homogeneous plate on every displacement that plate can take.

mod common;
use common::*;
use stamp::element::{Element, LocalSystem};
use stamp::mesh::QuadMesh;
use stamp_elements::multi_surface::lagrange;
use stamp_elements::orthotropic::rotate;
use stamp_elements::{
    FiveSurfaceLaminate, FiveSurfacePlate, FourSurfaceLaminate, FourSurfacePlate, Isotropic, Kinematics, Laminate, Layer, Orthotropic, Ply, PlyMaterial, Section,
    ThreeSurfaceLaminate, ThreeSurfacePlate,
};

/// A ply of Pagano's material (E1/E2 = 25, G12 = G13 = 0.5 E2, G23 = 0.2 E2, nu = 0.25), scaled.
fn pagano_ply() -> PlyMaterial {
    PlyMaterial::Orthotropic(Orthotropic::new([25.0e4, 1.0e4, 1.0e4], [0.5e4, 0.5e4, 0.2e4], [0.25; 3]).unwrap())
}

/// An unsymmetric stack: three plies of different thicknesses and angles, one isotropic.
fn unsymmetric() -> Laminate {
    Laminate::new(vec![
        Ply { thickness: 0.03, material: pagano_ply(), angle: 0.0 },
        Ply { thickness: 0.05, material: pagano_ply(), angle: 45.0 },
        Ply { thickness: 0.02, material: PlyMaterial::Isotropic(Isotropic::new(3.0e4, 0.3).unwrap()), angle: 0.0 },
        Ply { thickness: 0.04, material: pagano_ply(), angle: -30.0 },
    ])
    .unwrap()
}

enum AnyLaminate {
    Three(ThreeSurfaceLaminate),
    Four(FourSurfaceLaminate),
    Five(FiveSurfaceLaminate),
}

fn laminate_of(n: usize, mesh: &QuadMesh, l: Laminate, kin: Kinematics) -> AnyLaminate {
    match n {
        3 => AnyLaminate::Three(ThreeSurfaceLaminate::new(mesh, l, kin).unwrap()),
        4 => AnyLaminate::Four(FourSurfaceLaminate::new(mesh, l, kin).unwrap()),
        _ => AnyLaminate::Five(FiveSurfaceLaminate::new(mesh, l, kin).unwrap()),
    }
}

fn eval_n<E: Element>(plate: &E, v: &[f64], tangent: bool) -> LocalSystem {
    let mut ws = plate.new_workspace();
    let mut out = LocalSystem::new(v.len());
    plate.evaluate(0, v, &mut ws, &mut out, tangent);
    out
}

fn eval_l(p: &AnyLaminate, v: &[f64], tangent: bool) -> LocalSystem {
    match p {
        AnyLaminate::Three(p) => eval_n(p, v, tangent),
        AnyLaminate::Four(p) => eval_n(p, v, tangent),
        AnyLaminate::Five(p) => eval_n(p, v, tangent),
    }
}

/// Local dofs of element 0 for the displacement field `u(X)` at the surfaces `z` (x3, in the
/// order of the unknowns) of each node.
fn dofs_at(z: &[f64], mesh: &QuadMesh, u: &dyn Fn([f64; 3]) -> [f64; 3]) -> Vec<f64> {
    let m = z.len();
    let mut v = vec![0.0; 12 * m];
    for a in 0..4 {
        let x = mesh.coords[mesh.cells[0][a]];
        for (s, &x3) in z.iter().enumerate() {
            let d = u([x[0], x[1], x3]);
            v[3 * (m * a + s)..3 * (m * a + s) + 3].copy_from_slice(&d);
        }
    }
    v
}

/// X -> F X + c applied as a displacement (F - I) X + c.
fn affine(f: [[f64; 3]; 3], c: [f64; 3]) -> impl Fn([f64; 3]) -> [f64; 3] {
    move |x| std::array::from_fn(|i| c[i] + (0..3).map(|j| f[i][j] * x[j]).sum::<f64>() - x[i])
}

#[test]
fn tangent_of_an_unsymmetric_orthotropic_stack_matches_central_differences() {
    let mesh = distorted_element();
    let lam = unsymmetric();
    let mut rng = Lcg(17);
    for n in [3, 4] {
        let m = lam.plies.len() * (n - 1) + 1;
        let nd = 12 * m;
        for kin in [Kinematics::Nonlinear, Kinematics::Linear] {
            let plate = laminate_of(n, &mesh, lam.clone(), kin);
            let v: Vec<f64> = (0..nd).map(|_| rng.range(-0.05, 0.05)).collect();
            let k = eval_l(&plate, &v, true).tangent;
            let r = eval_l(&plate, &v, false).residual;
            let scale = max_abs(&k);
            let step = 1e-6;
            let (mut worst, mut worst_g) = (0.0f64, 0.0f64);
            for j in 0..nd {
                let (mut vp, mut vm) = (v.clone(), v.clone());
                vp[j] += step;
                vm[j] -= step;
                let (op, om) = (eval_l(&plate, &vp, false), eval_l(&plate, &vm, false));
                for i in 0..nd {
                    worst = worst.max(((op.residual[i] - om.residual[i]) / (2.0 * step) - k[i * nd + j]).abs() / scale);
                }
                worst_g = worst_g.max(((op.energy - om.energy) / (2.0 * step) - r[j]).abs() / max_abs(&r));
            }
            assert!(worst < 1e-7, "{n} surfaces per ply, {kin:?}: tangent against central differences: {worst:e}");
            assert!(worst_g < 1e-6, "{n} surfaces per ply, {kin:?}: residual against the energy's differences: {worst_g:e}");
            let asym = (0..nd).flat_map(|i| (0..nd).map(move |j| (i, j))).map(|(i, j)| (k[i * nd + j] - k[j * nd + i]).abs()).fold(0.0, f64::max);
            assert!(asym <= 1e-12 * scale, "{n} surfaces per ply, {kin:?}: tangent not symmetric: {asym:e}");
        }
    }
}

#[test]
fn rigid_body_motions_of_a_stack_are_strain_and_force_free() {
    let mesh = distorted_element();
    let lam = unsymmetric();
    let pi = std::f64::consts::PI;
    for n in 3..=5 {
        let z = lam.surfaces_in_dof_order(n);
        let plate = laminate_of(n, &mesh, lam.clone(), Kinematics::Nonlinear);
        let k_scale = max_abs(&eval_l(&plate, &vec![0.0; 12 * z.len()], true).tangent);
        let mut rng = Lcg(29);
        for trial in 0..12 {
            let rot = euler_krylov(rng.range(-pi, pi), rng.range(-pi, pi), rng.range(-pi, pi));
            let shift = [rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), rng.range(-5.0, 5.0)];
            let v = dofs_at(&z, &mesh, &affine(rot, shift));
            let out = eval_l(&plate, &v, false);
            let force = max_abs(&out.residual);
            let v_scale = max_abs(&v);
            assert!(force <= 1e-12 * k_scale * v_scale, "{n} per ply, trial {trial}: internal force {force:e}");
            assert!(out.energy.abs() <= 1e-24 * k_scale * v_scale * v_scale, "{n} per ply, trial {trial}: energy {:e}", out.energy);
            assert!(out.inadmissible.is_none());
        }
        // and a real strain is not: the interfaces carry it
        let v = dofs_at(&z, &mesh, &affine([[1.01, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], [0.0; 3]));
        assert!(eval_l(&plate, &v, false).energy > 0.0);
        let mirror = dofs_at(&z, &mesh, &affine([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]], [0.0; 3]));
        assert!(eval_l(&plate, &mirror, false).inadmissible.is_some(), "a mirror image is refused");
    }
}

/// The energy of a homogeneous deformation F is sum over the plies of thickness x area x
/// E.C(angle)E / 2, E = (F^T F - I)/2 in the plate's axes: on a distorted element whose t1 is
/// turned from x1 by about 8.5 degrees, so a law turned by the element's frame instead of x1 fails.
#[test]
fn homogeneous_deformations_have_each_plys_anisotropic_energy() {
    let mesh = distorted_element();
    let lam = unsymmetric();
    let area = {
        let x = mesh.cell_coords(0);
        0.5 * ((x[2][0] - x[0][0]) * (x[3][1] - x[1][1]) - (x[3][0] - x[1][0]) * (x[2][1] - x[0][1]))
    };
    for n in 3..=5 {
        let z = lam.surfaces_in_dof_order(n);
        for kin in [Kinematics::Nonlinear, Kinematics::Linear] {
            let plate = laminate_of(n, &mesh, lam.clone(), kin);
            let mut rng = Lcg(7);
            for trial in 0..6 {
                let f: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| (i == j) as u8 as f64 + rng.range(-0.2, 0.2)));
                let e: [[f64; 3]; 3] = std::array::from_fn(|i| {
                    std::array::from_fn(|j| {
                        let lin = 0.5 * (f[i][j] + f[j][i]) - (i == j) as u8 as f64;
                        match kin {
                            Kinematics::Nonlinear => 0.5 * ((0..3).map(|k| f[k][i] * f[k][j]).sum::<f64>() - (i == j) as u8 as f64),
                            Kinematics::Linear => lin,
                        }
                    })
                });
                let ev = [e[0][0], e[1][1], e[2][2], 2.0 * e[1][2], 2.0 * e[0][2], 2.0 * e[0][1]];
                let want: f64 = lam
                    .plies
                    .iter()
                    .map(|p| {
                        let c = rotate(&p.material.stiffness(), p.angle.to_radians());
                        let w: f64 = (0..6).map(|i| (0..6).map(|j| ev[i] * c[i][j] * ev[j]).sum::<f64>()).sum();
                        0.5 * w * p.thickness * area
                    })
                    .sum();
                let v = dofs_at(&z, &mesh, &affine(f, [0.1, -0.2, 0.3]));
                let got = eval_l(&plate, &v, false).energy;
                assert!((got - want).abs() <= 1e-11 * want, "{n} per ply, {kin:?}, trial {trial}: energy {got} against {want}");
            }
        }
    }
}

/// One isotropic ply is the multi-surface plate: the same residual, tangent and energy.
#[test]
fn one_isotropic_ply_is_the_multi_surface_plate() {
    let mesh = distorted_element();
    let iso = Isotropic::new(2.0e5, 0.3).unwrap();
    let lam = Laminate::new(vec![Ply { thickness: 0.12, material: PlyMaterial::Isotropic(iso), angle: 30.0 }]).unwrap();
    let sec = Section::homogeneous(0.12, iso).unwrap();
    let mut rng = Lcg(41);
    for n in 3..=5 {
        let v: Vec<f64> = (0..12 * n).map(|_| rng.range(-0.05, 0.05)).collect();
        let (a, b) = match n {
            3 => (eval_n(&ThreeSurfaceLaminate::new(&mesh, lam.clone(), Kinematics::Nonlinear).unwrap(), &v, true), eval_n(&ThreeSurfacePlate::new(&mesh, sec.clone(), Kinematics::Nonlinear).unwrap(), &v, true)),
            4 => (eval_n(&FourSurfaceLaminate::new(&mesh, lam.clone(), Kinematics::Nonlinear).unwrap(), &v, true), eval_n(&FourSurfacePlate::new(&mesh, sec.clone(), Kinematics::Nonlinear).unwrap(), &v, true)),
            _ => (eval_n(&FiveSurfaceLaminate::new(&mesh, lam.clone(), Kinematics::Nonlinear).unwrap(), &v, true), eval_n(&FiveSurfacePlate::new(&mesh, sec.clone(), Kinematics::Nonlinear).unwrap(), &v, true)),
        };
        let rel = |x: &[f64], y: &[f64]| x.iter().zip(y).fold(0.0f64, |m, (p, q)| m.max((p - q).abs())) / max_abs(y);
        assert!(rel(&a.residual, &b.residual) < 1e-13, "{n}: residual");
        assert!(rel(&a.tangent, &b.tangent) < 1e-13, "{n}: tangent");
        assert!((a.energy - b.energy).abs() < 1e-13 * b.energy, "{n}: energy");
    }
}

/// A stack of L identical isotropic plies of N surfaces each holds every displacement of the
/// homogeneous N-surface plate (a polynomial of degree N - 1 through the whole thickness is one in
/// each ply): with T the map from the homogeneous plate's unknowns to the stack's (the polynomial
/// at the stack's surfaces), E_stack(T v) = E_hom(v), T^T r_stack(T v) = r_hom(v) and
/// T^T K_stack T = K_hom, against a homogeneous section of the same L layers (the same Gauss levels;
/// exact also for the nonlinear energy, which N levels per layer do not integrate exactly).
#[test]
fn identical_isotropic_plies_reproduce_the_homogeneous_plate() {
    let mesh = distorted_element();
    let iso = Isotropic::new(2.0e5, 0.3).unwrap();
    let thick = [0.04, 0.03, 0.05];
    let lam = Laminate::new(thick.iter().map(|&t| Ply { thickness: t, material: PlyMaterial::Isotropic(iso), angle: 0.0 }).collect()).unwrap();
    let h: f64 = thick.iter().sum();
    let b = lam.boundaries();
    let sec = Section {
        delta_minus: -0.5 * h,
        delta_plus: 0.5 * h,
        layers: (0..3).map(|k| Layer { bottom: b[k], top: b[k + 1], material: iso }).collect(),
        shear_factor: 1.0,
        normal_stress: Default::default(),
    };
    sec.validate().unwrap();
    let mut rng = Lcg(43);
    for n in 3..=5 {
        let zh = stamp_elements::multi_surface::surface_zetas(n);
        let zs = lam.surfaces_in_dof_order(n);
        let (mh, ms) = (n, zs.len());
        // T: stack dof (a, s, i) = sum_t L_t(zeta_s) hom dof (a, t, i)
        let (dh, ds) = (12 * mh, 12 * ms);
        let mut t = vec![0.0; ds * dh];
        for a in 0..4 {
            for (s, &x3) in zs.iter().enumerate() {
                let (l, _) = lagrange(&zh, 2.0 * x3 / h);
                for (tt, &lt) in l.iter().enumerate() {
                    for i in 0..3 {
                        t[(3 * (ms * a + s) + i) * dh + 3 * (mh * a + tt) + i] = lt;
                    }
                }
            }
        }
        for kin in [Kinematics::Nonlinear, Kinematics::Linear] {
            let v: Vec<f64> = (0..dh).map(|_| rng.range(-0.05, 0.05)).collect();
            let vs: Vec<f64> = (0..ds).map(|r| (0..dh).map(|c| t[r * dh + c] * v[c]).sum()).collect();
            let (hom, stack) = match n {
                3 => (eval_n(&ThreeSurfacePlate::new(&mesh, sec.clone(), kin).unwrap(), &v, true), eval_n(&ThreeSurfaceLaminate::new(&mesh, lam.clone(), kin).unwrap(), &vs, true)),
                4 => (eval_n(&FourSurfacePlate::new(&mesh, sec.clone(), kin).unwrap(), &v, true), eval_n(&FourSurfaceLaminate::new(&mesh, lam.clone(), kin).unwrap(), &vs, true)),
                _ => (eval_n(&FiveSurfacePlate::new(&mesh, sec.clone(), kin).unwrap(), &v, true), eval_n(&FiveSurfaceLaminate::new(&mesh, lam.clone(), kin).unwrap(), &vs, true)),
            };
            let r: Vec<f64> = (0..dh).map(|c| (0..ds).map(|rr| t[rr * dh + c] * stack.residual[rr]).sum()).collect();
            let mut k = vec![0.0; dh * dh];
            let mut kt = vec![0.0; ds * dh]; // K_stack T
            for i in 0..ds {
                for j in 0..dh {
                    kt[i * dh + j] = (0..ds).map(|l| stack.tangent[i * ds + l] * t[l * dh + j]).sum();
                }
            }
            for i in 0..dh {
                for j in 0..dh {
                    k[i * dh + j] = (0..ds).map(|l| t[l * dh + i] * kt[l * dh + j]).sum();
                }
            }
            let rel = |x: &[f64], y: &[f64]| x.iter().zip(y).fold(0.0f64, |m, (p, q)| m.max((p - q).abs())) / max_abs(y);
            assert!((stack.energy - hom.energy).abs() < 1e-11 * hom.energy, "{n}, {kin:?}: energy {} against {}", stack.energy, hom.energy);
            assert!(rel(&r, &hom.residual) < 1e-11, "{n}, {kin:?}: residual differs by {:e}", rel(&r, &hom.residual));
            assert!(rel(&k, &hom.tangent) < 1e-11, "{n}, {kin:?}: tangent differs by {:e}", rel(&k, &hom.tangent));
        }
    }
}
