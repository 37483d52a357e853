//! Figure 10: what the levels change. For each puck radius, trials of a game from their own
//! initial conditions (their own seeds) under the influence policy, each beside the identical
//! trial all rigid; the measure is the paper's, the creatures that collided with the puck or a
//! wall. Trials are independent: they run on `--jobs` threads, split into `--shard`s, and an
//! interrupted run resumes from `fig10.partial.csv` without redoing finished trials.
//!
//! Over 600 lines: the trials, the shards, resuming and merging all read and write the rows of
//! one CSV file, kept in one place.

use crate::error::{LabError, io_error};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use super::plot::{self, Mark, Panel, Series};
use super::{ExperimentRecord, Options, Shard, command, load_settings, mean_and_variance, run_parallel, trials};
use simlod::config::{LevelRules, SimConfig, Validate, Validator, load_file};
use simlod::headless;
use simlod::lod::{LevelPolicy, Lod};

/// `assets/experiments/fig10.ron`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fig10Settings {
    /// The puck's radii of influence.
    pub radii_m: Vec<f32>,
    /// The level rules the trials run under (a file under the assets folder), with the
    /// influence policy.
    pub rules: String,
    /// Length of each trial.
    pub seconds: f32,
    /// Trials at each radius; `--trials` overrides it.
    pub trials: u32,
    /// Trial `i` runs with seed `first_seed + i`.
    pub first_seed: u64,
}

impl Validate for Fig10Settings {
    fn validate(&self, v: &mut Validator) {
        v.require(!self.radii_m.is_empty(), "radii_m", "must list at least one radius");
        for (i, r) in self.radii_m.iter().enumerate() {
            v.within(&format!("radii_m[{i}]"), *r, 0.0, 1e4);
        }
        v.require(
            !self.rules.is_empty() && !self.rules.contains([',', '"', '\n']),
            "rules",
            "must name a rules file (without commas or quotes)",
        );
        v.within("seconds", self.seconds, 1.0 / 30.0, simlod::config::MAX_DURATION_S);
        v.require(self.trials >= 1, "trials", "must be at least 1");
    }
}

const HEADER: &str = "puck_radius_m,trial,seed,seconds,rules,collided,collided_all_rigid,difference,falls,falls_all_rigid,mean_rigid,wall_s,wall_s_all_rigid";

/// What a part of figure 10's trials is, written beside its CSV as `fig10.part.json`: a merge
/// or a resume takes only parts made by the same plan and the same simlod, whole and unedited.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Part {
    /// Always `fig10`.
    pub experiment: String,
    /// The simlod version that ran the trials.
    pub version: String,
    /// A digest of everything a trial's outcome depends on: the scenario and every file it
    /// names, the rules the trials run under, the radii, the trial length and the seeds.
    pub plan: String,
    /// The trials of the whole run, over all parts.
    pub trials: u32,
    /// Which part of them, `K/N`.
    pub shard: String,
    /// Rows in the CSV.
    pub rows: usize,
    /// A digest of the CSV's bytes.
    pub checksum: String,
}

const PART_FILE: &str = "fig10.part.json";
/// Beside the journal of an unfinished run: the plan its rows were made by.
const JOURNAL_PLAN_FILE: &str = "fig10.partial.plan";

/// FNV-1a, written out so that a digest on disk means the same to every build.
fn digest(bytes: &[u8]) -> String {
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    format!("{hash:016x}")
}

/// The plan's digest: the config as the trials run it (their rules, any seed and policy) and
/// the settings but the trial count, which decides only how many trials there are.
fn plan_digest(config: &SimConfig, rules: &LevelRules, s: &Fig10Settings) -> String {
    let mut c = config.clone();
    c.rules = rules.clone();
    c.scenario.seed = 0;
    c.scenario.level_policy = LevelPolicy::AllRigid;
    let s = Fig10Settings { trials: 0, ..s.clone() };
    digest(format!("{c:?}\n{s:?}").as_bytes())
}

