//! A Python dict as the TOML table of a problem file: the same keys and values, so that the
//! problem-file library reads it with the same schema, checks and messages.
//!
//! The walk is bounded: a value nested deeper than [`MAX_DEPTH`] containers, a list or dict that
//! contains itself (the ids of the containers on the current path are kept) and an object whose
//! `tolist()` gives back an object with `tolist()` again are refused with a StampError naming the
//! key, instead of recursing until the stack overflows.

use crate::StampError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// The deepest nesting of lists, tuples and dicts below the problem's dict (a problem file needs
/// four or five levels).
pub const MAX_DEPTH: usize = 64;

/// The dict as a TOML table.
pub fn to_table(dict: &Bound<'_, PyDict>) -> PyResult<toml::Table> {
    let mut walk = Walk { path: vec![dict.as_ptr() as usize] };
    let mut table = toml::Table::new();
    for (k, v) in dict.iter() {
        let key = key_of(&k, "")?;
        table.insert(key.clone(), walk.value(&v, &key, false)?);
    }
    Ok(table)
}

fn key_of(k: &Bound<'_, PyAny>, parent: &str) -> PyResult<String> {
    k.cast::<PyString>().map(|s| s.to_string()).map_err(|_| StampError::new_err(format!("{}: keys are strings, got {}", if parent.is_empty() { "the problem" } else { parent }, k.repr().map(|r| r.to_string()).unwrap_or_default())))
}

/// The containers (their ids) from the problem's dict down to the value being converted.
struct Walk {
    path: Vec<usize>,
}

impl Walk {
    /// Enter the container `v` (named `key`): refused if it is one of those it lies in, or too deep.
    fn enter(&mut self, v: &Bound<'_, PyAny>, key: &str) -> PyResult<()> {
        let id = v.as_ptr() as usize;
        if self.path.contains(&id) {
            let kind = v.get_type().name().map(|n| n.to_string()).unwrap_or_default();
            return Err(StampError::new_err(format!("{key}: the {kind} contains itself (a value of a problem cannot hold the list or dict it lies in)")));
        }
        // the problem's dict is path[0]: its values are at depth 1
        if self.path.len() > MAX_DEPTH {
            return Err(StampError::new_err(format!("{key}: nested more than {MAX_DEPTH} levels deep (a problem's values are numbers, strings, bools, lists and dicts a few levels deep)")));
        }
        self.path.push(id);
        Ok(())
    }

    /// A Python value as a TOML value; `key` names it in errors ("punch[0].motion");
    /// `listed`: `v` is what a `tolist()` returned.
    fn value(&mut self, v: &Bound<'_, PyAny>, key: &str, listed: bool) -> PyResult<toml::Value> {
        // bool first: it is an int in Python
        if let Ok(b) = v.cast::<PyBool>() {
            return Ok(toml::Value::Boolean(b.is_true()));
        }
        if v.is_instance_of::<PyInt>() {
            return match v.extract::<i64>() {
                Ok(i) => Ok(toml::Value::Integer(i)),
                Err(_) => Err(StampError::new_err(format!("{key}: the whole number {} is out of range", v.repr()?))),
            };
        }
        if let Ok(f) = v.cast::<PyFloat>() {
            return Ok(toml::Value::Float(f.value()));
        }
        if let Ok(s) = v.cast::<PyString>() {
            return Ok(toml::Value::String(s.to_string()));
        }
        if let Ok(d) = v.cast::<PyDict>() {
            self.enter(v, key)?;
            let mut table = toml::Table::new();
            for (k, x) in d.iter() {
                let name = key_of(&k, key)?;
                let sub = format!("{key}.{name}");
                table.insert(name, self.value(&x, &sub, false)?);
            }
            self.path.pop();
            return Ok(toml::Value::Table(table));
        }
        let items: Option<Vec<Bound<'_, PyAny>>> = if let Ok(l) = v.cast::<PyList>() {
            Some(l.iter().collect())
        } else if let Ok(t) = v.cast::<PyTuple>() {
            Some(t.iter().collect())
        } else {
            None
        };
        if let Some(items) = items {
            self.enter(v, key)?;
            let values = items.iter().enumerate().map(|(i, x)| self.value(x, &format!("{key}[{i}]"), false)).collect::<PyResult<Vec<_>>>()?;
            self.path.pop();
            return Ok(toml::Value::Array(values));
        }
        if v.is_none() {
            return Err(StampError::new_err(format!("{key}: None is no value of a problem (leave the key out for its default)")));
        }
        // numpy arrays and scalars: as Python lists and numbers (once: what tolist() gives must be
        // plain Python values, not the object again or another array)
        if v.hasattr("tolist")? && v.hasattr("dtype")? {
            let kind = v.get_type().name()?.to_string();
            if listed {
                return Err(StampError::new_err(format!("{key}: tolist() gave a {kind}, not a list or a number")));
            }
            let list = v.call_method0("tolist")?;
            if list.as_ptr() == v.as_ptr() {
                return Err(StampError::new_err(format!("{key}: {kind}.tolist() gave the {kind} itself, not a list or a number")));
            }
            return self.value(&list, key, true);
        }
        Err(StampError::new_err(format!("{key}: expected a number, string, bool, list or dict, got {}", v.get_type().name()?)))
    }
}
