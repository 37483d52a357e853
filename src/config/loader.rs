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
    let value: T = parse_text(text).map_err(|(path, e)| parse_error(file, &path, e))?;
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

fn parse_error(file: &Path, path: &str, e: ron::error::SpannedError) -> ConfigError {
    use ron::Error;
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