/// Reads `dir`'s part record and checks its CSV against it.
fn read_part(dir: &Path) -> Result<(Part, Vec<Row>), LabError> {
    let (csv_path, part_path) = (dir.join("fig10.csv"), dir.join(PART_FILE));
    let csv = std::fs::read(&csv_path).map_err(|e| {
        LabError::Invalid(format!(
            "{}: {e} (is {} a finished fig10 run or shard?)",
            csv_path.display(),
            dir.display()
        ))
    })?;
    let part: Part = std::fs::read_to_string(&part_path)
        .map_err(|e| {
            LabError::Invalid(format!(
                "{}: {e}: without it nothing says what made {}",
                part_path.display(),
                csv_path.display()
            ))
        })
        .and_then(|json| {
            serde_json::from_str(&json)
                .map_err(|e| LabError::Invalid(format!("{}: not a fig10 part record: {e}", part_path.display())))
        })?;
    if part.experiment != "fig10" {
        return Err(LabError::Invalid(format!(
            "{}: a part of {}, not of fig10",
            part_path.display(),
            part.experiment
        )));
    }
    if digest(&csv) != part.checksum {
        return Err(LabError::Invalid(format!(
            "{}: changed since it was written (its checksum is {}, its part record says {}): cut short, edited or copied from another run",
            csv_path.display(),
            digest(&csv),
            part.checksum
        )));
    }
    let rows = read_rows(&csv_path)?.unwrap_or_default();
    if rows.len() != part.rows {
        return Err(LabError::Invalid(format!(
            "{}: {} rows, and its part record says {}",
            csv_path.display(),
            rows.len(),
            part.rows
        )));
    }
    Ok((part, rows))
}

/// One trial at one radius, beside the identical trial all rigid.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The puck's radius of influence, metres.
    pub puck_radius_m: f32,
    /// The trial's number, from 0.
    pub trial: u32,
    /// The seed of the trial's initial conditions (`first_seed + trial`).
    pub seed: u64,
    /// Length of the trial, simulated seconds.
    pub seconds: f32,
    /// The level rules file the trial ran under (under the assets folder).
    pub rules: String,
    /// Creatures that collided with the puck or a wall under the influence policy (figure 10's measure).
    pub collided: u64,
    /// The same count in the identical trial all rigid.
    pub collided_all_rigid: u64,
    /// Creatures that fell under the influence policy.
    pub falls: u64,
    /// Creatures that fell in the identical trial all rigid.
    pub falls_all_rigid: u64,
    /// Creatures at the rigid level, averaged over the trial's steering decisions.
    pub mean_rigid: f64,
    /// Wall-clock seconds the trial took under the influence policy.
    pub wall_s: f64,
    /// Wall-clock seconds the identical trial took all rigid.
    pub wall_s_all_rigid: f64,
}

impl Row {
    /// Figure 10's y value for this trial: creatures collided under the influence policy less all rigid.
    pub fn difference(&self) -> i64 {
        self.collided as i64 - self.collided_all_rigid as i64
    }

    fn to_csv(&self) -> String {
        format!(
            "{},{},{},{},{},{},{},{},{},{},{:.3},{:.4},{:.4}",
            self.puck_radius_m,
            self.trial,
            self.seed,
            self.seconds,
            self.rules,
            self.collided,
            self.collided_all_rigid,
            self.difference(),
            self.falls,
            self.falls_all_rigid,
            self.mean_rigid,
            self.wall_s,
            self.wall_s_all_rigid
        )
    }

    fn parse(line: &str) -> Option<Row> {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != HEADER.split(',').count() {
            return None;
        }
        Some(Row {
            puck_radius_m: f[0].parse().ok()?,
            trial: f[1].parse().ok()?,
            seed: f[2].parse().ok()?,
            seconds: f[3].parse().ok()?,
            rules: f[4].to_owned(),
            collided: f[5].parse().ok()?,
            collided_all_rigid: f[6].parse().ok()?,
            falls: f[8].parse().ok()?,
            falls_all_rigid: f[9].parse().ok()?,
            mean_rigid: f[10].parse().ok()?,
            wall_s: f[11].parse().ok()?,
            wall_s_all_rigid: f[12].parse().ok()?,
        })
    }

