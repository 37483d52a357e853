//! The `record-gait` command: a kind's gait table recorded from its rigid model (paper 3.2).

use crate::Failure;
use clap::Args;
use std::path::{Path, PathBuf};

use crate::scenario::*;
use simlod::config::{CreatureDef, CreatureGroup, MeasuredAnew, Validate, Validator, load_file};
use simlod::gait::GaitTable;
use simlod_lab::record::{RecordSettings, record, to_file_text};

#[derive(Args)]
pub(crate) struct RecordGaitArgs {
    #[command(flatten)]
    pub(crate) scenario: ScenarioArgs,
    /// The creature file; it must have a `rigid` section.
    #[arg(long)]
    pub(crate) creature: PathBuf,
    /// Steady forward speeds to record, increasing (default: each whole m/s below the kind's
    /// top speed, and the top speed).
    #[arg(long, value_delimiter = ',')]
    pub(crate) speeds: Option<Vec<f32>>,
    /// Where to write the table (default: the creature's `gait_table`, or gaits/<kind>.ron
    /// under the assets folder).
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Write the table even where a table of another kind is: that kind loses its table.
    #[arg(long)]
    pub(crate) replace_other_kind: bool,
}

impl RecordGaitArgs {
    pub(crate) fn run(&self) -> Result<(), Failure> {
        self.scenario
            .refuse_level_flags("record-gait", "it runs the kind's rigid model alone, at steady speeds")?;
        let def: CreatureDef = load_file(&self.creature).map_err(|e| e.to_string())?;
        let mut config = self.scenario.load_measuring(MeasuredAnew {
            gait_table_of: Some(&def.name),
            ..MeasuredAnew::default()
        })?;
        if def.rigid.is_none() {
            return Err(Failure::from(format!(
                "{}: the creature has no `rigid` section to record from",
                self.creature.display()
            )));
        }
        let defaults = RecordSettings::up_to(def.top_speed_m_per_s);
        let speeds = self.speeds.clone().unwrap_or_else(|| defaults.speeds_m_per_s.clone());
        if speeds.is_empty()
            || speeds.windows(2).any(|w| w[0] >= w[1])
            || speeds.iter().any(|v| !(0.0..=10.0).contains(v))
        {
            return Err(Failure::from(format!(
                "--speeds must be increasing speeds between 0 and 10 m/s, got {speeds:?}"
            )));
        }
        // The recording never depends on a table recorded before.
        let index = config.kind_index(&def.name).unwrap_or_else(|| {
            config.kinds.push(def.clone());
            config.gaits.push(None);
            config.kinds.len() - 1
        });
        config.kinds[index] = def.clone();
        config.gaits[index] = None;
        config.scenario.creatures = vec![CreatureGroup {
            kind: def.name.clone(),
            count: 1,
        }];
        let settings = RecordSettings {
            speeds_m_per_s: speeds.clone(),
            ..defaults
        };
        let out = self.out.clone().unwrap_or_else(|| {
            self.scenario.assets.join(
                def.gait_table
                    .clone()
                    .unwrap_or_else(|| format!("gaits/{}.ron", def.name)),
            )
        });
        // Another kind's table is never overwritten by accident (a copied creature file
        // that kept its original's `gait_table` line names the original's table).
        if !self.replace_other_kind
            && let Ok(old) = load_file::<GaitTable>(&out)
            && old.creature != def.name
        {
            return Err(Failure::from(format!(
                "{path} holds the gait table of `{other}`, not of `{kind}`: recording `{kind}` there would \
                 take `{other}`'s table away. Give `{kind}` its own `gait_table` (or --out FILE), or pass \
                 --replace-other-kind",
                path = out.display(),
                other = old.creature,
                kind = def.name,
            )));
        }
        let table = record(&config, &def.name, &settings)?;
        let speeds: Vec<String> = speeds.iter().map(f32::to_string).collect();
        // The files are found again from the command alone: the assets folder where it is not
        // the default, and the scenario where one was given.
        let mut command = format!(
            "simlod record-gait --creature {} --speeds {}",
            self.creature.display(),
            speeds.join(",")
        );
        if self.scenario.assets != Path::new("assets") || self.scenario.scenario.is_some() {
            command += &format!(" {}", self.scenario.file_flags());
        }
        // A table the loader would refuse is not written: the old one stays.
        let mut check = Validator::default();
        table.validate(&mut check);
        check
            .finish(&out)
            .map_err(|e| format!("the recording is not a usable gait table, so it was not written:\n{e}"))?;
        if let Some(dir) = out.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        }
        std::fs::write(&out, to_file_text(&table, &command))
            .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
        println!("recorded {} from its rigid model into {}", def.name, out.display());
        for row in &table.rows {
            println!(
                "  {:.3} m/s: hop {:.3} s, stance {:.0} %, {} samples",
                row.speed_m_per_s,
                row.hop_period_s,
                row.stance_fraction * 100.0,
                row.samples.len()
            );
        }
        println!(
            "  effective limits for the point mass: top speed {:.3} m/s, acceleration {:.3} m/s^2",
            table.top_speed_m_per_s, table.acceleration_limit_m_per_s2
        );
        Ok(())
    }
}
