//! Fuzzing the asset parsers: every kind of shipped file, mutated by a small seeded mutator
//! (bytes flipped, numbers replaced by extremes, fields dropped or duplicated, file names
//! replaced by other files' names, a file replaced by another kind of file, files cut short).
//! Every input must be refused with an error, or load and then run a few frames headless under
//! a policy the mutator picks; never a panic. `SIMLOD_FUZZ_CASES` sets how many inputs (default
//! 300); `SIMLOD_FUZZ_SEED` where the mutator starts. Property tests (proptest) below feed the
//! parsers and the validation arbitrary text and numbers.

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use crate::assets::assets_with;
use crate::support::*;
use proptest::strategy::Strategy;
use simlod::config::{ConfigError, SimConfig, load_file};
use simlod::headless::HeadlessSim;
use simlod::lod::LevelPolicy;
use simlod_lab::experiments::{
    ExperimentFile, budget::BudgetSettings, crowd::CrowdSettings, fig7::Fig7Settings, fig10::Fig10Settings,
    frame_rate::FrameRateSettings, step_response::StepResponseConfig, table1::Table1Settings,
};
use std::path::Path;

/// The files the default scenario loads: the scenario, and every file it names.
const SIMULATION_FILES: [&str; 8] = [
    "scenarios/default.ron",
    "arena.ron",
    "rules/levels.ron",
    "costs.ron",
    "creatures/hopper.ron",
    "creatures/biped.ron",
    "gaits/hopper.ron",
    "gaits/biped.ron",
];

/// The experiments' files, each read by its own settings type.
const EXPERIMENT_FILES: [&str; 8] = [
    "experiments/step_response.ron",
    "experiments/table1.ron",
    "experiments/fig7.ron",
    "experiments/fig8.ron",
    "experiments/fig9.ron",
    "experiments/fig10.ron",
    "experiments/budget.ron",
    "experiments/crowd.ron",
];

/// Loads an experiment's file as its experiment does.
fn load_experiment_file(path: &Path) -> Result<(), ConfigError> {
    let name = path.file_stem().unwrap().to_str().unwrap();
    match name {
        "step_response" => load_file::<StepResponseConfig>(path).map(drop),
        "table1" => load_file::<ExperimentFile<Table1Settings>>(path).map(drop),
        "fig7" => load_file::<ExperimentFile<Fig7Settings>>(path).map(drop),
        "fig8" | "fig9" => load_file::<ExperimentFile<FrameRateSettings>>(path).map(drop),
        "fig10" => load_file::<ExperimentFile<Fig10Settings>>(path).map(drop),
        "budget" => load_file::<ExperimentFile<BudgetSettings>>(path).map(drop),
        "crowd" => load_file::<ExperimentFile<CrowdSettings>>(path).map(drop),
        _ => unreachable!("{name}"),
    }
}

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

const NAMES: [&str; 18] = [
    "",
    "gaits/biped.ron",
    "gaits/stilt.ron",
    "costs.ron",
    "rules/budget-contacts.ron",
    "stilt",
    "experiments/fig10.ron",
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
    match rng.random_range(0..9) {
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
        7 => {
            bytes.splice(0..0, [0xef, 0xbb, 0xbf]);
            "byte-order mark".to_owned()
        }
        _ => {
            // A link to the wrong file: another kind's table, a cost model where rules are, ...
            let other = if rng.random_bool(0.5) {
                SIMULATION_FILES[rng.random_range(0..SIMULATION_FILES.len())]
            } else {
                EXPERIMENT_FILES[rng.random_range(0..EXPERIMENT_FILES.len())]
            };
            *bytes = std::fs::read(assets_root().join(other)).unwrap();
            format!("replaced by {other}")
        }
    }
}

