//! The capstan (verification/capstan.py, docs/verification/friction.md): a plate strip wrapped
//! 90 degrees around a fixed cylinder (R = 100, mu = 0.3) along a `path`, then pulled at end 2
//! while end 1 is held by a dead load T1. Once every contact point slips, a belt would give
//! T2 / T1 = e^(mu phi); the plate's thickness (friction at the face, the tension along the
//! mid-surface) and its pinned end lower the ratio by an error proportional to h / R. Run at
//! h = 2 and 1 on cells of 2 (the ratio within 1e-5 of cells of 1), the error must be below 1.5 %
//! and halve with h.

mod common;
use common::*;
use std::process::Command;

/// T2 / T1 and the wrap angle (radians) at the end of the run of thickness `h`, with the counts
/// of sticking and slipping nodes.
fn capstan(h: f64) -> (f64, f64, u64, u64) {
    let o = Command::new("python3").arg(repo().join("verification/capstan.py")).args(["write", &h.to_string(), "0.5"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = run_text(&format!("capstan-{h}"), &String::from_utf8(o.stdout).unwrap());
    let (head, rows) = history(&out);
    let last = rows.len() - 1;
    assert_eq!(column(&head, &rows, "load_factor")[last], 1.0);
    let (r2, r3) = (column(&head, &rows, "bottom_reaction_x2")[last], column(&head, &rows, "bottom_reaction_x3")[last]);
    let d = column(&head, &rows, "cylinder_dissipation");
    assert!(d.windows(2).all(|w| w[1] >= w[0]), "the dissipation decreased");
    let s = summary(&out);
    let c = &s["steps"].as_array().unwrap()[last]["punches"]["cylinder"];
    let phi = std::f64::consts::FRAC_PI_4 + r3.atan2(-r2);
    (r2.hypot(r3) / 100.0, phi, c["sticking_nodes"].as_u64().unwrap(), c["slipping_nodes"].as_u64().unwrap())
}

#[test]
fn the_ratio_of_the_end_tensions_tends_to_the_capstan_formula_as_the_strip_thins() {
    let mu = 0.3f64;
    let belt = (mu * std::f64::consts::FRAC_PI_2).exp();
    let runs = std::thread::scope(|s| {
        let a = s.spawn(|| capstan(2.0));
        let b = s.spawn(|| capstan(1.0));
        [a.join().unwrap(), b.join().unwrap()]
    });
    let mut errors = Vec::new();
    for ((ratio, phi, stick, slip), h) in runs.iter().zip([2.0, 1.0]) {
        let e = ratio / belt - 1.0;
        let e_phi = ratio / (mu * phi).exp() - 1.0;
        println!("h = {h}: T2/T1 = {ratio:.6} against e^(mu pi/2) = {belt:.6} ({e:+.4e}); wrap angle {:.3} deg, against e^(mu phi) {e_phi:+.4e}; {slip} slipping, {stick} sticking", phi.to_degrees());
        // every point in contact slides: the onset of slip has passed
        assert!(*stick == 0 && *slip > 100, "h = {h}: {stick} sticking, {slip} slipping");
        assert!(e < 0.0 && e > -0.015, "h = {h}: T2/T1 {ratio} against {belt}");
        errors.push(e);
    }
    // the error is proportional to h / R
    let halving = errors[1] / errors[0];
    assert!((halving - 0.5).abs() < 0.05, "error at h = 1 over the error at h = 2: {halving}");
}
