//! The paper's section-5 benchmark: Tables 1 and 2 and the reaction check, solved
//! through the generic framework exactly as `stamp paper` does.

use stamp_cli::paper::tables::run_paper;

#[test]
fn tables_1_and_2_and_the_reaction_check() {
    let r = run_paper().expect("the benchmark solves");
    for row in &r.table1 {
        for (name, z) in [("linear", &row.linear), ("nonlinear", &row.nonlinear)] {
            assert_eq!((z.b_int, z.b_ext), (z.paper[0], z.paper[1]), "Table 1 {name}, P = {}: loaded zone", row.p);
            assert!(z.v3_rel_diff.abs() < 0.0015, "Table 1 {name}, P = {}: v3 = {} vs {} ({:+.3}%)", row.p, z.v3, z.paper[2], 100.0 * z.v3_rel_diff);
        }
    }
    for row in &r.table2 {
        assert!(row.v3_rel_diff.abs() < 0.0015, "Table 2, P = {}: v3 = {} vs {}", row.p, row.v3, row.paper[2]);
        // b_ext may lie up to two nodes inside the paper's (docs/verification/paper.md); never outside it
        assert!(row.b_ext <= row.paper[1] && row.paper[1] - row.b_ext <= 5.0 + 1e-9, "Table 2, P = {}: b_ext {} vs {}", row.p, row.b_ext, row.paper[1]);
        assert_eq!(row.b_int, 0.0, "Table 2 has no lift-off at the centre");
        assert!((row.reaction - row.load_per_end).abs() <= 1e-8 * row.load_per_end, "P = {}: reaction {} vs {}", row.p, row.reaction, row.load_per_end);
    }
    let check = &r.reaction_check;
    assert_eq!(check.paper, 20.0);
    assert!(check.rel_diff.abs() <= 1e-8, "reaction {} at P = 20 (relative {:e})", check.ours, check.rel_diff);
}
