//! The damped growth of the active set: which penetrating points enter in an evaluation with
//! a tangent, and that the held-back ones still count as changes until they are in.
use super::{ContactKinematics, ContactPair, ContactPoint, LONE_MAX_FLIPS, RELEASE_FRACTION};
use crate::surface::ContactSurface;
use nalgebra::Vector3;
use std::sync::Arc;

/// The punch's underside is the plane x3 = 0 (Psi = -x3: a point above it, x3 > 0, penetrates).
struct Plane;
impl ContactSurface for Plane {
    fn psi(&self, x: &Vector3<f64>) -> f64 {
        -x[2]
    }
    fn gradient(&self, _x: &Vector3<f64>) -> Vector3<f64> {
        Vector3::new(0.0, 0.0, -1.0)
    }
}

/// Four points at x3 = 0 below the plane (touching), each with its own dofs.
fn pair(entry_fraction: f64) -> ContactPair {
    let points = (0..4).map(|k| ContactPoint { node: k, x_ref: [k as f64, 0.0, -1e-3], dofs: [3 * k, 3 * k + 1, 3 * k + 2], weight: 1.0 }).collect();
    let mut pair = ContactPair::new("plane", Arc::new(Plane), points, 10.0, ContactKinematics::Exact);
    pair.entry_fraction = entry_fraction;
    pair
}

/// Evaluate with a tangent at the points' upward displacements `w` (x3 = -1e-3 + w);
/// returns the changes and the active flags.
fn evaluate(pair: &mut ContactPair, w: [f64; 4]) -> (usize, Vec<bool>) {
    let mut u = vec![0.0; 12];
    for k in 0..4 {
        u[3 * k + 2] = w[k];
    }
    let mut force = vec![0.0; 12];
    let mut add = |_: usize, _: usize, _: f64| {};
    let changes = pair.evaluate(&u, 0.0, &mut force, Some(&mut add)).unwrap();
    (changes, pair.state.iter().map(|s| s.active).collect())
}

#[test]
fn only_the_deepest_half_of_the_new_penetrations_enters() {
    let mut p = pair(0.5);
    // first evaluation: the last point touches (Psi = 0), the others are clear
    assert_eq!(evaluate(&mut p, [0.0, 0.0, 0.0, 1e-3]), (1, vec![false, false, false, true]));
    // penetrations 1, 0.6, 0.4 (x3 = w - 1e-3): the deepest is 0.999, half of it 0.4995;
    // 0.599 enters, 0.399 is held back but counts as a change
    let w = [1.0, 0.6, 0.4, 1e-3];
    let (changes, active) = evaluate(&mut p, w);
    assert_eq!(active, vec![true, true, false, true]);
    assert_eq!(changes, 3, "two points entered, one is held back");
    // the held-back point gets no force
    assert_eq!(p.state[2].lambda, 0.0);
    assert!(p.state[0].lambda < 0.0 && p.state[1].lambda < 0.0);
    // next time it is the deepest of the inactive points: it enters, and then nothing changes
    let (changes, active) = evaluate(&mut p, w);
    assert_eq!((changes, active), (1, vec![true, true, true, true]));
    assert_eq!(evaluate(&mut p, w).0, 0);
}

#[test]
fn from_an_empty_set_only_the_deepest_penetrations_enter() {
    // the very first evaluation already overlaps: only the deepest trial (-9.99) enters:
    // -5.99 and -3.99 are held back
    let mut p = pair(0.5);
    let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 0.0]);
    assert_eq!(active, vec![true, false, false, false]);
    assert_eq!(changes, 3, "one point entered, two are held back");
    assert_eq!(p.state[1].lambda, 0.0);
    // then the set grows by the damped rule (0.599 and 0.399 against half of 0.599: both)
    assert_eq!(evaluate(&mut p, [1.0, 0.6, 0.4, 0.0]), (2, vec![true, true, true, false]));
    // every point released, then two equally deep penetrations: both enter, the shallower
    // (-2.99 against -4.99) is held back
    let mut p = pair(0.5);
    assert_eq!(evaluate(&mut p, [0.0; 4]), (0, vec![false; 4]));
    let (changes, active) = evaluate(&mut p, [0.5, 0.5, 0.3, 0.0]);
    assert_eq!((changes, active), (3, vec![true, true, false, false]));
    // a residual-only evaluation (line-search trial) still sees every penetration
    let mut p = pair(0.5);
    let mut u = vec![0.0; 12];
    u[2] = 1.0;
    u[5] = 0.6;
    let mut force = vec![0.0; 12];
    assert_eq!(p.evaluate(&u, 0.0, &mut force, None).unwrap(), 0, "the first evaluation records its set");
    assert!(force[2] != 0.0 && force[5] != 0.0);
}