    /// Same trial of the same plan (the wall times aside).
    fn key(&self) -> (u32, u64, u32, u32, String) {
        (
            self.puck_radius_m.to_bits(),
            self.seed,
            self.trial,
            self.seconds.to_bits(),
            self.rules.clone(),
        )
    }
}

/// The rows of a `fig10.csv` (or a partial one); `None` if the file does not exist.
pub fn read_rows(path: &Path) -> Result<Option<Vec<Row>>, LabError> {
    let Ok(text) = std::fs::read_to_string(path) else {
        return Ok(None);
    };
    rows_of(&text, path).map(Some)
}

/// The rows of a fig10 table's `text`, read from `path`.
fn rows_of(text: &str, path: &Path) -> Result<Vec<Row>, LabError> {
    let mut lines = text.lines();
    if lines.next() != Some(HEADER) {
        return Err(LabError::Invalid(format!(
            "{}: not a fig10 table (its first line is not `{HEADER}`)",
            path.display()
        )));
    }
    lines
        .enumerate()
        .filter(|(_, l)| !l.is_empty())
        .map(|(i, l)| {
            Row::parse(l)
                .ok_or_else(|| LabError::Invalid(format!("{}: line {}: not a fig10 row: {l}", path.display(), i + 2)))
        })
        .collect()
}

/// One trial: the all-rigid run, then the influence policy at every radius, same seed.
fn run_trial(config: &SimConfig, rules: &LevelRules, s: &Fig10Settings, trial: u32) -> Vec<Row> {
    let seed = s.first_seed + u64::from(trial);
    let seconds = f64::from(s.seconds);
    let mut c = config.clone();
    c.rules = rules.clone();
    c.scenario.seed = seed;
    c.scenario.level_policy = LevelPolicy::AllRigid;
    let rigid = headless::run(c.clone(), seconds);
    c.scenario.level_policy = LevelPolicy::Influence;
    s.radii_m
        .iter()
        .map(|&r| {
            c.rules.influence.puck_radius_m = r;
            let run = headless::run(c.clone(), seconds);
            Row {
                puck_radius_m: r,
                trial,
                seed,
                seconds: s.seconds,
                rules: s.rules.clone(),
                collided: run.creatures_collided,
                collided_all_rigid: rigid.creatures_collided,
                falls: run.falls,
                falls_all_rigid: rigid.falls,
                mean_rigid: run.levels_mean[Lod::Rigid],
                wall_s: run.wall_seconds,
                wall_s_all_rigid: rigid.wall_seconds,
            }
        })
        .collect()
}

