//! Range checks for asset files, reported as "file: field: what is wrong".

use std::fmt;
use std::path::{Path, PathBuf};

/// One thing wrong with one field of one file.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// Dotted path of the field, e.g. `puck.mass_kg`; empty when the whole file is at fault.
    pub field: String,
    /// What is wrong with it.
    pub message: String,
}

/// A file that could not be used, and every problem found in it. Never a panic.
#[derive(Clone, Debug, PartialEq)]
pub struct ConfigError {
    /// The file.
    pub file: PathBuf,
    /// What is wrong with it, field by field.
    pub problems: Vec<Problem>,
}

impl ConfigError {
    /// An error of one problem with one field.
    pub fn one(file: &Path, field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            file: file.to_path_buf(),
            problems: vec![Problem {
                field: field.into(),
                message: message.into(),
            }],
        }
    }
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, p) in self.problems.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{}: ", self.file.display())?;
            if !p.field.is_empty() {
                write!(f, "field `{}`: ", p.field)?;
            }
            write!(f, "{}", p.message)?;
        }
        Ok(())
    }
}

impl std::error::Error for ConfigError {}

/// Collects the problems of one file while its fields are checked.
#[derive(Default)]
pub struct Validator {
    prefix: Vec<String>,
    problems: Vec<Problem>,
}

impl Validator {
    /// The file's error if any check failed.
    pub fn finish(self, file: &Path) -> Result<(), ConfigError> {
        if self.problems.is_empty() {
            Ok(())
        } else {
            Err(ConfigError {
                file: file.to_path_buf(),
                problems: self.problems,
            })
        }
    }

    /// Checks the fields of a nested struct under `name`.
    pub fn nested(&mut self, name: &str, check: impl FnOnce(&mut Self)) {
        self.prefix.push(name.to_owned());
        check(self);
        self.prefix.pop();
    }

    /// Records that `field` (under the nested struct being checked) is wrong.
    pub fn fail(&mut self, field: &str, message: impl Into<String>) {
        let mut path = self.prefix.join(".");
        if !field.is_empty() {
            if !path.is_empty() {
                path.push('.');
            }
            path.push_str(field);
        }
        self.problems.push(Problem {
            field: path,
            message: message.into(),
        });
    }

    /// A finite number strictly above zero.
    pub fn positive(&mut self, field: &str, value: f32) {
        if !value.is_finite() {
            self.fail(field, format!("must be a finite number, got {value}"));
        } else if value <= 0.0 {
            self.fail(field, format!("must be greater than 0, got {value}"));
        }
    }

    /// A finite number at zero or above.
    pub fn non_negative(&mut self, field: &str, value: f32) {
        if !value.is_finite() {
            self.fail(field, format!("must be a finite number, got {value}"));
        } else if value < 0.0 {
            self.fail(field, format!("must not be negative, got {value}"));
        }
    }

    /// A finite number within `[min, max]`.
    pub fn within(&mut self, field: &str, value: f32, min: f32, max: f32) {
        if !value.is_finite() {
            self.fail(field, format!("must be a finite number, got {value}"));
        } else if !(min..=max).contains(&value) {
            self.fail(field, format!("must be between {min} and {max}, got {value}"));
        }
    }

    /// A finite number within `[lo, hi]`, a range that makes physical sense for the game;
    /// the message gives the unit, read from the field's name (`_m`, `_kg`, `_m_per_s`, ...).
    pub fn range(&mut self, field: &str, value: f32, lo: f32, hi: f32) {
        let unit = unit_of(field);
        if !value.is_finite() {
            self.fail(field, format!("must be a finite number{unit}, got {value}"));
        } else if !(lo..=hi).contains(&value) {
            let (lo, hi, value) = (number(lo), number(hi), number(value));
            self.fail(field, format!("must be between {lo} and {hi}{unit}, got {value}"));
        }
    }

    /// A file named by another, relative to the assets folder: it must stay inside it, so a
    /// scenario shared by someone else cannot make the program read any file of the user's.
    pub fn asset_path(&mut self, field: &str, path: &str) {
        if let Err(why) = inside_assets(path) {
            self.fail(field, format!("{why}, got {path:?}"));
        }
    }

    /// A creature kind's name: it names the file `creatures/<name>.ron`, so it is a plain name.
    pub fn kind_name(&mut self, field: &str, name: &str) {
        self.require(
            !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-'),
            field,
            format!("must be a non-empty name of letters, digits, '-' or '_', got {name:?}"),
        );
    }

