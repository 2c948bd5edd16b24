//! Pressures that vary over the plate: `pressure = "sin(pi*x1/10)*sin(pi*x2/10)"`, an expression in
//! x1, x2 with the syntax of a punch's `psi` (stamp_contact's parser), evaluated at the reference
//! positions of the Gauss points and turned into consistent nodal forces int N_a q dA.

use crate::schema::limits::MAX_MAGNITUDE;
use crate::schema::{PressureSpec, Problem};
use stamp::Result;
use stamp::mesh::{bilinear, bilinear_jacobian, QuadMesh};

/// The Gauss points of the 2 x 2 rule.
const G: f64 = 0.577_350_269_189_625_8;

/// The pressure of `load[i]` as a function of (x1, x2); a number is a constant.
pub fn pressure_function(spec: &PressureSpec, size: f64) -> Box<dyn Fn(f64, f64) -> f64 + Send + Sync> {
    match spec {
        PressureSpec::Uniform(q) => {
            let q = *q;
            Box::new(move |_, _| q)
        }
        PressureSpec::Expression(text) => {
            let e = stamp_contact::Expression::new(text, size).expect("checked when the problem was read");
            Box::new(move |x1, x2| e.value(&nalgebra::Vector3::new(x1, x2, 0.0)))
        }
    }
}

/// int N_a q dA over `cells` for every node (2 x 2 Gauss points per cell), or the first point where
/// q is not a finite number, for the error of `key`.
pub fn nodal_forces(p: &Problem, span: std::ops::Range<usize>, key: &str, mesh: &QuadMesh, cells: &[usize], q: &dyn Fn(f64, f64) -> f64) -> Result<Vec<f64>> {
    let mut f = vec![0.0; mesh.num_nodes()];
    for &c in cells {
        let x = mesh.cell_coords(c);
        for (s, t) in [(-G, -G), (G, -G), (G, G), (-G, G)] {
            let (n, dn) = bilinear(s, t);
            let det = bilinear_jacobian(&x, &dn).abs();
            let at = |i: usize| (0..4).map(|a| n[a] * x[a][i]).sum::<f64>();
            let v = q(at(0), at(1));
            if !v.is_finite() {
                return Err(p.error_at(span, key, format!("the pressure is {v} at (x1, x2) = ({}, {}), a point of the loaded group", at(0), at(1))));
            }
            // the range of a pressure written as a number ("1.7e308" summed to -inf nodal forces,
            // "1e300" to NaN in the solve)
            if v.abs() > MAX_MAGNITUDE {
                return Err(p.error_at(span, key, format!("the pressure is {v:e} at (x1, x2) = ({}, {}), a point of the loaded group: beyond {MAX_MAGNITUDE:e}, the largest magnitude a number may have", at(0), at(1))));
            }
            for a in 0..4 {
                f[mesh.cells[c][a]] += n[a] * v * det;
            }
        }
    }
    Ok(f)
}
