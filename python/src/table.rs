//! A Python dict as the TOML table of a problem file: the same keys and values, so that the
//! problem-file library reads it with the same schema, checks and messages.

use crate::StampError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// The dict as a TOML table.
pub fn to_table(dict: &Bound<'_, PyDict>) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (k, v) in dict.iter() {
        let key = key_of(&k, "")?;
        table.insert(key.clone(), value(&v, &key)?);
    }
    Ok(table)
}

fn key_of(k: &Bound<'_, PyAny>, parent: &str) -> PyResult<String> {
    k.cast::<PyString>().map(|s| s.to_string()).map_err(|_| StampError::new_err(format!("{}: keys are strings, got {}", if parent.is_empty() { "the problem" } else { parent }, k.repr().map(|r| r.to_string()).unwrap_or_default())))
}

/// A Python value as a TOML value; `key` names it in errors ("punch[0].motion").
fn value(v: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
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
        let mut table = toml::Table::new();
        for (k, x) in d.iter() {
            let name = key_of(&k, key)?;
            let sub = format!("{key}.{name}");
            table.insert(name, value(&x, &sub)?);
        }
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
        let values = items.iter().enumerate().map(|(i, x)| value(x, &format!("{key}[{i}]"))).collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(values));
    }
    if v.is_none() {
        return Err(StampError::new_err(format!("{key}: None is no value of a problem (leave the key out for its default)")));
    }
    // numpy arrays and scalars: as Python lists and numbers
    if v.hasattr("tolist")? && v.hasattr("dtype")? {
        return value(&v.call_method0("tolist")?, key);
    }
    Err(StampError::new_err(format!("{key}: expected a number, string, bool, list or dict, got {}", v.get_type().name()?)))
}
