//! `stamp run meshes/paper-r100.toml` through the library entry point: the paper's Table 2 (last row)
//! through the generic problem-file path, and the files it writes.

mod common;
#[path = "../../tests/common/python.rs"]
mod python;
use common::*;
use serde_json::Value;
use std::process::Command;

fn vec3(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("a 3-vector");
    [0, 1, 2].map(|i| a[i].as_f64().unwrap())
}

#[test]
fn paper_r100_reproduces_table2_last_row() {
    let out = temp_dir("paper-r100");
    let outcome = stamp_cli::run::run(&repo().join("meshes/paper-r100.toml"), Some(&out), true).expect("the paper's strip converges");
    assert_eq!(outcome.converged_steps, 5);
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "converged");
    assert_eq!(summary["nodes"], 82);
    assert_eq!(summary["cells"], 40);
    let steps = summary["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 5, "every_step = false: the five targets");
    let last = steps.last().unwrap();
    assert_eq!(last["load_factor"].as_f64().unwrap(), 1.0);
    assert_eq!(last["converged"], true);

    // Table 2, P = 20 per end: v3(l) = 45.50 (paper), 45.4786 (stamp paper); 0.15 % acceptance
    let u = vec3(&last["points"]["end_point"]["displacement"]);
    assert!(((u[2] - 45.50) / 45.50).abs() < 1.5e-3, "v3 at the end = {}", u[2]);
    assert!((u[2] - 45.4786).abs() < 1e-3, "v3 at the end = {} (stamp paper: 45.4786)", u[2]);
    assert_eq!(u[0], 0.0, "plane strain");
    // every target's v3 within 0.15 % of Table 2
    for (e, paper) in steps.iter().zip([26.39, 39.62, 43.85, 45.11, 45.50]) {
        let v3 = vec3(&e["points"]["end_point"]["displacement"])[2];
        assert!(((v3 - paper) / paper).abs() < 1.5e-3, "t = {}: v3 = {v3}, paper {paper}", e["load_factor"]);
    }

    // the contact reaction on the plate balances the end load of 20 (per unit length; width 1)
    let r = vec3(&last["reaction"]);
    assert!((r[2] + 20.0).abs() < 20.0 * 1e-8, "vertical reaction {} (should be -20: the punch pushes the plate down)", r[2]);
    assert_eq!(r[0], 0.0);
    let pr = vec3(&last["punches"]["cylinder"]["reaction"]);
    assert_eq!(pr, r);

    // loaded zone on the half plate: [0, 90] in x2 (one node inside the paper's 92.5: docs/verification/paper.md)
    let zone = &last["loaded_zone"];
    let (lo, hi) = (vec3(&zone["min"]), vec3(&zone["max"]));
    assert!(lo[1].abs() < 1e-9 && (hi[1] - 90.0).abs() < 1e-9, "loaded zone {lo:?} .. {hi:?}");
    assert_eq!((lo[0], hi[0]), (0.0, 1.0));
    assert_eq!((lo[2], hi[2]), (1.0, 1.0), "the top face x3 = delta+ = 1");
    assert!(last["max_penetration"].as_f64().unwrap() < 1e-3);
    assert!(last["active_nodes"].as_u64().unwrap() >= 2 * 36);

    // files: pvd listing every vtu with the load factor as time, CSV per step, plots
    let pvd = std::fs::read_to_string(out.join("paper-r100.pvd")).unwrap();
    for e in steps {
        let vtu = e["vtu"].as_str().unwrap();
        assert!(out.join(vtu).is_file(), "{vtu} missing");
        assert!(pvd.contains(&format!("timestep=\"{}\"", e["load_factor"].as_f64().unwrap())) && pvd.contains(vtu), "{pvd}");
        let csv_name = e["csv"][0].as_str().unwrap();
        let csv = std::fs::read_to_string(out.join(csv_name)).unwrap();
        let mut lines = csv.lines();
        assert_eq!(lines.next().unwrap(), "node,x1,x2,x1_deformed,x2_deformed,x3_deformed,q_n,lambda,active");
        assert_eq!(lines.count(), 82);
    }
    // the last CSV: q_n >= 0, and q_n = 0 off the loaded zone (x2 > 92.5)
    let csv = std::fs::read_to_string(out.join(last["csv"][0].as_str().unwrap())).unwrap();
    for line in csv.lines().skip(1) {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        assert!(f[6] >= 0.0 && (f[6] + f[7] * 0.0).is_finite());
        if f[2] > 92.6 {
            assert_eq!(f[6], 0.0, "{line}");
        }
    }
    for f in ["probe_cylinder.png", "probe_cylinder.svg", "force_travel_cylinder.png"] {
        let bytes = std::fs::read(out.join(f)).unwrap();
        assert!(bytes.len() > 1000, "{f} is too small");
    }
    assert_eq!(&std::fs::read(out.join("probe_cylinder.png")).unwrap()[..4], b"\x89PNG");
    // no temporary files left behind (the run's manifest of its files and its lock are not ones)
    for entry in std::fs::read_dir(&out).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.starts_with('.') || name == stamp_cli::run::out_dir::MANIFEST || name == stamp_cli::run::folder_lock::LOCK_FILE, "temporary file {name} left");
    }

    // an independent reader: VTK
    if !python::python_with(&["vtk"], "reading the strip's .vtu back with VTK") {
        return;
    }
    let vtu = out.join(last["vtu"].as_str().unwrap());
    let check = Command::new("python3").arg(repo().join("tests/check_vtu.py")).arg(&vtu).output().unwrap();
    assert!(check.status.success(), "check_vtu.py: {}", String::from_utf8_lossy(&check.stderr));
    let got: Value = serde_json::from_slice(&check.stdout).unwrap();
    assert_eq!(got["points"], 82);
    assert_eq!(got["cells"], 40);
    assert_eq!(got["cell_types"], serde_json::json!([9]));
    let point_arrays = ["displacement", "displacement_bottom", "displacement_top", "lambda", "contact_pressure", "contact_pressure_recovered", "gap", "active", "loaded"];
    for (name, comps) in point_arrays.iter().zip([3, 3, 3, 1, 1, 1, 1, 1, 1]) {
        assert_eq!(got["point_arrays"][name]["components"], comps, "{name}");
        assert_eq!(got["point_arrays"][name]["tuples"], 82, "{name}");
    }
    for name in ["N11", "N22", "N12", "M11", "M22", "M12", "Q1", "Q2", "T33"] {
        assert_eq!(got["cell_arrays"][name]["tuples"], 40, "{name}");
    }
    // the active count in the file equals the summary's
    assert_eq!(got["point_arrays"]["active"]["sum"].as_f64().unwrap(), last["active_nodes"].as_f64().unwrap());
    // values at the end node (0, 100) read back with VTK equal the summary's
    let script = r#"