#[test]
fn a_lone_point_swinging_in_and_out_is_frozen_after_lone_max_flips_changes() {
    // nothing penetrates, then point 0 alone: in, out (held for the one evaluation after it
    // entered), out, in (three changes with at most one point active): frozen, its next swing is
    // no change
    let mut p = pair(0.5);
    assert_eq!(evaluate(&mut p, [0.0; 4]).0, 0);
    let (inside, outside) = ([1.0, 0.0, 0.0, 0.0], [0.0; 4]);
    for (k, (w, changes)) in [(inside, 1), (outside, 1), (outside, 1), (inside, 1)].into_iter().enumerate() {
        assert_eq!(evaluate(&mut p, w).0, changes, "evaluation {k}");
    }
    assert_eq!(LONE_MAX_FLIPS, 3);
    assert!(p.frozen[0] && !p.frozen[1]);
    assert_eq!(evaluate(&mut p, outside), (0, vec![false; 4]), "a frozen point follows Psi without counting");
    // the same swings next to two active points: not lone, counted up to max_flips (10)
    let mut p = pair(0.5);
    let (inside, outside) = ([1.0, 0.0, 1.0, 1.0], [0.0, 0.0, 1.0, 1.0]);
    assert_eq!(evaluate(&mut p, outside).1, vec![false, false, true, true]);
    assert_eq!(evaluate(&mut p, outside).0, 0, "points 2 and 3 are settled");
    for k in 0..5 {
        assert_eq!(evaluate(&mut p, inside).0, 1, "entry {k}");
        assert_eq!(evaluate(&mut p, outside), (1, vec![true, false, true, true]), "held after entry {k} (a change: not converged)");
        if k < 4 {
            assert_eq!(evaluate(&mut p, outside).0, 1, "release {k}");
            assert!(!p.frozen[0]);
        }
    }
    assert_eq!(evaluate(&mut p, outside).0, 1);
    assert!(p.frozen[0], "frozen at the tenth change");
}

#[test]
fn the_first_iteration_of_a_load_step_takes_only_the_deepest_tenth() {
    let mut p = pair(0.5);
    evaluate(&mut p, [0.0, 0.0, 0.0, 1e-3]);
    p.start_step(false);
    // trials -9.99, -5.99, -3.99 against 0.9 * -9.99: only the first enters
    let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 1e-3]);
    assert_eq!((changes, active), (3, vec![true, false, false, true]));
    // the next iteration uses entry_fraction (half of -5.99): both enter
    assert_eq!(evaluate(&mut p, [1.0, 0.6, 0.4, 1e-3]), (2, vec![true; 4]));
}

#[test]
fn a_predicted_step_takes_every_penetrating_point_at_once_and_the_next_step_damps_again() {
    // from the coarse mesh's solution: no damping, not even at the first evaluation (which
    // would take the deepest point only and count the others as changes): every
    // penetrating point is in the set it records
    let mut p = pair(0.5);
    p.start_step(true);
    let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 0.0]);
    assert_eq!((changes, active), (0, vec![true, true, true, false]));
    // later evaluations of the step too: a point that starts penetrating enters at once
    let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 1.0]);
    assert_eq!((changes, active), (1, vec![true; 4]));
    // a step from the secant predictor damps as before: of the new penetrations (trials
    // -9.99, -5.99, -3.99 against 0.9 * -9.99) only the deepest enters
    let mut p = pair(0.5);
    p.start_step(true);
    assert_eq!(evaluate(&mut p, [1.0, 0.0, 0.0, 0.0]), (0, vec![true, false, false, false]));
    p.start_step(false);
    let (changes, active) = evaluate(&mut p, [1.0, 1.0, 0.6, 0.4]);
    assert_eq!((changes, active), (3, vec![true, true, false, false]));
}

