//! The inclined plane (NAFEMS CGS-4 as FrontISTR runs it): verification/inclined_plane.toml, a
//! plate on a rigid plane inclined at tan a = 0.1 (a tilted `plane` punch), its weight G a dead
//! surface load along -x3 and the push a prescribed motion of its left edge along +x1 with v3 free
//! (so the edge's reaction is a horizontal force F); the weight and the tilt of the edge are put on
//! first along `path`s, then the edge is pushed. Once every contact point slides up the slope,
//! force balance alone gives F / G = (tan a + mu) / (1 - mu tan a).

mod common;
use common::*;

#[test]
fn the_push_over_the_weight_at_the_sliding_limit_is_exact() {
    let shipped = std::fs::read_to_string(repo().join("verification/inclined_plane.toml")).unwrap();
    let tan_a = 0.1f64;
    for mu in [0.0, 0.1, 0.2, 0.3] {
        let exact = (tan_a + mu) / (1.0 - mu * tan_a);
        assert!(shipped.contains("friction = 0.2\n"));
        let out = run_text(&format!("inclined-{mu}"), &shipped.replacen("friction = 0.2\n", &format!("friction = {mu:?}\n"), 1));
        let (head, rows) = history(&out);
        let last = rows.len() - 1;
        let t = column(&head, &rows, "load_factor");
        assert_eq!(t[last], 1.0);
        let f = column(&head, &rows, "left_reaction_x1")[last];
        // the edge holds x1 only: no vertical force but the weight's and the slope's
        assert_eq!(column(&head, &rows, "left_reaction_x3")[last], 0.0);
        let g = 100.0;
        // the slope's force on the plate balances F and G
        let (p1, p2, p3) = (column(&head, &rows, "slope_force_x1")[last], column(&head, &rows, "slope_force_x2")[last], column(&head, &rows, "slope_force_x3")[last]);
        println!("mu = {mu}: F/G = {:.12} against {exact:.12} (error {:.2e}); force on the slope ({p1:.9}, {p2:.2e}, {p3:.9})", f / g, f / g / exact - 1.0);
        assert!((f / g / exact - 1.0).abs() < 1e-6, "mu = {mu}: F/G = {}, expected {exact}", f / g);
        assert!((p1 - f).abs() < 1e-6 * g && (p3 + g).abs() < 1e-6 * g && p2.abs() < 1e-6 * g, "force on the slope ({p1}, {p2}, {p3})");
        let s = summary(&out);
        let slope = &s["steps"].as_array().unwrap()[last]["punches"]["slope"];
        if mu > 0.0 {
            // the limit: every point in contact slides, none sticks
            assert_eq!(slope["sticking_nodes"].as_u64().unwrap(), 0, "{slope}");
            assert_eq!(slope["slipping_nodes"].as_u64().unwrap(), 81, "{slope}");
            let d = column(&head, &rows, "slope_dissipation");
            assert!(d.windows(2).all(|w| w[1] >= w[0]) && d[last] > 0.0);
        }
        assert_eq!(slope["active_nodes"].as_u64().unwrap(), 81, "the plate lies on the slope: {slope}");
    }
}
