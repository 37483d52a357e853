//! Range checks for asset files, reported as "file: field: what is wrong".

use std::fmt;
use std::path::{Path, PathBuf};

/// One thing wrong with one field of one file.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// Dotted path of the field, e.g. `puck.mass_kg`; empty when the whole file is at fault.
    pub field: String,
    pub message: String,
}

/// A file that could not be used, and every problem found in it. Never a panic.
#[derive(Clone, Debug, PartialEq)]
pub struct ConfigError {
    pub file: PathBuf,
    pub problems: Vec<Problem>,
}

impl ConfigError {
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

    /// A condition that spans fields, with the message to give when it does not hold.
    pub fn require(&mut self, ok: bool, field: &str, message: impl Into<String>) {
        if !ok {
            self.fail(field, message);
        }
    }
}

/// Range checks of a deserialized asset file.
pub trait Validate {
    fn validate(&self, v: &mut Validator);
}
