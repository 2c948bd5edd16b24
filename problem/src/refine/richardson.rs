//! Richardson extrapolation of a result computed on a mesh and on its uniform refinements (each
//! halves the element size h): if the error behaves like C h^p, the converged value is
//! F_inf = F_L + (F_L - F_{L-1}) / (2^p - 1), F_L the finest result. With two meshes p is assumed
//! ([`ASSUMED_ORDER`]); with three or more it is observed from the last three,
//! p = log2((F_{L-1} - F_{L-2}) / (F_L - F_{L-1})), when that is a sensible number (the differences
//! have the same sign and p lies in [[`MIN_OBSERVED`], [`MAX_OBSERVED`]]), else the assumed order
//! is used. The estimated error of each mesh's result is F_k - F_inf.

/// The order assumed with one refinement: the plate element's under smooth loads (the hard simply
/// supported plate's deflection under a pressure: observed 2.04). Contact results on coarse meshes
/// converge more slowly: the simply supported quarter plate under a sphere, force at travel 0.9,
/// observed order 1.08 on 10 x 10, 20 x 20, 40 x 40 and 1.44 on 20 x 20 .. 80 x 80 (other
/// examples 0.9 .. 3.3), so with one refinement the estimate can understate their error by up to
/// about 1.6 times; `--refine 2` observes the order.
pub const ASSUMED_ORDER: f64 = 2.0;
/// Observed orders outside [MIN_OBSERVED, MAX_OBSERVED] are not trusted (the meshes are not in the
/// asymptotic range, or the differences are round-off).
pub const MIN_OBSERVED: f64 = 0.5;
pub const MAX_OBSERVED: f64 = 4.0;

/// The extrapolation of one quantity at one load step.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// The results on the meshes, coarsest first.
    pub values: Vec<f64>,
    /// The estimated converged value F_inf.
    pub value: f64,
    /// The order p used.
    pub order: f64,
    /// The order observed from the last three meshes (None with two meshes, or when the
    /// differences change sign or vanish).
    pub observed_order: Option<f64>,
    /// F_k - F_inf for every mesh.
    pub errors: Vec<f64>,
}

impl Estimate {
    /// The estimated error of mesh k in percent of |F_inf| (0 when both are 0; None when only
    /// F_inf is 0).
    pub fn percent(&self, k: usize) -> Option<f64> {
        let e = self.errors[k];
        if self.value == 0.0 {
            return (e == 0.0).then_some(0.0);
        }
        Some(100.0 * e / self.value.abs())
    }
}

/// Extrapolate `values` (at least two, coarsest first, each mesh refined once more).
pub fn extrapolate(values: &[f64]) -> Estimate {
    assert!(values.len() >= 2, "Richardson extrapolation needs two meshes at least");
    let n = values.len();
    let observed_order = (n >= 3).then(|| observed(values[n - 3], values[n - 2], values[n - 1])).flatten();
    let order = observed_order.filter(|p| (MIN_OBSERVED..=MAX_OBSERVED).contains(p)).unwrap_or(ASSUMED_ORDER);
    let (fine, coarse) = (values[n - 1], values[n - 2]);
    let value = fine + (fine - coarse) / (2f64.powf(order) - 1.0);
    Estimate { values: values.to_vec(), value, order, observed_order, errors: values.iter().map(|v| v - value).collect() }
}

/// log2 of the ratio of successive differences, if they have the same sign.
fn observed(f0: f64, f1: f64, f2: f64) -> Option<f64> {
    let (d1, d2) = (f1 - f0, f2 - f1);
    let ratio = d1 / d2;
    (ratio > 0.0 && ratio.is_finite()).then(|| ratio.log2())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_meshes_assume_second_order() {
        // F(h) = 10 + 3 h^2 on h = 1, 1/2: exact with p = 2
        let e = extrapolate(&[13.0, 10.75]);
        assert_eq!(e.order, 2.0);
        assert_eq!(e.observed_order, None);
        assert!((e.value - 10.0).abs() < 1e-12, "{e:?}");
        assert!((e.errors[0] - 3.0).abs() < 1e-12 && (e.errors[1] - 0.75).abs() < 1e-12);
        assert!((e.percent(0).unwrap() - 30.0).abs() < 1e-9);
    }

    #[test]
    fn three_meshes_observe_the_order() {
        // F(h) = -5 + 2 h^1.5 on h = 1, 1/2, 1/4
        let f = |h: f64| -5.0 + 2.0 * h.powf(1.5);
        let e = extrapolate(&[f(1.0), f(0.5), f(0.25)]);
        assert!((e.observed_order.unwrap() - 1.5).abs() < 1e-12, "{e:?}");
        assert_eq!(e.order, e.observed_order.unwrap());
        assert!((e.value + 5.0).abs() < 1e-12, "{e:?}");
        // the finest mesh (h = 1/4) is 2 / 8 = 0.25 off: 5 % of |F_inf| = 5
        assert!((e.percent(2).unwrap() - 100.0 * 2.0 * 0.25f64.powf(1.5) / 5.0).abs() < 1e-9);
    }

    #[test]
    fn an_erratic_sequence_falls_back_to_the_assumed_order() {
        let e = extrapolate(&[1.0, 1.2, 1.1]);
        assert_eq!(e.observed_order, None, "the differences change sign");
        assert_eq!(e.order, ASSUMED_ORDER);
        let e = extrapolate(&[1.0, 1.5, 1.9]);
        assert!(e.observed_order.unwrap() < MIN_OBSERVED);
        assert_eq!(e.order, ASSUMED_ORDER);
        // identical results (a prescribed quantity): no order, no error
        let e = extrapolate(&[2.0, 2.0, 2.0]);
        assert_eq!((e.value, e.observed_order, e.percent(0)), (2.0, None, Some(0.0)));
        let e = extrapolate(&[0.0, 0.0]);
        assert_eq!(e.percent(1), Some(0.0));
        let e = extrapolate(&[1.0, 0.0]);
        assert!(e.value != 0.0);
    }
}
