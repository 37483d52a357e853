//! One parse-and-validate path for both the asset server and plain files.

use super::{ConfigError, Validate, Validator};
use bevy::asset::{Asset, AssetLoader, LoadContext, io::Reader};
use bevy::reflect::TypePath;
use serde::de::DeserializeOwned;
use std::marker::PhantomData;
use std::path::Path;

/// Parses RON bytes into `T` and validates it; every error names `file`.
pub fn parse_ron<T: DeserializeOwned + Validate>(bytes: &[u8], file: &Path) -> Result<T, ConfigError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        ConfigError::one(
            file,
            "",
            format!("not a RON text file: invalid UTF-8 at byte {}", e.valid_up_to()),
        )
    })?;
    // Some editors start a UTF-8 file with a byte-order mark; it says nothing, so skip it.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if text.trim().is_empty() {
        return Err(ConfigError::one(file, "", "the file is empty"));
    }
    let value: T = parse_text(text).map_err(|(path, e)| parse_error(file, text, &path, e))?;
    let mut v = Validator::default();
    value.validate(&mut v);
    v.finish(file)?;
    Ok(value)
}

/// Reads and parses one asset file by path (the headless CLI and the tests).
pub fn load_file<T: DeserializeOwned + Validate>(file: &Path) -> Result<T, ConfigError> {
    let bytes = std::fs::read(file).map_err(|e| ConfigError::one(file, "", format!("cannot read the file: {e}")))?;
    parse_ron(&bytes, file)
}

/// Deserializes `text`, keeping the path of the field being read when it failed.
fn parse_text<T: DeserializeOwned>(text: &str) -> Result<T, (String, ron::error::SpannedError)> {
    let mut de = ron::Deserializer::from_str(text).map_err(|e| (String::new(), e))?;
    let value = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        (path, de.span_error(e.into_inner()))
    })?;
    de.end().map_err(|e| (String::new(), de.span_error(e)))?;
    Ok(value)
}

/// The dotted path of the field a parse error is about: where the parser was (`path`, "."
/// at the top), and the field the error names, if it is not that place itself.
fn field_path(path: &str, named: Option<&str>) -> String {
    let mut parts: Vec<&str> = path.split('.').filter(|p| !p.is_empty() && *p != "?").collect();
    if let Some(name) = named
        && parts.last() != Some(&name)
    {
        parts.push(name);
    }
    parts.join(".")
}

fn parse_error(file: &Path, text: &str, path: &str, e: ron::error::SpannedError) -> ConfigError {
    use ron::Error;
    if let Some((field, message)) = wrong_type(text, path, &e) {
        return ConfigError::one(file, field, message);
    }
    let named = match &e.code {
        Error::MissingStructField { field, .. } | Error::DuplicateStructField { field, .. } => Some(*field),
        Error::NoSuchStructField { found, .. } => Some(found.as_str()),
        _ => None,
    };
    let field = field_path(path, named);
    let message = match &e.code {
        Error::MissingStructField { .. } => "is missing".to_owned(),
        Error::NoSuchStructField { expected, .. } => {
            format!(
                "is not a known field (line {}); expected one of: {}",
                e.position.line,
                expected.join(", ")
            )
        }
        code => format!("line {}, column {}: {code}", e.position.line, e.position.col),
    };
    ConfigError::one(file, field, message)
}

/// A value of the wrong type, named by its field with what was expected and what was found.
/// The parser's own words name only the token it wanted next: after the `10` of `count: 10.5`
/// it wants a comma.
fn wrong_type(text: &str, path: &str, e: &ron::error::SpannedError) -> Option<(String, String)> {
    use ron::Error;
    let at = byte_offset(text, e.position.line, e.position.col)?;
    let line = e.position.line;
    let expected = match &e.code {
        Error::ExpectedInteger => "a whole number",
        Error::ExpectedFloat => "a number",
        Error::ExpectedBoolean => "true or false",
        Error::ExpectedString => "text in double quotes",
        Error::ExpectedComma | Error::ExpectedStructLikeEnd | Error::ExpectedArrayEnd | Error::TrailingCharacters => {
            // A fraction where a whole number was read: the parser stopped at its `.`.
            let before = &text[..at];
            let digits = before.trim_end_matches(|c: char| c.is_ascii_digit());
            if !text[at..].starts_with('.') || digits.len() == before.len() {
                return None;
            }
            let number_start = digits.trim_end_matches(['-', '+']).len();
            let key = digits[..number_start].trim_end().strip_suffix(':')?.trim_end();
            let key_start = key
                .trim_end_matches(|c: char| c.is_ascii_alphanumeric() || c == '_')
                .len();
            let key = &key[key_start..];
            let found = value_at(text, number_start);
            let field = field_path(path, (!key.is_empty()).then_some(key));
            return Some((field, format!("expected a whole number, found {found} (line {line})")));
        }
        _ => return None,
    };
    let found = value_at(text, at);
    Some((
        field_path(path, None),
        format!("expected {expected}, found {found} (line {line})"),
    ))
}

/// The byte where a parser position (1-based line, 1-based column in characters) is.
fn byte_offset(text: &str, line: usize, col: usize) -> Option<usize> {
    let start: usize = text
        .split_inclusive('\n')
        .take(line.checked_sub(1)?)
        .map(str::len)
        .sum();
    let line_text = text.get(start..)?.split('\n').next()?;
    let within = line_text
        .char_indices()
        .nth(col.checked_sub(1)?)
        .map_or(line_text.len(), |(i, _)| i);
    Some(start + within)
}

/// The value written at `at`: up to the next delimiter or the end of its line.
fn value_at(text: &str, at: usize) -> &str {
    let rest = &text[at..];
    let end = rest.find([',', ')', ']', '}', '\n']).unwrap_or(rest.len());
    let found = rest[..end].trim();
    if found.is_empty() { "nothing" } else { found }
}

/// Bevy asset loader for any validated RON asset type: the game's hot-reload path.
#[derive(TypePath)]
pub struct RonAssetLoader<T> {
    _asset: PhantomData<fn() -> T>,
}

impl<T> Default for RonAssetLoader<T> {
    fn default() -> Self {
        Self { _asset: PhantomData }
    }
}

impl<T: Asset + DeserializeOwned + Validate> AssetLoader for RonAssetLoader<T> {
    type Asset = T;
    type Settings = ();
    type Error = ConfigError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<T, ConfigError> {
        let file = load_context.path().path().to_path_buf();
        let mut bytes = Vec::new();
        reader
            .read_to_end(&mut bytes)
            .await
            .map_err(|e| ConfigError::one(&file, "", format!("cannot read the file: {e}")))?;
        parse_ron(&bytes, &file)
    }

    fn extensions(&self) -> &[&str] {
        &["ron"]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::ArenaConfig;

    #[test]
    fn a_byte_order_mark_is_skipped_and_alone_is_an_empty_file() {
        let file = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/arena.ron"));
        let text = std::fs::read(file).unwrap();
        let marked = [&[0xef, 0xbb, 0xbf][..], &text].concat();
        assert_eq!(
            parse_ron::<ArenaConfig>(&marked, file).unwrap(),
            parse_ron::<ArenaConfig>(&text, file).unwrap()
        );
        let err = parse_ron::<ArenaConfig>(&[0xef, 0xbb, 0xbf, b'\n'], file).unwrap_err();
        assert!(err.to_string().contains("empty"), "{err}");
    }
}