#[test]
fn right_after_an_augmented_lagrangian_update_no_point_is_released() {
    // points 0 and 1 in contact (lambda -9.99 each), an update (lambda_bar <- lambda), then
    // point 1 lifts off by 2 (trial -9.99 + 10 * 2.001 > 0): the next evaluation with a
    // tangent keeps it, the one after releases it
    let mut p = pair(0.5);
    assert_eq!(evaluate(&mut p, [1.0, 1.0, 0.0, 0.0]).1, vec![true, true, false, false]);
    p.augment();
    let lifted = [1.0, -2.0, 0.0, 0.0];
    let (changes, active) = evaluate(&mut p, lifted);
    assert_eq!((changes, active.clone()), (0, vec![true, true, false, false]), "held right after the update");
    let (changes, active) = evaluate(&mut p, lifted);
    assert_eq!((changes, active), (1, vec![true, false, false, false]), "released at the next evaluation");
    // without an update in between it is released at once (once past the evaluation after it
    // entered, which holds it too)
    let mut q = pair(0.5);
    evaluate(&mut q, [1.0, 1.0, 0.0, 0.0]);
    assert_eq!(evaluate(&mut q, [1.0, 1.0, 0.0, 0.0]).0, 0);
    assert_eq!(evaluate(&mut q, lifted), (1, vec![true, false, false, false]));
    // a point that entered at the last evaluation is held once, then released
    let mut r = pair(0.5);
    evaluate(&mut r, [1.0, 0.0, 0.0, 0.0]);
    assert_eq!(evaluate(&mut r, [1.0, 1.0, 0.0, 0.0]), (1, vec![true, true, false, false]), "point 1 enters");
    assert_eq!(evaluate(&mut r, lifted), (1, vec![true, true, false, false]), "held the evaluation after it entered, counted as a change");
    assert!(r.state[1].lambda > 0.0, "its force is the exact (here tensile) trial multiplier");
    assert_eq!(evaluate(&mut r, lifted), (1, vec![true, false, false, false]), "then released");
}

#[test]
fn with_entry_fraction_zero_every_penetrating_point_enters_at_once() {
    let mut p = pair(0.0);
    evaluate(&mut p, [0.0; 4]);
    let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 0.0]);
    assert_eq!((changes, active), (3, vec![true, true, true, false]));
}

#[test]
fn a_residual_only_evaluation_reports_the_true_changes_and_holds_nothing_back() {
    let mut p = pair(0.5);
    evaluate(&mut p, [0.0; 4]);
    let mut u = vec![0.0; 12];
    u[2] = 1.0;
    u[8] = 0.4;
    let mut force = vec![0.0; 12];
    // a line-search trial: the force of every penetrating point, nothing recorded
    assert_eq!(p.evaluate(&u, 0.0, &mut force, None).unwrap(), 2);
    assert!(force[8] != 0.0, "the shallow penetration acts in a residual-only evaluation");
    assert_eq!(p.last_active, vec![false; 4]);
}

#[test]
fn barely_tensile_points_leave_after_the_most_tensile_one() {
    // all four points in contact (Psi = 0), then three lift off by 1, 0.8 and 0.02 (trials 10, 8
    // and 0.2): those at or above RELEASE_FRACTION (5 %) of the most tensile trial leave at
    // once; the barely tensile one stays active with its exact (tensile) force, counted as a
    // change, and leaves at the next evaluation, when it is the most tensile
    let mut p = pair(0.5);
    assert_eq!(p.release_fraction, RELEASE_FRACTION);
    evaluate(&mut p, [1e-3; 4]);
    assert_eq!(evaluate(&mut p, [1e-3; 4]), (0, vec![true; 4]), "settled in contact");
    let lifted = [-1.0 + 1e-3, -0.8 + 1e-3, -0.02 + 1e-3, 1e-3];
    assert_eq!(evaluate(&mut p, lifted), (3, vec![false, false, true, true]));
    assert!((p.state[2].lambda - 0.2).abs() < 1e-12, "held with its exact trial multiplier");
    assert_eq!(evaluate(&mut p, lifted), (1, vec![false, false, false, true]), "then released");
    assert_eq!(evaluate(&mut p, lifted).0, 0);
    // release_fraction = 0: every tensile point leaves at once
    let mut q = pair(0.5);
    q.release_fraction = 0.0;
    evaluate(&mut q, [1e-3; 4]);
    evaluate(&mut q, [1e-3; 4]);
    assert_eq!(evaluate(&mut q, lifted), (3, vec![false, false, false, true]));
}

