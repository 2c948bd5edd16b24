//! The validated values of a problem file: numbers and counts checked while deserialising (the
//! error is raised inside the deserializer, so toml reports its line), 3-vectors, and how a
//! message shows a number.

use super::limits;
use serde::Deserialize;
use serde::de::{Deserializer, Error as _};

/// A number as a message shows it: plain decimals for ordinary sizes, `{:e}` for tiny or huge ones
/// (so that 1e300 is not printed with 300 digits and 1e-200 does not show as 0).
pub fn num(v: f64) -> String {
    if v == 0.0 || (v.is_finite() && v.abs() >= 1e-4 && v.abs() < 1e15) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A vector as a message shows it (see [`num`]).
pub fn vec_text(v: &[f64]) -> String {
    format!("[{}]", v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", "))
}

macro_rules! checked_number {
    ($name:ident, $what:expr, $ok:expr) => {
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct $name(pub f64);
        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
                let v = f64::deserialize(d)?;
                let ok: fn(f64) -> bool = $ok;
                if v.is_finite() && ok(v) {
                    Ok($name(v))
                } else {
                    Err(D::Error::custom(format!("expected {}, got {}", $what, num(v))))
                }
            }
        }
    };
}

checked_number!(Positive, "a positive number from 1e-100 to 1e100", |v| (limits::MIN_MAGNITUDE..=limits::MAX_MAGNITUDE).contains(&v));
checked_number!(NonNegative, "a number from 0 to 1e100", |v| (0.0..=limits::MAX_MAGNITUDE).contains(&v));
checked_number!(Finite, "a finite number of magnitude at most 1e100", |v| v.abs() <= limits::MAX_MAGNITUDE);
checked_number!(FrictionCoefficient, "a friction coefficient from 0 to 10", |v| (0.0..=10.0).contains(&v));
checked_number!(Poisson, "Poisson's ratio in (-1, 0.5)", |v| v > -1.0 && v < 0.5);
checked_number!(Fraction, "a number in [0, 1)", |v| (0.0..1.0).contains(&v));
checked_number!(Increment, "a load increment in [1e-12, 1e6]", |v| (limits::MIN_INCREMENT..=limits::MAX_LOAD_FACTOR).contains(&v));
checked_number!(InitialIncrement, "a fraction of the first target in [1e-12, 1]", |v| (limits::MIN_INCREMENT..=1.0).contains(&v));
checked_number!(RelTol, "a relative tolerance in [1e-15, 0.1] (below 1e-15 floating point cannot reach it)", |v| (limits::MIN_REL_TOL..=0.1).contains(&v));

/// Any number as written (a whole number of any size, or a float), for range messages that show
/// what was given instead of serde's "expected i64".
pub(super) struct AnyNumber(pub(super) std::result::Result<i128, f64>);

impl<'de> Deserialize<'de> for AnyNumber {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = AnyNumber;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a whole number")
            }
            fn visit_i64<E>(self, v: i64) -> std::result::Result<AnyNumber, E> {
                Ok(AnyNumber(Ok(v.into())))
            }
            fn visit_u64<E>(self, v: u64) -> std::result::Result<AnyNumber, E> {
                Ok(AnyNumber(Ok(v.into())))
            }
            fn visit_f64<E>(self, v: f64) -> std::result::Result<AnyNumber, E> {
                Ok(AnyNumber(Err(v)))
            }
        }
        d.deserialize_any(V)
    }
}

/// A whole number in a range, checked while deserialising (so toml gives the line).
macro_rules! checked_count {
    ($name:ident, $min:expr, $max:expr) => {
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub struct $name(pub usize);
        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
                let (min, max): (u64, u64) = ($min, $max);
                match AnyNumber::deserialize(d)?.0 {
                    Ok(v) if v >= min as i128 && v <= max as i128 => Ok($name(v as usize)),
                    Ok(v) => Err(D::Error::custom(format!("expected a whole number from {min} to {max}, got {v}"))),
                    Err(v) => Err(D::Error::custom(format!("expected a whole number from {min} to {max}, got the decimal number {}", num(v)))),
                }
            }
        }
    };
}

checked_count!(StepCount, 1, limits::MAX_STEPS);
checked_count!(IterationCount, 1, limits::MAX_ITERATIONS);
checked_count!(CycleCount, 0, limits::MAX_ITERATIONS);
checked_count!(LineSearchCount, 0, limits::MAX_LINE_SEARCH_STEPS);
checked_count!(CutbackCount, 0, limits::MAX_CUTBACKS);
checked_count!(MaxStepCount, 1, limits::MAX_STEP_BUDGET);

/// A 3-vector of finite numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vec3(pub [f64; 3]);
impl<'de> Deserialize<'de> for Vec3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = <[f64; 3]>::deserialize(d)?;
        if v.iter().all(|x| x.is_finite() && x.abs() <= limits::MAX_MAGNITUDE) {
            Ok(Vec3(v))
        } else {
            Err(D::Error::custom(format!("expected three finite numbers of magnitude at most 1e100, got {}", vec_text(&v))))
        }
    }
}

/// A factor along the load factor: rows `[[t, factor], ...]`, piecewise linear in t like a
/// punch's `motion` rows (checked by [`stamp::factor_path::FactorPath::new`]): a `[[load]]`'s or
/// a `[[boundary]]`'s `path`.
#[derive(Debug, Clone, PartialEq)]
pub struct PathSpec(pub stamp::factor_path::FactorPath);
impl<'de> Deserialize<'de> for PathSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        const FORM: &str = "expected rows [[t, factor], ...] (the factor piecewise linear in the load factor t)";
        let rows = Vec::<Vec<f64>>::deserialize(d).map_err(|_| D::Error::custom(FORM))?;
        if rows.len() > limits::MAX_PATH_ROWS {
            return Err(D::Error::custom(format!("a path has at most {} rows, got {}", limits::MAX_PATH_ROWS, rows.len())));
        }
        let mut out = Vec::with_capacity(rows.len());
        for (k, r) in rows.iter().enumerate() {
            if r.len() != 2 {
                return Err(D::Error::custom(format!("path row {k}: expected [t, factor], got {} numbers", r.len())));
            }
            if !r.iter().all(|x| x.is_finite() && x.abs() <= limits::MAX_MAGNITUDE) {
                return Err(D::Error::custom(format!("path row {k}: expected finite numbers of magnitude at most 1e100, got {}", vec_text(r))));
            }
            if r[0] > limits::MAX_LOAD_FACTOR {
                return Err(D::Error::custom(format!("path row {k}: the load factor t = {} is above the largest target allowed, 1e6", num(r[0]))));
            }
            out.push((r[0], r[1]));
        }
        stamp::factor_path::FactorPath::new(&out).map(PathSpec).map_err(|e| D::Error::custom(if e.starts_with("row") { format!("path {e}") } else { e }))
    }
}
