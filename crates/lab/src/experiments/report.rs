//! `report.md`: every experiment run into a folder, in the paper's order, each with its plot,
//! what the paper reports, what we measured and how they compare (from each `<name>.json`).

use crate::error::LabError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::{ExperimentRecord, write_out};

/// The experiments in the order the report shows them.
pub const ORDER: [&str; 9] = [
    "step-response",
    "table1",
    "fig7",
    "fig8",
    "fig9",
    "fig10",
    "budget",
    "crowd",
    "budget-scale",
];

/// Rewrites `report.md` in `out` from the experiments whose JSON is there.
pub fn write(out: &Path) -> Result<PathBuf, LabError> {
    let mut text = String::from(
        "# simlod: the paper's results, reproduced\n\n\
         Carlson & Hodgins, *Simulation Levels of Detail for Real-time Animation* (GI '97), section 4. \
         Each section below was written by the command it names; timing experiments take one \
         measurement at a time in one process, and their figures move with whatever else the machine runs.\n",
    );
    for name in ORDER {
        let path = out.join(format!("{name}.json"));
        let Ok(json) = std::fs::read_to_string(&path) else {
            continue;
        };
        let record: ExperimentRecord = serde_json::from_str(&json)
            .map_err(|e| LabError::Invalid(format!("{}: not an experiment record: {e}", path.display())))?;
        let smoke_test = if record.smoke_test {
            "**Smoke test** (`--quick`): small counts and short games that check the pipeline runs. \
             Its numbers are not findings, and no sentence below is a conclusion.\n\n"
        } else {
            ""
        };
        let _ = write!(
            text,
            "\n## {name}{}\n\n{smoke_test}![{name}]({name}.png)\n\n`{}`\n\n{}\n",
            if record.smoke_test { " (smoke test)" } else { "" },
            record.command,
            record.report.trim_end()
        );
    }
    write_out(out, "report.md", &text)
}
