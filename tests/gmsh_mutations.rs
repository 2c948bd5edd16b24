//! Mutation test of the gmsh reader: thousands of corrupted versions of the ASCII and binary
//! fixtures (numbers replaced by 0, -1, 2^63, 10^12, 2^64-1, NaN, ...; lines deleted, duplicated or
//! swapped; bytes flipped, inserted or cut off) must each give a valid mesh or an error of a few
//! hundred characters, never a panic. Deterministic (xorshift generator); a failure writes the
//! mutated input next to the test binary's scratch directory and names it.

use stamp::io::parse_msh_bytes;
use stamp::mesh::check::check_mesh;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

struct XorShift(u64);
impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const NUMBERS: [&str; 12] = [
    "0",
    "-1",
    "9223372036854775808",
    "1000000000000",
    "18446744073709551615",
    "NaN",
    "inf",
    "1e308",
    "-0",
    "2",
    "4294967296",
    "-2147483649",
];

/// Spans of the whitespace-separated tokens of `b` that look like numbers.
fn number_spans(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let s = i;
        while i < b.len() && !b[i].is_ascii_whitespace() {
            i += 1;
        }
        if b[s].is_ascii_digit() || b[s] == b'-' {
            out.push((s, i));
        }
    }
    out
}

fn line_spans(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut s = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            out.push((s, i + 1));
            s = i + 1;
        }
    }
    if s < b.len() {
        out.push((s, b.len()));
    }
    out
}

/// One random mutation of `b`, with a description.
fn mutate(b: &[u8], binary: bool, rng: &mut XorShift) -> (Vec<u8>, String) {
    if b.len() < 16 || number_spans(b).is_empty() {
        return (b.to_vec(), "nothing (input too short)".into());
    }
    let kind = rng.below(if binary { 8 } else { 7 });
    match kind {
        0 | 1 => {
            // a number replaced (in binary files, only the ASCII parts have tokens worth it)
            let spans = number_spans(b);
            let (s, e) = spans[rng.below(spans.len())];
            let v = NUMBERS[rng.below(NUMBERS.len())];
            ([&b[..s], v.as_bytes(), &b[e..]].concat(), format!("number at {s}..{e} -> {v}"))
        }
        2 => {
            let l = line_spans(b);
            let (s, e) = l[rng.below(l.len())];
            ([&b[..s], &b[e..]].concat(), format!("line at {s} deleted"))
        }
        3 => {
            let l = line_spans(b);
            let (s, e) = l[rng.below(l.len())];
            ([&b[..e], &b[s..e], &b[e..]].concat(), format!("line at {s} duplicated"))
        }
        4 => {
            let l = line_spans(b);
            let (i, j) = (rng.below(l.len()), rng.below(l.len()));
            let (i, j) = (i.min(j), i.max(j));
            if i == j {
                return (b.to_vec(), "nothing".into());
            }
            let (a, c) = (l[i], l[j]);
            ([&b[..a.0], &b[c.0..c.1], &b[a.1..c.0], &b[a.0..a.1], &b[c.1..]].concat(), format!("lines at {} and {} swapped", a.0, c.0))
        }
        5 => {
            let mut v = b.to_vec();
            let n = 1 + rng.below(4);
            let mut what = String::from("bytes flipped at");
            for _ in 0..n {
                let p = rng.below(v.len());
                v[p] ^= 1 << rng.below(8);
                what += &format!(" {p}");
            }
            (v, what)
        }
        6 => {
            if rng.below(2) == 0 {
                let p = rng.below(b.len());
                (b[..p].to_vec(), format!("cut at {p}"))
            } else {
                let p = rng.below(b.len());
                let n = 1 + rng.below(16);
                let ins: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
                ([&b[..p], ins.as_slice(), &b[p..]].concat(), format!("{n} bytes inserted at {p}"))
            }
        }
        _ => {
            // binary: 8 bytes overwritten with a special integer or double
            let specials: [u64; 7] = [0, u64::MAX, 1 << 63, 1_000_000_000_000, f64::NAN.to_bits(), u32::MAX as u64, 1 << 32];
            let mut v = b.to_vec();
            let p = rng.below(v.len().saturating_sub(8));
            let x = specials[rng.below(specials.len())];
            let w = if rng.below(2) == 0 { 8 } else { 4 };
            v[p..p + w].copy_from_slice(&x.to_le_bytes()[..w]);
            (v, format!("{w} bytes at {p} -> {x:#x}"))
        }
    }
}

#[test]
fn mutated_meshes_give_a_mesh_or_a_short_error() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let fixtures = [
        ("rect.msh", false, 700),
        ("rect_bin.msh", true, 700),
        ("holed.msh", false, 500),
        ("holed_tri.msh", false, 600),
        ("holed_tri_bin.msh", true, 500),
        ("holed_quad9.msh", false, 500),
    ];
    // STAMP_MUTATION_SEED and STAMP_MUTATION_SCALE (a multiplier of the counts) run other or
    // longer series by hand.
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    let scale = env("STAMP_MUTATION_SCALE").unwrap_or(3) as usize;
    let mut rng = XorShift(env("STAMP_MUTATION_SEED").unwrap_or(0x9e37_79b9_7f4a_7c15).max(1));
    let (mut ok, mut refused) = (0, 0);
    let start = std::time::Instant::now();
    for (name, binary, n) in fixtures {
        let original = std::fs::read(dir.join(name)).unwrap();
        for k in 0..n * scale {
            let (bytes, what) = mutate(&original, binary, &mut rng);
            // a second mutation on a third of them
            let (bytes, what) = if k % 3 == 0 {
                let (b2, w2) = mutate(&bytes, binary, &mut rng);
                (b2, format!("{what}; {w2}"))
            } else {
                (bytes, what)
            };
            let result = catch_unwind(AssertUnwindSafe(|| parse_msh_bytes(Path::new(name), &bytes)));
            let fail = |why: String| -> ! {
                let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("mutation-{k}-{name}"));
                std::fs::write(&out, &bytes).unwrap();
                panic!("{name}, mutation {k} ({what}): {why}; the input is in {}", out.display())
            };
            match result {
                Err(_) => fail("the reader panicked".into()),
                Ok(Ok(m)) => {
                    if let Err(d) = check_mesh(&m.mesh) {
                        fail(format!("accepted a mesh that fails the checks: {d:?}"));
                    }
                    if m.node_tags.len() != m.mesh.num_nodes() || m.cell_tags.len() != m.mesh.num_cells() {
                        fail("tag arrays of the wrong length".into());
                    }
                    ok += 1;
                }
                Ok(Err(e)) => {
                    let msg = e.to_string();
                    if msg.len() > 400 || msg.chars().any(|c| c.is_control()) || !msg.starts_with(name) {
                        fail(format!("bad message ({} bytes): {msg}", msg.len()));
                    }
                    refused += 1;
                }
            }
        }
    }
    println!("{ok} mutated files accepted, {refused} refused, in {:.2} s", start.elapsed().as_secs_f64());
    // Both outcomes occur (the mutations are not all harmless nor all fatal).
    assert!(ok > 100 && refused > 1000, "{ok} accepted, {refused} refused");
}
