//! Places in the problem file's text: "line L, column C" of an offset, toml's errors as messages
//! with the key and the line under them.

use stamp::error::QUOTE_LIMIT;
use stamp::quote;

/// "line L, column C" (1-based; the column counts characters) of a byte offset of `source`.
pub fn line_col_of(source: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(source.len());
    while !source.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &source[..offset];
    let line = before.matches('\n').count() + 1;
    let col = before[before.rfind('\n').map(|i| i + 1).unwrap_or(0)..].chars().count() + 1;
    (line, col)
}

/// toml's error as "line L, column C: what is wrong" followed by the offending line, both cut to
/// fit a message (toml itself would echo a line of any length in full).
pub(super) fn toml_message(source: &str, e: &toml::de::Error) -> String {
    // serde quotes user text (an unknown key, a bad string) in full: cut every long word at 80
    // characters, and the whole at 300
    let what: Vec<String> = e.message().trim().split(' ').map(|w| if w.chars().count() > QUOTE_LIMIT { quote(w) } else { w.to_string() }).collect();
    let what = unquoted_key_list(&what.join(" "));
    let what = quote_long(&what, 300);
    let Some(span) = e.span() else { return what };
    let (line, col) = line_col_of(source, span.start);
    // `E = 210 GPa`: toml asks for quotes, but the value is meant as a number
    // (toml may point inside the value, at the unit of `2e4MPa`: back to the value's start)
    let before = source.get(..span.start).unwrap_or("");
    let value_start = before.trim_end_matches(|c: char| c.is_ascii_digit() || matches!(c, '.' | '+' | '-' | '_' | 'e' | 'E')).len();
    // `E = "210 GPa"`: serde says "invalid type: string"; the value is the same mistake
    let quoted = what.starts_with("invalid type: string").then(|| source.get(span.start..).and_then(|t| t.strip_prefix('"')).unwrap_or("")).filter(|t| !t.is_empty());
    let what = match number_with_unit(quoted.unwrap_or(source.get(value_start..).unwrap_or(""))) {
        Some((number, unit)) => format!(
            "'{}' is a number followed by a unit: values are plain numbers in the units the whole file uses, and stamp converts nothing ([units] only labels the outputs){}",
            quote(&format!("{number} {unit}")),
            converted(source, number, unit)
        ),
        None => what,
    };
    // an unknown key: toml points at the key itself, which the message names; its table is named
    // before it ("punch[0]: unknown field `radios`")
    let unknown_key = || {
        let text = source.lines().nth(line.checked_sub(1)?)?;
        let eq = text.chars().skip(col.saturating_sub(1)).position(|c| c == '=')?;
        let key = key_at(source, line, col + eq + 1)?;
        key.rsplit_once('.').map(|(table, _)| table.to_string())
    };
    let key = if what.starts_with("unknown field") { unknown_key() } else { key_at(source, line, col) };
    let what = match key {
        // our own checks may name the key already ("mesh.rectangle.n: ...")
        Some(key) if !what.starts_with(&key) => format!("{}: {what}", quote(&key)),
        _ => what,
    };
    format!("line {line}, column {col}: {what}\n{}", source_window(source, line, col))
}

/// serde's "unknown field `x`, expected one of `a`, `b`, ..." with the table's keys listed without
/// their backquotes: the list of a table of many keys (`[[punch]]`'s 22) stays whole within a
/// message's length.
fn unquoted_key_list(what: &str) -> String {
    const LIST: &str = ", expected one of ";
    match what.split_once(LIST) {
        Some((head, keys)) if what.starts_with("unknown field") => format!("{head}{LIST}{}", keys.replace('`', "")),
        _ => what.to_string(),
    }
}

/// Known units as (name, kind in [units], factor to SI).
const KNOWN_UNITS: &[(&str, &str, f64)] = &[
    ("Pa", "pressure", 1.0),
    ("kPa", "pressure", 1e3),
    ("MPa", "pressure", 1e6),
    ("GPa", "pressure", 1e9),
    ("N/mm^2", "pressure", 1e6),
    ("N/mm2", "pressure", 1e6),
    ("N/m^2", "pressure", 1.0),
    ("mN", "force", 1e-3),
    ("N", "force", 1.0),
    ("kN", "force", 1e3),
    ("MN", "force", 1e6),
    ("um", "length", 1e-6),
    ("mm", "length", 1e-3),
    ("cm", "length", 1e-2),
    ("m", "length", 1.0),
    ("km", "length", 1e3),
];

