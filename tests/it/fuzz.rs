//! Fuzzing the asset parsers: the shipped files, mutated by a small seeded mutator (bytes
//! flipped, numbers replaced by extremes, fields dropped or duplicated, file names replaced,
//! files cut short). Every input must be refused with an error, or load and then run a few
//! frames headless; never a panic. `SIMLOD_FUZZ_CASES` sets how many inputs (default 300);
//! `SIMLOD_FUZZ_SEED` where the mutator starts.

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use crate::assets::assets_with;
use crate::support::*;
use simlod::config::SimConfig;
use simlod::headless::HeadlessSim;

const FILES: [&str; 6] = [
    "scenarios/default.ron",
    "arena.ron",
    "rules/levels.ron",
    "creatures/hopper.ron",
    "creatures/biped.ron",
    "gaits/hopper.ron",
];

const NUMBERS: [&str; 16] = [
    "0",
    "0.0",
    "-1",
    "-1.0",
    "1e30",
    "-1e30",
    "NaN",
    "inf",
    "-inf",
    "1e-30",
    "4294967296",
    "2000000",
    "1e6",
    "0.0001",
    "2000",
    "1",
];

const NAMES: [&str; 12] = [
    "",
    "../arena.ron",
    "/etc/passwd",
    "creatures",
    "gaits/",
    "gaits/hopper.ron",
    "arena.ron",
    "rules/levels.ron",
    "hopper",
    "biped",
    "creatures/hopper.ron",
    "a\u{0}b",
];

/// Byte ranges of the numbers in `text` (digits with a sign, point and exponent).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit() && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'));
        if starts {
            let start = if i > 0 && b[i - 1] == b'-' { i - 1 } else { i };
            let mut j = i;
            while j < b.len() && (b[j].is_ascii_digit() || b"._eE-+".contains(&b[j])) {
                j += 1;
            }
            spans.push((start, j));
            i = j;
        } else {
            i += 1;
        }
    }
    spans
}

/// Byte ranges of the insides of the quoted strings in `text`.
fn strings(text: &str) -> Vec<(usize, usize)> {
    let quotes: Vec<usize> = text.match_indices('"').map(|(i, _)| i).collect();
    quotes.chunks_exact(2).map(|q| (q[0] + 1, q[1])).collect()
}

fn pick<T: Copy>(rng: &mut StdRng, items: &[T]) -> Option<T> {
    (!items.is_empty()).then(|| items[rng.random_range(0..items.len())])
}

/// One mutation of `bytes`, and what it was.
fn mutate(rng: &mut StdRng, bytes: &mut Vec<u8>) -> String {
    if bytes.is_empty() {
        return "nothing: the file is already empty".to_owned();
    }
    let text = String::from_utf8_lossy(bytes).into_owned();
    match rng.random_range(0..8) {
        0 => {
            let i = rng.random_range(0..bytes.len());
            let bit = 1u8 << rng.random_range(0..8);
            bytes[i] ^= bit;
            format!("flipped bit {bit:#x} of byte {i}")
        }
        1 | 2 => match pick(rng, &numbers(&text)) {
            Some((a, b)) => {
                let n = NUMBERS[rng.random_range(0..NUMBERS.len())];
                *bytes = format!("{}{n}{}", &text[..a], &text[b..]).into_bytes();
                format!("number at {a} ({}) -> {n}", &text[a..b])
            }
            None => "nothing".to_owned(),
        },
        3 | 4 => {
            let lines: Vec<&str> = text.split_inclusive('\n').collect();
            let i = rng.random_range(0..lines.len());
            let drop = rng.random_bool(0.5);
            let mut out = String::new();
            for (j, l) in lines.iter().enumerate() {
                if j != i || !drop {
                    out.push_str(l);
                }
                if j == i && !drop {
                    out.push_str(l);
                }
            }
            *bytes = out.into_bytes();
            format!("line {} {}", i + 1, if drop { "dropped" } else { "duplicated" })
        }
        5 => match pick(rng, &strings(&text)) {
            Some((a, b)) => {
                let s = NAMES[rng.random_range(0..NAMES.len())];
                *bytes = format!("{}{s}{}", &text[..a], &text[b..]).into_bytes();
                format!("string at {a} ({}) -> {s:?}", &text[a..b])
            }
            None => "nothing".to_owned(),
        },
        6 => {
            let at = rng.random_range(0..bytes.len());
            bytes.truncate(at);
            format!("cut at byte {at}")
        }
        _ => {
            bytes.splice(0..0, [0xef, 0xbb, 0xbf]);
            "byte-order mark".to_owned()
        }
    }
}

/// Loads the mutated assets; if they load, runs a few frames. The outcome, or the panic.
fn try_case(root: &std::path::Path) -> Result<bool, String> {
    catch_unwind(AssertUnwindSafe(|| {
        match SimConfig::load(&root.join("scenarios/default.ron"), root) {
            Err(e) => {
                assert!(!e.problems.is_empty() && !e.to_string().is_empty());
                false
            }
            Ok(config) => {
                let mut sim = HeadlessSim::new(config);
                for _ in 0..3 {
                    sim.advance_frame();
                }
                true
            }
        }
    }))
    .map_err(|p| {
        p.downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

#[test]
fn mutated_asset_files_are_refused_or_run_never_panic() {
    let cases: u64 = std::env::var("SIMLOD_FUZZ_CASES").map_or(300, |v| v.parse().unwrap());
    let seed: u64 = std::env::var("SIMLOD_FUZZ_SEED").map_or(16, |v| v.parse().unwrap());
    let root = assets_with(
        "fuzz",
        "arena.ron",
        &std::fs::read(assets_root().join("arena.ron")).unwrap(),
    );
    let mut rng = StdRng::seed_from_u64(seed);
    let (mut loaded, mut panics, mut slowest) = (0, Vec::new(), (0.0, String::new()));
    for case in 0..cases {
        let file = FILES[rng.random_range(0..FILES.len())];
        let original = std::fs::read(assets_root().join(file)).unwrap();
        let mut bytes = original.clone();
        let what: Vec<String> = (0..rng.random_range(1..=3))
            .map(|_| mutate(&mut rng, &mut bytes))
            .collect();
        let what = format!("case {case}: {file}: {}", what.join("; "));
        std::fs::write(root.join(file), &bytes).unwrap();
        let start = Instant::now();
        match try_case(&root) {
            Ok(ran) => loaded += u32::from(ran),
            Err(message) => {
                let keep = root.parent().unwrap().join(format!("fuzz_panic_{case}.ron"));
                std::fs::write(&keep, &bytes).unwrap();
                panics.push(format!("{what}: {message} (input kept in {})", keep.display()));
            }
        }
        let took = start.elapsed().as_secs_f64();
        if took > slowest.0 {
            slowest = (took, what);
        }
        std::fs::write(root.join(file), &original).unwrap();
    }
    println!(
        "fuzz: {cases} inputs from seed {seed}, {loaded} loaded and ran, {} refused, {} panicked; slowest {:.2} s ({})",
        cases - u64::from(loaded) - panics.len() as u64,
        panics.len(),
        slowest.0,
        slowest.1
    );
    assert!(panics.is_empty(), "{}", panics.join("\n"));
}