    /// A condition that spans fields, with the message to give when it does not hold.
    pub fn require(&mut self, ok: bool, field: &str, message: impl Into<String>) {
        if !ok {
            self.fail(field, message);
        }
    }
}

/// A number as a reader wants it: 1e30, not thirty-one digits.
pub fn number(x: f32) -> String {
    if x != 0.0 && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

/// " m", " kg", ... for a field named with its unit, else nothing.
fn unit_of(field: &str) -> &'static str {
    // Longest suffixes first: `_m_per_s2` before `_m_per_s` before `_s`.
    const UNITS: [(&str, &str); 20] = [
        ("_cd_per_m2", " cd/m^2"),
        ("_nm_s_per_rad", " N m s/rad"),
        ("_nm_per_rad", " N m/rad"),
        ("_n_s_per_m", " N s/m"),
        ("_n_per_m", " N/m"),
        ("_m_per_s2", " m/s^2"),
        ("_m_per_s", " m/s"),
        ("_deg_per_s", " degrees/s"),
        ("_rad_per_s", " rad/s"),
        ("_per_s", " per second"),
        ("_nm", " N m"),
        ("_lux", " lux"),
        ("_px", " px"),
        ("_kg", " kg"),
        ("_hz", " Hz"),
        ("_deg", " degrees"),
        ("_rad", " rad"),
        ("_ms", " ms"),
        ("_m", " m"),
        ("_s", " s"),
    ];
    let name = field.rsplit('.').next().unwrap_or(field);
    UNITS
        .iter()
        .find(|(suffix, _)| name.ends_with(suffix))
        .map_or("", |(_, unit)| unit)
}

/// Why `path` (relative to the assets folder) could lead out of it, if it could. Checked on
/// the text, so that the game's asset server and the headless loader refuse the same paths;
/// a symbolic link out of the folder is caught where the file is opened.
pub fn inside_assets(path: &str) -> Result<(), &'static str> {
    use std::path::Component;
    if path.is_empty() {
        return Err("must name a file under the assets folder");
    }
    if path.contains('\\') || path.contains(':') || path.starts_with('/') {
        return Err("must be a path relative to the assets folder, with '/' between folders");
    }
    if !std::path::Path::new(path)
        .components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err("must stay inside the assets folder (no '..')");
    }
    if !path.ends_with(".ron") {
        return Err("must name a .ron file");
    }
    Ok(())
}

/// Range checks of a deserialized asset file.
pub trait Validate {
    /// Records every problem with `self` in `v`, each under its field's path.
    fn validate(&self, v: &mut Validator);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problems(check: impl FnOnce(&mut Validator)) -> Vec<Problem> {
        let mut v = Validator::default();
        check(&mut v);
        v.problems
    }

    #[test]
    fn a_range_names_the_field_its_bounds_and_the_unit_from_the_field_name() {
        let p = problems(|v| v.nested("puck", |v| v.range("speed_m_per_s", 1e30, 0.01, 50.0)));
        assert_eq!(p[0].field, "puck.speed_m_per_s");
        assert_eq!(p[0].message, "must be between 0.01 and 50 m/s, got 1e30");
        let p = problems(|v| v.range("acceleration_limit_m_per_s2", -1.0, 0.01, 1000.0));
        assert!(p[0].message.contains("1000 m/s^2, got -1"), "{p:?}");
        let p = problems(|v| v.range("wall_thickness_m", f32::NAN, 0.01, 100.0));
        assert!(p[0].message.contains("finite number m, got NaN"), "{p:?}");
        assert!(problems(|v| v.range("hop_period_s", 0.5, 0.05, 10.0)).is_empty());
        assert!(
            problems(|v| v.range("flight_window.0", 2.0, 0.0, 1.0))[0]
                .message
                .ends_with("1, got 2")
        );
    }

    #[test]
    fn a_path_that_could_leave_the_assets_folder_is_refused() {
        for bad in [
            "",
            "../x.ron",
            "gaits/../../x.ron",
            "/etc/passwd.ron",
            "C:/x.ron",
            "gaits\\x.ron",
            "gaits/",
            "gaits/x",
        ] {
            assert!(inside_assets(bad).is_err(), "{bad:?} should be refused");
        }
        for good in ["arena.ron", "gaits/hopper.ron", "./rules/levels.ron"] {
            assert_eq!(inside_assets(good), Ok(()), "{good:?}");
        }
    }
}
