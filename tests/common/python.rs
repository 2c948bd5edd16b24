//! The Python checks of the integration tests (VTK's reader, Python's XML parser): an independent
//! reader of our files. Missing Python or a missing module fails the test with how to install it;
//! a test that passes without checking would say the files were read back when they were not. To
//! run the suite without them knowingly, set STAMP_SKIP_PYTHON_CHECKS=1: the checks then say
//! SKIPPED on stderr and pass.

use std::process::Command;

/// The environment variable that lets the Python checks be skipped.
pub const SKIP_VAR: &str = "STAMP_SKIP_PYTHON_CHECKS";

/// True when `python3 -c "import <modules>"` works; false (after a SKIPPED line on stderr) when it
/// does not and [`SKIP_VAR`] is 1; else the test fails, naming `check` (what would be checked) and
/// the command that installs the modules.
pub fn python_with(modules: &[&str], check: &str) -> bool {
    let import = if modules.is_empty() { "pass".to_string() } else { format!("import {}", modules.join(", ")) };
    let run = Command::new("python3").args(["-c", &import]).output();
    let why = match &run {
        Ok(o) if o.status.success() => return true,
        Ok(o) => format!("`python3 -c \"{import}\"` fails: {}", String::from_utf8_lossy(&o.stderr).trim()),
        Err(e) => format!("python3 cannot be started: {e}"),
    };
    let install = if modules.is_empty() { "install python3".to_string() } else { format!("python3 -m pip install {}", modules.join(" ")) };
    if std::env::var(SKIP_VAR).is_ok_and(|v| v == "1") {
        eprintln!("SKIPPED ({SKIP_VAR}=1): {check}: {why}");
        return false;
    }
    panic!("{check} is not possible: {why}. Run `{install}` (.ci/run does), or set {SKIP_VAR}=1 to skip this check knowingly");
}