/// The value the file should hold for `number unit`: converted into the unit its `[units]` table
/// gives for that kind ("; with [units] pressure = \"MPa\": write 210000"), or advice to convert
/// by hand when the file names none (the number alone would be read in the file's units, which
/// is how `E = 210` in a file of MPa made a plate 1000 times too soft).
fn converted(source: &str, number: &str, unit: &str) -> String {
    let Some(&(_, kind, factor)) = KNOWN_UNITS.iter().find(|u| u.0 == unit) else {
        return ": write the number converted into the units of the rest of the file".to_string();
    };
    let file_unit = file_units(source).into_iter().find(|(k, _)| k == kind).map(|(_, u)| u);
    let value: Option<f64> = number.replace('_', "").parse().ok();
    match (file_unit.as_deref().and_then(|u| KNOWN_UNITS.iter().find(|k| k.0 == u && k.1 == kind)), value) {
        (Some(&(name, _, to)), Some(v)) => format!(": with [units] {kind} = \"{name}\", write {}", v * factor / to),
        _ => format!(": write it converted into the file's {kind} unit (e.g. {} {unit} is {} in MPa), and name that unit in [units] {kind}", number, value.map(|v| v * factor / 1e6).unwrap_or(f64::NAN)),
    }
}

/// The `[units]` table's entries (kind, unit) read from the text (the file may not parse as a
/// whole: this is for an error's advice).
fn file_units(source: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut inside = false;
    for line in source.lines() {
        let t = line.split('#').next().unwrap_or("").trim();
        if t.starts_with('[') {
            inside = t == "[units]";
            continue;
        }
        if let (true, Some((k, v))) = (inside, t.split_once('=')) {
            out.push((k.trim().to_string(), v.trim().trim_matches('"').to_string()));
        }
    }
    out
}

/// A value written as a number followed by a unit word (`210 GPa`, `2mm`, `0.05 N/mm`): the
/// number and the unit, else None. `text` starts at the value.
fn number_with_unit(text: &str) -> Option<(&str, &str)> {
    let line = text.lines().next()?;
    let end = line.find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '+' | '-' | '_' | 'e' | 'E'))).unwrap_or(line.len());
    // the longest prefix that is a number ("2e4MPa": "2e4"; "5em": "5")
    let (number, rest) = (1..=end).rev().map(|k| line.split_at(k)).find(|(n, _)| n.replace('_', "").parse::<f64>().is_ok())?;
    let rest = rest.trim_start();
    let unit_end = rest.find(|c: char| c.is_whitespace() || matches!(c, ',' | ']' | '}' | '#' | '"')).unwrap_or(rest.len());
    let unit = &rest[..unit_end];
    unit.chars().next().is_some_and(|c| c.is_alphabetic() || c == '%').then_some((number, unit))
}

/// "  L | <the line around the column>": the problem file's line under an error (at most 60
/// characters of it, from 30 before the column, control bytes hidden).
pub(super) fn source_window(source: &str, line: usize, col: usize) -> String {
    let text = source.lines().nth(line.saturating_sub(1)).unwrap_or("");
    let skip = col.saturating_sub(30);
    let shown: String = text.chars().skip(skip).collect();
    format!("  {line} | {}{}", if skip > 0 { "..." } else { "" }, quote_long(&shown, 60))
}

/// The dotted key whose value sits at (line, column), for toml errors, which give only a place:
/// the last `key =` before the column on that line, after the last `[table]` header above it
/// ("solver.steps", "mesh.n" inside an inline table). None when the place is not a value.
fn key_at(source: &str, line: usize, col: usize) -> Option<String> {
    let text = source.lines().nth(line.checked_sub(1)?)?;
    let before: String = text.chars().take(col.saturating_sub(1)).collect();
    // walk the line up to the column: `key =` sets the pending key, `{` opens an inline table
    // under it, `}` closes one (strings are skipped)
    let (mut stack, mut pending, mut word, mut in_string): (Vec<String>, Option<String>, String, bool) = (Vec::new(), None, String::new(), false);
    for c in before.chars() {
        match c {
            '"' => in_string = !in_string,
            _ if in_string => {}
            '=' => pending = Some(std::mem::take(&mut word).trim().trim_matches('"').to_string()).filter(|k| !k.is_empty()),
            '{' => stack.extend(pending.take()),
            '}' => {
                stack.pop();
                pending = None;
            }
            ',' => word.clear(),
            c if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') => word.push(c),
            c if c.is_whitespace() => {}
            _ => word.clear(),
        }
    }
    stack.extend(pending);
    if stack.is_empty() {
        return None;
    }
    let key = stack.join(".");
    // the last header above; an array of tables ([[punch]]) gets its index, as in "punch[1]"
    let headers: Vec<(bool, String)> = source
        .lines()
        .take(line - 1)
        .filter_map(|l| {
            let l = l.trim();
            l.starts_with('[').then(|| (l.starts_with("[["), l.trim_start_matches('[').split(']').next().unwrap_or("").trim().to_string()))
        })
        .collect();
    Some(match headers.last() {
        Some((true, t)) => format!("{t}[{}].{key}", headers.iter().filter(|(a, h)| *a && h == t).count() - 1),
        Some((false, t)) if !t.is_empty() => format!("{t}.{key}"),
        _ => key,
    })
}

/// [`quote`] with a longer limit (toml's messages list expected keys): control characters become
/// '?', the text is cut at `limit` characters.
fn quote_long(text: &str, limit: usize) -> String {
    let total = text.chars().count();
    let mut out: String = text.chars().take(limit).map(|c| if c.is_control() { '?' } else { c }).collect();
    if total > limit {
        out.push_str(&format!("... ({total} characters)"));
    }
    out
}
