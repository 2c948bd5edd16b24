//! Verification of the plate under a sphere: mesh convergence of the sphere problem.
//!
//! Clamped square plate a = 40, h = 1, E = 2e5, nu = 0.3, pressed at its centre by a rigid sphere
//! R = 40 moved 2 (twice the thickness: membrane action), quarter model, automatic eps_reg
//! (100 E h / (l_e^2 (2R)^2), so the penetration also falls with l_e^2). Four meshes: structured
//! 8 x 8 and 16 x 16, and distorted 8 x 8 and 16 x 16 (every interior node moved at random by up to a
//! quarter of the element size, nodes on the edges and symmetry lines along them; the distortion
//! does not fade with refinement), and a structured 20 x 20 as the reference. Reported: the centre
//! deflection (mid-surface), the punch's force on the whole plate, the contact radius (zero of the
//! gap on the x1 axis, interpolated), the outermost loaded node, the force-weighted mean radius.
//! Required: on both families the 16 x 16 result is closer to the reference than the 8 x 8 one, and
//! structured and distorted meshes approach each other.
//!
//! `cargo test --release --test verify_convergence -- --nocapture` prints the table (README, "Mesh
//! convergence (sphere problem)").

mod common;
use common::sphere::*;

fn problem(n: usize, distortion: f64) -> SphereProblem {
    let mut p = SphereProblem::new(40.0, 1.0, n, Support::Clamped);
    p.radius = 40.0;
    p.depth = 2.0;
    p.distortion = distortion;
    p.seed = 3;
    p
}

#[test]
fn sphere_problem_converges_on_structured_and_distorted_meshes() {
    let cases = [("structured", 8, 0.0), ("structured", 16, 0.0), ("distorted", 8, 0.25), ("distorted", 16, 0.25), ("structured (reference)", 20, 0.0)];
    let mut rows = Vec::new();
    println!("| mesh (quarter) | elements | centre deflection | reaction P | contact radius (axis) | outermost loaded node | force-weighted radius | loaded nodes |");
    println!("|---|---|---|---|---|---|---|---|");
    for (what, n, d) in cases {
        let clock = std::time::Instant::now();
        let r = problem(n, d).solve(&[1.0]).last().unwrap().1;
        eprintln!("{what} {n}: {:.2} s", clock.elapsed().as_secs_f64());
        println!("| {what} | {n} x {n} | {:.6} | {:.1} | {:.4} | {:.4} | {:.4} | {} |", r.w, r.reaction, r.edge, r.radius, r.force_radius, r.active);
        rows.push(r);
    }
    let [s8, s16, d8, d16, reference] = [rows[0], rows[1], rows[2], rows[3], rows[4]];
    let quantities: [(&str, fn(&SphereResult) -> f64); 3] = [("centre deflection", |r| r.w), ("reaction", |r| r.reaction), ("contact radius", |r| r.edge)];
    for (what, f) in quantities {
        let e = |r: &SphereResult| (f(r) - f(&reference)).abs() / f(&reference);
        let gap = |a: &SphereResult, b: &SphereResult| (f(a) - f(b)).abs() / f(&reference);
        println!(
            "{what}: difference from the 20 x 20 reference: structured {:.2e} -> {:.2e}, distorted {:.2e} -> {:.2e}; structured vs distorted {:.2e} -> {:.2e}",
            e(&s8), e(&s16), e(&d8), e(&d16), gap(&s8, &d8), gap(&s16, &d16)
        );
        assert!(e(&s16) < e(&s8), "{what}: the structured mesh does not converge");
        assert!(e(&d16) < e(&d8), "{what}: the distorted mesh does not converge");
        assert!(gap(&s16, &d16) < gap(&s8, &d8) || gap(&s16, &d16) < 1e-3, "{what}: structured and distorted meshes do not approach each other");
        assert!(e(&s16) < 0.02 && e(&d16) < 0.02, "{what}: 16 x 16 is more than 2 % off the reference");
    }
}