import sys, json, vtk
r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(sys.argv[1]); r.Update(); g = r.GetOutput()
k = min(range(g.GetNumberOfPoints()), key=lambda i: (g.GetPoint(i)[0] - 0.0)**2 + (g.GetPoint(i)[1] - 100.0)**2)
pd = g.GetPointData(); cd = g.GetCellData()
q = pd.GetArray("contact_pressure")
print(json.dumps({"point": g.GetPoint(k), "displacement": pd.GetArray("displacement").GetTuple3(k),
  "q_min": min(q.GetValue(i) for i in range(q.GetNumberOfTuples())),
  "M11_max": max(abs(cd.GetArray("M11").GetValue(i)) for i in range(g.GetNumberOfCells())),
  "M22_max": max(abs(cd.GetArray("M22").GetValue(i)) for i in range(g.GetNumberOfCells()))}))
"#;
    let o = Command::new("python3").args(["-c", script]).arg(&vtu).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(vec3(&v["point"]), [0.0, 100.0, 0.0]);
    let d = vec3(&v["displacement"]);
    for i in 0..3 {
        assert!((d[i] - u[i]).abs() <= 1e-12 * u[2].abs(), "VTK displacement {d:?} vs summary {u:?}");
    }
    assert!(v["q_min"].as_f64().unwrap() >= 0.0);
    // the strip bends about x1: M22 carries the bending, far more than M11 (= nu-effects only)
    let (m11, m22) = (v["M11_max"].as_f64().unwrap(), v["M22_max"].as_f64().unwrap());
    assert!(m22 > 1.0 && m11 < m22, "M11 {m11}, M22 {m22}");
}