/// Runs figure 10 from `file`: this shard's trials on `--jobs` threads, resuming an interrupted
/// run; writes its CSV, plot, JSON and report and returns what it says.
pub fn run(config: &SimConfig, file: &Path, options: &Options) -> Result<String, LabError> {
    let s: Fig10Settings = load_settings(file, options)?;
    let rules: LevelRules = load_file(&options.assets.join(&s.rules))
        .map_err(|e| LabError::Invalid(format!("{e} (named by {}: field `rules`)", file.display())))?;
    let s = Fig10Settings {
        trials: trials(options, s.trials),
        ..s
    };
    let out = &options.out;
    std::fs::create_dir_all(out).map_err(io_error("create", out))?;
    let (done_path, partial_path) = (out.join("fig10.csv"), out.join("fig10.partial.csv"));
    let plan = plan_digest(config, &rules, &s);
    // What an earlier run of the same plan finished, whole trials only; a part made by another
    // plan or another simlod is refused, never mixed in.
    let mut earlier = Vec::new();
    if done_path.exists() {
        let (part, rows) = read_part(out)?;
        same_plan(&part.plan, &part.version, &plan, &done_path)?;
        earlier = rows;
    }
    let journal_plan = out.join(JOURNAL_PLAN_FILE);
    if partial_path.exists() {
        let made_by = std::fs::read_to_string(&journal_plan).map_err(|e| {
            LabError::Invalid(format!(
                "{}: {e}: without it nothing says what made {}",
                journal_plan.display(),
                partial_path.display()
            ))
        })?;
        let (version, made_by) = made_by.trim().split_once(' ').unwrap_or(("", made_by.trim()));
        same_plan(made_by, version, &plan, &partial_path)?;
        earlier.extend(read_journal(&partial_path)?);
    }
    std::fs::write(&journal_plan, format!("{} {plan}\n", env!("CARGO_PKG_VERSION")))
        .map_err(io_error("write", &journal_plan))?;
    let mine: Vec<u32> = (0..s.trials).filter(|&t| options.shard.owns(t)).collect();
    let settings = &s;
    let wanted: BTreeSet<_> = mine
        .iter()
        .flat_map(|&t| {
            settings.radii_m.iter().map(move |r| {
                let seed = settings.first_seed + u64::from(t);
                (r.to_bits(), seed, t, settings.seconds.to_bits(), settings.rules.clone())
            })
        })
        .collect();
    let mut by_trial: BTreeMap<u32, Vec<Row>> = BTreeMap::new();
    let mut seen = BTreeSet::new();
    for row in earlier {
        if wanted.contains(&row.key()) && seen.insert(row.key()) {
            by_trial.entry(row.trial).or_default().push(row);
        }
    }
    by_trial.retain(|_, rows| rows.len() == s.radii_m.len());
    let todo: Vec<u32> = mine.iter().copied().filter(|t| !by_trial.contains_key(t)).collect();
    if todo.len() < mine.len() {
        eprintln!(
            "fig10: resuming: {} of {} trials already done in {}",
            mine.len() - todo.len(),
            mine.len(),
            out.display()
        );
    }
    // The journal: every finished trial's rows, appended as it finishes.
    let mut journal_text = format!("{HEADER}\n");
    for row in by_trial.values().flatten() {
        journal_text += &(row.to_csv() + "\n");
    }
    std::fs::write(&partial_path, journal_text).map_err(io_error("write", &partial_path))?;
    let mut journal = std::fs::OpenOptions::new()
        .append(true)
        .open(&partial_path)
        .map_err(io_error("open", &partial_path))?;
    let mut progress = super::Progress::new("fig10 trials", todo.len() as u64);
    let mut failed = None;
    run_parallel(
        &todo,
        options.jobs,
        |&t| run_trial(config, &rules, &s, t),
        |&t, rows| {
            let text: String = rows.iter().map(|r| r.to_csv() + "\n").collect();
            if let Err(e) = journal.write_all(text.as_bytes()).and_then(|()| journal.flush()) {
                failed = Some(io_error("write", &partial_path)(e));
            }
            by_trial.insert(t, rows);
            progress.inc();
        },
    );
    drop(progress);
    if let Some(e) = failed {
        return Err(e);
    }
    let rows: Vec<Row> = by_trial.into_values().flatten().collect();
    let part = PartOf {
        plan,
        trials: s.trials,
        shard: options.shard,
    };
    let text = finish(
        rows,
        out,
        &command("fig10", options),
        (&options.scenario, &options.assets),
        options.quick,
        &part,
    )?;
    let _ = std::fs::remove_file(&partial_path);
    let _ = std::fs::remove_file(&journal_plan);
    Ok(text)
}

/// Which part of which plan a finished run is.
struct PartOf {
    plan: String,
    trials: u32,
    shard: Shard,
}

/// Refuses `file`, made by plan `made_by` with simlod `version`, for a run of plan `plan`.
fn same_plan(made_by: &str, version: &str, plan: &str, file: &Path) -> Result<(), LabError> {
    let this = env!("CARGO_PKG_VERSION");
    if version != this {
        return Err(LabError::Invalid(format!(
            "{}: made by simlod {version}, and this is {this}: move it away or write to another --out",
            file.display()
        )));
    }
    if made_by != plan {
        return Err(LabError::Invalid(format!(
            "{}: made with other settings (plan {made_by}; this run's is {plan}: the scenario, its files, the rules, the radii, the trial length or the seeds differ): move it away or write to another --out",
            file.display()
        )));
    }
    Ok(())
}

