//! Mutation test of the problem-file reader: the shipped problem files (meshes/*.toml) mutated a
//! few thousand times (numbers replaced by extreme values, lines deleted or duplicated, keys
//! swapped, the file truncated, random bytes and huge strings inserted), each fed through
//! `Problem::parse` and `build` (not the solve). Every mutant must give Ok or an error of at most
//! a few hundred characters, and never panic. Deterministic: a fixed xorshift seed.

mod common;
use common::*;
use stamp_cli::run::{build::build, Problem};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

/// How many mutants in all.
const MUTANTS: usize = 5000;
/// The longest error message accepted (without the problem file's path).
const MAX_MESSAGE: usize = 400;

/// xorshift64* (Vigna 2016): enough randomness for a test, no crate needed.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// The replacements of a number.
fn extremes() -> Vec<String> {
    let mut v: Vec<String> = [
        "0", "-1", "1e300", "-1e308", "5e-324", "nan", "inf", "-inf", "9223372036854775807", "18446744073709551615", "-9223372036854775808", "1e-300",
        "0.0", "-0.0", "4294967296", "1e12", "1e6", "2.5", "[]", "[1e300, 1e300]", "\"x\"", "true",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    v.push(format!("\"{}\"", "s".repeat(100_000)));
    v
}

/// Byte ranges of the number tokens of a TOML text (outside strings and comments).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let (mut i, mut in_string, mut in_comment) = (0, false, false);
    while i < b.len() {
        let c = b[i];
        if in_comment {
            in_comment = c != b'\n';
        } else if in_string {
            in_string = c != b'"';
        } else if c == b'"' {
            in_string = true;
        } else if c == b'#' {
            in_comment = true;
        } else if (c.is_ascii_digit() || c == b'-') && i > 0 && matches!(b[i - 1], b' ' | b'=' | b'[' | b',') {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || matches!(b[i], b'.' | b'-' | b'+' | b'_')) {
                i += 1;
            }
            if text[start..i].bytes().any(|x| x.is_ascii_digit()) {
                out.push((start, i));
            }
            continue;
        }
        i += 1;
    }
    out
}

/// The largest char boundary <= i.
fn floor_char(text: &str, mut i: usize) -> usize {
    i = i.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// One random mutation of `text`, and what it did.
fn mutate(text: &str, rng: &mut Rng, extremes: &[String]) -> (String, String) {
    let lines: Vec<&str> = text.lines().collect();
    if lines.is_empty() {
        return (text.to_string(), "nothing (empty text)".into());
    }
    match rng.below(8) {
        0 | 1 | 2 => {
            let nums = numbers(text);
            if nums.is_empty() {
                return (text.to_string(), "nothing".into());
            }
            let (a, b) = nums[rng.below(nums.len())];
            let x = &extremes[rng.below(extremes.len())];
            (format!("{}{}{}", &text[..a], x, &text[b..]), format!("number {} -> {}", &text[a..b], stamp::quote(x)))
        }
        3 => {
            let k = rng.below(lines.len());
            let mut l = lines.clone();
            l.remove(k);
            (l.join("\n"), format!("delete line {}", k + 1))
        }
        4 => {
            let k = rng.below(lines.len());
            let mut l = lines.clone();
            l.insert(k, lines[k]);
            (l.join("\n"), format!("duplicate line {}", k + 1))
        }
        5 => {
            // swap the keys of two `key = value` lines
            let keyed: Vec<usize> = (0..lines.len()).filter(|&k| lines[k].contains(" = ") && !lines[k].trim_start().starts_with('#')).collect();
            if keyed.len() < 2 {
                return (text.to_string(), "nothing".into());
            }
            let (i, j) = (keyed[rng.below(keyed.len())], keyed[rng.below(keyed.len())]);
            let (ki, vi) = lines[i].split_once(" = ").unwrap();
            let (kj, vj) = lines[j].split_once(" = ").unwrap();
            let mut l: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
            l[i] = format!("{kj} = {vi}");
            l[j] = format!("{ki} = {vj}");
            (l.join("\n"), format!("swap the keys of lines {} and {}", i + 1, j + 1))
        }
        6 => {
            let at = floor_char(text, rng.below(text.len()));
            (text[..at].to_string(), format!("truncate at byte {at}"))
        }
        _ => {
            // random characters (control characters, quotes, brackets, non-ASCII) at a random place
            let at = floor_char(text, rng.below(text.len()));
            let n = 1 + rng.below(8);
            let junk: String = (0..n)
                .map(|_| match rng.below(4) {
                    0 => char::from(rng.below(32) as u8),
                    1 => ['"', '[', ']', '{', '}', '=', ',', '\n', '#', '.'][rng.below(10)],
                    2 => char::from_u32(0x80 + rng.below(0x2000) as u32).unwrap_or('?'),
                    _ => char::from(0x20 + rng.below(95) as u8),
                })
                .collect();
            (format!("{}{}{}", &text[..at], junk, &text[at..]), format!("insert {} at byte {at}", stamp::quote(&junk)))
        }
    }
}

#[test]
fn mutated_shipped_problem_files_never_panic_and_give_short_errors() {
    let dir = repo().join("meshes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().and_then(|e| e.to_str()) == Some("toml")).collect();
    files.sort();
    assert!(files.len() >= 5, "{files:?}");
    let texts: Vec<(PathBuf, String)> = files.iter().map(|p| (p.clone(), std::fs::read_to_string(p).unwrap())).collect();
    let extremes = extremes();
    // STAMP_MUTATION_SEED / STAMP_MUTANTS explore further (the suite runs the fixed ones)
    let seed = std::env::var("STAMP_MUTATION_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(0x9e37_79b9_7f4a_7c15u64);
    let count = std::env::var("STAMP_MUTANTS").ok().and_then(|s| s.parse().ok()).unwrap_or(MUTANTS);
    let mut rng = Rng(seed | 1);
    let (mut ok, mut refused) = (0, 0);
    let start = std::time::Instant::now();
    for k in 0..count {
        let (path, text) = &texts[rng.below(texts.len())];
        let (mut mutant, mut what) = mutate(text, &mut rng, &extremes);
        // sometimes two mutations at once
        if rng.below(4) == 0 {
            let (m2, w2) = mutate(&mutant, &mut rng, &extremes);
            mutant = m2;
            what = format!("{what}; {w2}");
        }
        let outcome = catch_unwind(AssertUnwindSafe(|| check(path, &mutant)));
        match outcome {
            Ok(Ok(())) => ok += 1,
            Ok(Err(msg)) => {
                let len = msg.replace(&path.display().to_string(), "").chars().count();
                assert!(len <= MAX_MESSAGE, "mutant {k} of {} ({what}): a message of {len} characters:\n{msg}", path.display());
                refused += 1;
            }
            Err(_) => {
                let shown: String = mutant.chars().take(3000).collect();
                panic!("mutant {k} of {} ({what}) panicked; the input:\n{shown}", path.display());
            }
        }
    }
    eprintln!("{count} mutants: {ok} accepted, {refused} refused, in {:.1} s", start.elapsed().as_secs_f64());
    assert!(refused > count / 4 && ok > count / 20, "{ok} accepted, {refused} refused: the mutations do not exercise both ways");
}

/// Parse and build (no solve); the error message on failure.
fn check(path: &Path, text: &str) -> Result<(), String> {
    let p = Problem::parse(path, text.to_string()).map_err(|e| e.to_string())?;
    build(&p).map(|_| ()).map_err(|e| e.to_string())
}