/// Loads the mutated file: an experiment's by its settings type; otherwise the default
/// scenario and everything it names, and if they load, a few frames under `policy`. Whether it
/// loaded, or the panic.
fn try_case(root: &Path, file: &str, policy: LevelPolicy) -> Result<bool, String> {
    catch_unwind(AssertUnwindSafe(|| {
        let loaded = if file.starts_with("experiments/") {
            load_experiment_file(&root.join(file))
        } else {
            SimConfig::load(&root.join("scenarios/default.ron"), root).map(|mut config| {
                config.scenario.level_policy = policy;
                let mut sim = HeadlessSim::new(config);
                for _ in 0..3 {
                    sim.advance_frame();
                }
            })
        };
        match loaded {
            Err(e) => {
                assert!(!e.problems.is_empty() && !e.to_string().is_empty());
                false
            }
            Ok(()) => true,
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
        let files = [&SIMULATION_FILES[..], &EXPERIMENT_FILES[..]].concat();
        let file = files[rng.random_range(0..files.len())];
        let policy = LevelPolicy::ALL[rng.random_range(0..LevelPolicy::ALL.len())];
        let original = std::fs::read(assets_root().join(file)).unwrap();
        let mut bytes = original.clone();
        let what: Vec<String> = (0..rng.random_range(1..=3))
            .map(|_| mutate(&mut rng, &mut bytes))
            .collect();
        let what = format!("case {case}: {file} ({policy:?}): {}", what.join("; "));
        std::fs::write(root.join(file), &bytes).unwrap();
        let start = Instant::now();
        match try_case(&root, file, policy) {
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

/// Every file type, parsed and validated from `text`: the first error, if any.
fn parse_as_every_type(text: &str) -> Vec<Result<(), ConfigError>> {
    use simlod::config::{ArenaConfig, CostModel, CreatureDef, LevelRules, Scenario, parse_ron};
    use simlod::gait::GaitTable;
    let (b, f) = (text.as_bytes(), Path::new("fuzzed.ron"));
    vec![
        parse_ron::<Scenario>(b, f).map(drop),
        parse_ron::<ArenaConfig>(b, f).map(drop),
        parse_ron::<LevelRules>(b, f).map(drop),
        parse_ron::<CostModel>(b, f).map(drop),
        parse_ron::<CreatureDef>(b, f).map(drop),
        parse_ron::<GaitTable>(b, f).map(drop),
        parse_ron::<ExperimentFile<Fig10Settings>>(b, f).map(drop),
        parse_ron::<ExperimentFile<BudgetSettings>>(b, f).map(drop),
    ]
}

/// A number as RON writes it, special values included.
fn ron_number(v: f64) -> String {
    if v.is_nan() {
        "NaN".to_owned()
    } else if v.is_infinite() {
        (if v > 0.0 { "inf" } else { "-inf" }).to_owned()
    } else {
        format!("{v:?}")
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, ..Default::default() })]

    /// Text of any kind, RON-like or not, is refused with a message or read: never a panic.
    #[test]
    fn any_text_is_refused_with_a_message_or_read(text in "[ -~\n]{0,200}|\\PC{0,200}") {
        for parsed in parse_as_every_type(&text) {
            if let Err(e) = parsed {
                proptest::prop_assert!(!e.problems.is_empty() && !e.to_string().is_empty());
            }
        }
    }

    /// Any number in any numeric place of any shipped simulation file is refused naming a
    /// field, or gives a world that builds and runs a frame.
    #[test]
    fn any_number_anywhere_is_refused_naming_a_field_or_runs(
        file in 0..SIMULATION_FILES.len(),
        place in 0usize..10_000,
        value in proptest::prop_oneof![
            proptest::num::f64::ANY,
            -1e4..1e4f64,
            proptest::prelude::Just(0.0),
            (0u32..1000).prop_map(f64::from),
        ],
    ) {
        let file = SIMULATION_FILES[file];
        let text = std::fs::read_to_string(assets_root().join(file)).unwrap();
        let spans = numbers(&text);
        let (a, b) = spans[place % spans.len()];
        let root = assets_with("proptest_numbers", file, format!("{}{}{}", &text[..a], ron_number(value), &text[b..]).as_bytes());
        match SimConfig::load(&root.join("scenarios/default.ron"), &root) {
            Err(e) => proptest::prop_assert!(
                e.problems.iter().all(|p| !p.message.is_empty()) && !e.problems.is_empty(),
                "{e}"
            ),
            Ok(config) => {
                let mut sim = HeadlessSim::new(config);
                sim.advance_frame();
            }
        }
    }
}