/// The rows of an unfinished run's journal. Its last line, cut short by the interruption
/// (no line end), is a trial that did not finish: dropped, and the trial runs again.
fn read_journal(path: &Path) -> Result<Vec<Row>, LabError> {
    let text = std::fs::read_to_string(path).map_err(io_error("read", path))?;
    let whole = text.rfind('\n').map_or("", |end| &text[..=end]);
    if whole.len() < text.len() {
        eprintln!(
            "fig10: {}: its last line was cut short; that trial runs again",
            path.display()
        );
    }
    rows_of(whole, path)
}

/// `simlod experiment merge DIR... --out OUT`: the shards' rows as one run's.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<String, LabError> {
    let mut rows = Vec::new();
    let mut seen = BTreeSet::new();
    let mut first: Option<(&Path, Part, Shard)> = None;
    let mut shards = BTreeSet::new();
    for dir in dirs {
        let (part, part_rows) = read_part(dir)?;
        let shard: Shard = part
            .shard
            .parse()
            .map_err(|e| LabError::Invalid(format!("{}: field `shard`: {e}", dir.join(PART_FILE).display())))?;
        if let Some((first_dir, f, f_shard)) = &first {
            for (what, this, that) in [
                ("simlod version", &part.version, &f.version),
                (
                    "plan (the scenario, its files, the rules, the radii, the trial length or the seeds)",
                    &part.plan,
                    &f.plan,
                ),
                ("trial count", &part.trials.to_string(), &f.trials.to_string()),
                ("number of shards", &shard.n.to_string(), &f_shard.n.to_string()),
            ] {
                if this != that {
                    return Err(LabError::Invalid(format!(
                        "{}: its {what} is {this}, and {}'s is {that}: they are not parts of one run",
                        dir.display(),
                        first_dir.display()
                    )));
                }
            }
        }
        if !shards.insert(shard.k) {
            return Err(LabError::Invalid(format!(
                "{}: shard {} is given twice: the parts overlap",
                dir.display(),
                part.shard
            )));
        }
        for row in part_rows {
            if !seen.insert(row.key()) {
                return Err(LabError::Invalid(format!(
                    "{}: trial {} (seed {}) at {} m is also in another part: the parts overlap",
                    dir.join("fig10.csv").display(),
                    row.trial,
                    row.seed,
                    row.puck_radius_m
                )));
            }
            rows.push(row);
        }
        first.get_or_insert((dir.as_path(), part, shard));
    }
    let Some((first_dir, first, Shard { n, .. })) = first else {
        return Err(LabError::Invalid("name the folders of the parts to merge".to_owned()));
    };
    if let Some(k) = (1..=n).find(|k| !shards.contains(k)) {
        return Err(LabError::Invalid(format!(
            "shard {k}/{n} is missing: merged, the parts would not be one run's {} trials",
            first.trials
        )));
    }
    let record = std::fs::read_to_string(first_dir.join("fig10.json"))
        .ok()
        .and_then(|json| serde_json::from_str::<ExperimentRecord>(&json).ok());
    let text = |r: &ExperimentRecord, k: &str| r.summary[k].as_str().map(PathBuf::from);
    let (scenario, assets) = record
        .as_ref()
        .and_then(|r| text(r, "scenario").zip(text(r, "assets")))
        .unwrap_or_else(|| ("assets/scenarios/default.ron".into(), "assets".into()));
    // Shards of a smoke test merge into a smoke test.
    let smoke_test = record.is_some_and(|r| r.smoke_test);
    let dirs: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
    let command = format!("simlod experiment merge {} --out {}", dirs.join(" "), out.display());
    let part = PartOf {
        plan: first.plan,
        trials: first.trials,
        shard: Shard::WHOLE,
    };
    finish(rows, out, &command, (&scenario, &assets), smoke_test, &part)
}

/// Figures per radius.
#[derive(Clone, Debug, Serialize)]
struct RadiusSummary {
    puck_radius_m: f32,
    trials: usize,
    mean_difference: f64,
    variance_difference: f64,
    mean_collided: f64,
    mean_collided_all_rigid: f64,
    mean_falls: f64,
    mean_falls_all_rigid: f64,
    /// Falls under influence minus all rigid, trial by trial: mean and standard error.
    mean_falls_difference: f64,
    standard_error_falls_difference: f64,
    mean_rigid: f64,
    wall_s: f64,
    wall_s_all_rigid: f64,
    /// All-rigid wall time over this radius's.
    speedup: f64,
}

