use stamp_cli::paper::run_paper;
fn main() {
    match run_paper() {
        Ok(r) => {
            for row in &r.table1 {
                println!("T1 P={} lin [{}, {}] v3={:.4} ({:+.3}%)  nl [{}, {}] v3={:.4} ({:+.3}%) act={:?}", row.p, row.linear.b_int, row.linear.b_ext, row.linear.v3, 100.0*row.linear.v3_rel_diff, row.nonlinear.b_int, row.nonlinear.b_ext, row.nonlinear.v3, 100.0*row.nonlinear.v3_rel_diff, row.nonlinear.active_set);
            }
            for row in &r.table2 {
                println!("T2 P={} [{}, {}] v3={:.4} ({:+.3}%) reaction {:.10} it {}", row.p, row.b_int, row.b_ext, row.v3, 100.0*row.v3_rel_diff, row.reaction, row.newton_iterations);
            }
            println!("{:.3} s", r.seconds);
        }
        Err(e) => { eprintln!("error: {e}"); std::process::exit(1) }
    }
}