#[test]
fn a_tension_that_falls_tenfold_at_each_iteration_is_held_and_one_that_does_not_is_released() {
    // all four points in contact; then the first lifts off (trial 10) and the third is barely
    // tensile (0.2): held by the release fraction. Its tension then falls to 0.01 and 0.0001
    // (the remainder of a convex punch's linearisation converging away): still held, each time
    // a change; back in compression it stays in with no change
    let mut p = pair(0.5);
    assert_eq!(p.hold_converging, true);
    evaluate(&mut p, [1e-3; 4]);
    assert_eq!(evaluate(&mut p, [1e-3; 4]), (0, vec![true; 4]));
    let lift = |w2: f64| [-1.0 + 1e-3, 1e-3, 1e-3 - w2, 1e-3];
    assert_eq!(evaluate(&mut p, lift(0.02)), (2, vec![false, true, true, true]));
    assert_eq!(evaluate(&mut p, lift(0.001)), (1, vec![false, true, true, true]), "0.01 < 0.1 x 0.2: held");
    assert!((p.state[2].lambda - 0.01).abs() < 1e-12, "with its exact trial multiplier");
    assert_eq!(evaluate(&mut p, lift(1e-5)), (1, vec![false, true, true, true]), "1e-4 < 0.1 x 0.01: held");
    assert_eq!(evaluate(&mut p, lift(-1e-5)), (0, vec![false, true, true, true]), "pressed again");
    // a tension that does not fall tenfold (0.2, then 0.15) is a lift-off: released
    let mut q = pair(0.5);
    evaluate(&mut q, [1e-3; 4]);
    evaluate(&mut q, [1e-3; 4]);
    assert_eq!(evaluate(&mut q, lift(0.02)), (2, vec![false, true, true, true]));
    assert_eq!(evaluate(&mut q, lift(0.015)), (1, vec![false, true, false, true]));
    // hold_converging = false: released as soon as it is the most tensile
    let mut r = pair(0.5);
    r.hold_converging = false;
    evaluate(&mut r, [1e-3; 4]);
    evaluate(&mut r, [1e-3; 4]);
    evaluate(&mut r, lift(0.02));
    assert_eq!(evaluate(&mut r, lift(0.001)), (1, vec![false, true, false, true]));
}

#[test]
fn a_set_is_not_emptied_in_one_evaluation() {
    // all four points in contact, then all lift off (trials 10, 8, 6 and 5), none penetrating:
    // the least tensile one stays for one more evaluation (a change), then leaves too
    let mut p = pair(0.5);
    assert!(p.guard_empty);
    evaluate(&mut p, [1e-3; 4]);
    assert_eq!(evaluate(&mut p, [1e-3; 4]), (0, vec![true; 4]), "settled in contact");
    let lifted = [-1.0 + 1e-3, -0.8 + 1e-3, -0.6 + 1e-3, -0.5 + 1e-3];
    assert_eq!(evaluate(&mut p, lifted), (4, vec![false, false, false, true]));
    assert!((p.state[3].lambda - 5.0).abs() < 1e-12, "held with its exact trial multiplier");
    assert_eq!(evaluate(&mut p, lifted), (1, vec![false; 4]), "then released: a real lift-off");
    assert_eq!(evaluate(&mut p, lifted).0, 0);
    // a set that keeps a pressed point is released as the rules say
    let mut q = pair(0.5);
    evaluate(&mut q, [1e-3; 4]);
    evaluate(&mut q, [1e-3; 4]);
    assert_eq!(evaluate(&mut q, [-1.0 + 1e-3, -0.8 + 1e-3, -0.6 + 1e-3, 2e-3]), (3, vec![false, false, false, true]));
    // guard_empty = false: every point leaves at once
    let mut r = pair(0.5);
    r.guard_empty = false;
    evaluate(&mut r, [1e-3; 4]);
    evaluate(&mut r, [1e-3; 4]);
    assert_eq!(evaluate(&mut r, lifted), (4, vec![false; 4]));
}