fn summarise(rows: &[Row]) -> Vec<RadiusSummary> {
    let mut radii: Vec<f32> = rows.iter().map(|r| r.puck_radius_m).collect();
    radii.sort_by(f32::total_cmp);
    radii.dedup();
    radii
        .into_iter()
        .map(|radius| {
            let at: Vec<&Row> = rows.iter().filter(|r| r.puck_radius_m == radius).collect();
            let n = at.len() as f64;
            let mean = |f: &dyn Fn(&Row) -> f64| at.iter().map(|r| f(r)).sum::<f64>() / n;
            let of = |f: &dyn Fn(&Row) -> f64| mean_and_variance(&at.iter().map(|r| f(r)).collect::<Vec<_>>());
            let (mean_difference, variance_difference) = of(&|r| r.difference() as f64);
            let (mean_falls_difference, variance_falls_difference) = of(&|r| r.falls as f64 - r.falls_all_rigid as f64);
            let wall_s = at.iter().map(|r| r.wall_s).sum::<f64>();
            let wall_s_all_rigid = at.iter().map(|r| r.wall_s_all_rigid).sum::<f64>();
            RadiusSummary {
                puck_radius_m: radius,
                trials: at.len(),
                mean_difference,
                variance_difference,
                mean_collided: mean(&|r| r.collided as f64),
                mean_collided_all_rigid: mean(&|r| r.collided_all_rigid as f64),
                mean_falls: mean(&|r| r.falls as f64),
                mean_falls_all_rigid: mean(&|r| r.falls_all_rigid as f64),
                mean_falls_difference,
                standard_error_falls_difference: (variance_falls_difference / n).sqrt(),
                mean_rigid: mean(&|r| r.mean_rigid),
                wall_s,
                wall_s_all_rigid,
                speedup: wall_s_all_rigid / wall_s,
            }
        })
        .collect()
}

/// Writes the table, the plots, the summary and the report from all the trials' rows.
/// The CSV, plot, JSON and report of the trials' rows; a `smoke_test` (`--quick`) says so and
/// draws no conclusion.
fn finish(
    mut rows: Vec<Row>,
    out: &Path,
    command: &str,
    (scenario, assets): (&Path, &Path),
    smoke_test: bool,
    part: &PartOf,
) -> Result<String, LabError> {
    std::fs::create_dir_all(out).map_err(io_error("create", out))?;
    rows.sort_by(|a, b| a.puck_radius_m.total_cmp(&b.puck_radius_m).then(a.trial.cmp(&b.trial)));
    let mut csv = format!("{HEADER}\n");
    for row in &rows {
        csv += &(row.to_csv() + "\n");
    }
    let record = Part {
        experiment: "fig10".to_owned(),
        version: env!("CARGO_PKG_VERSION").to_owned(),
        plan: part.plan.clone(),
        trials: part.trials,
        shard: format!("{}/{}", part.shard.k, part.shard.n),
        rows: rows.len(),
        checksum: digest(csv.as_bytes()),
    };
    let json = serde_json::to_string_pretty(&record).expect("a part record serialises");
    super::write_out(out, "fig10.csv", &csv)?;
    super::write_out(out, PART_FILE, &(json + "\n"))?;
    let per_radius = summarise(&rows);
    let difference: Vec<(f64, f64)> = per_radius
        .iter()
        .map(|p| (f64::from(p.puck_radius_m), p.mean_difference))
        .collect();
    // The claim is about the mean: its bars are standard errors (the trials' spread over the
    // square root of their count), not the trials' own spread.
    let standard_errors: Vec<f64> = per_radius
        .iter()
        .map(|p| (p.variance_difference / p.trials.max(1) as f64).sqrt())
        .collect();
    let mut with_bars = Series::new(
        "influence minus all rigid (mean, bars: 1 standard error)",
        difference.clone(),
        Mark::Line,
        0,
    );
    with_bars.errors = Some(standard_errors.clone());
    let zero = Series::new(
        "no change",
        difference.iter().map(|&(x, _)| (x, 0.0)).collect(),
        Mark::Dashed,
        plot::REFERENCE,
    );
    let trade: Vec<(f64, f64)> = per_radius.iter().map(|p| (p.mean_difference, p.speedup)).collect();
    let n_trials = per_radius.iter().map(|p| p.trials).max().unwrap_or(0);
    let seconds = rows.first().map_or(0.0, |r| r.seconds);
    plot::draw(
        &out.join("fig10.png"),
        1400,
        600,
        &[
            Panel {
                title: format!(
                    "Figure 10: change in creatures that hit the puck or a wall ({n_trials} trials of {seconds} s)"
                ),
                x_label: "the puck's radius of influence (m)".into(),
                y_label: "change in creatures collided".into(),
                series: vec![with_bars, zero],
                ..Panel::default()
            },
            Panel {
                title: "the trade-off: speed against outcome".into(),
                x_label: "change in creatures collided (mean)".into(),
                y_label: "speed-up over all rigid (wall time)".into(),
                series: vec![Series {
                    x_errors: Some(standard_errors),
                    ..Series::new(
                        "one point per radius (bars: 1 standard error)",
                        trade.clone(),
                        Mark::Line,
                        1,
                    )
                }],
                notes: per_radius
                    .iter()
                    .map(|p| (p.mean_difference, p.speedup, format!("  {} m", p.puck_radius_m)))
                    .collect(),
                ..Panel::default()
            },
        ],
        smoke_test,
    )?;
    let mut report = format!(
        "For each puck radius, {n_trials} trials of {seconds} s, each from its own seed, under the influence policy (rules `{}`), \
         each beside the identical trial all rigid; the measure is the paper's, the creatures that collided with the puck or a wall. \
         The difference is influence minus all rigid. Trials ran in parallel, each simulation on one thread; wall times are per trial.\n\n\
         | radius (m) | trials | difference: mean | variance | collided | collided all rigid | falls | falls all rigid | falls: difference +- s.e. | rigid creatures (mean) | speed-up |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
        rows.first().map_or("", |r| r.rules.as_str())
    );
    for p in &per_radius {
        let _ = writeln!(
            report,
            "| {} | {} | {:+.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:+.2} +- {:.2} | {:.1} | {:.2} |",
            p.puck_radius_m,
            p.trials,
            p.mean_difference,
            p.variance_difference,
            p.mean_collided,
            p.mean_collided_all_rigid,
            p.mean_falls,
            p.mean_falls_all_rigid,
            p.mean_falls_difference,
            p.standard_error_falls_difference,
            p.mean_rigid,
            p.speedup
        );
    }
    // Switching must not add falls. Beyond noise: more than two standard errors of
    // the trial-by-trial difference.
    let more_falls: Vec<String> = per_radius
        .iter()
        .filter(|p| p.mean_falls_difference > 2.0 * p.standard_error_falls_difference)
        .map(|p| format!("{} m", p.puck_radius_m))
        .collect();
    if !smoke_test {
        let _ = write!(
            report,
            "\nFalls under influence beyond all rigid's by more than two standard errors of the trial-by-trial difference: {}.\n",
            if more_falls.is_empty() {
                "at no radius".to_string()
            } else {
                more_falls.join(", ")
            }
        );
    }
    let _ = write!(
        report,
        "\nThe paper finds the difference flat from 15 to 8 m and falling below 8 m (the hybrid, more agile, collides less). \
         Any row reruns alone: `simlod run --scenario {sc} --rules {rules} --seed SEED --policy influence --puck-radius R --seconds {seconds} --json` \
         prints `creatures_collided` (the row's `collided`) and `falls`; the same with `--policy all-rigid` the all-rigid ones.\n",
        sc = scenario.display(),
        rules = assets.join(rows.first().map_or("", |r| r.rules.as_str())).display(),
    );
    ExperimentRecord {
        experiment: "fig10".into(),
        command: command.to_owned(),
        summary: serde_json::json!({
            "per_radius": per_radius,
            "scenario": scenario.display().to_string(),
            "assets": assets.display().to_string(),
        }),
        report,
        smoke_test,
    }
    .save(out, &["fig10.csv", PART_FILE, "fig10.png"])
}
