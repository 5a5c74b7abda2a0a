//! Mapping files: the user's word on which source joint plays which
//! canonical landmark, over whatever the names and structure found.

use super::{Landmark, MappingError};
use std::path::Path;

/// A mapping file: landmark name → source joint name, or `{ end_of = "J" }`
/// for the End Site of joint J.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UserMapping {
    pub path: String,
    pub(super) entries: Vec<(Landmark, String, bool)>,
}

impl UserMapping {
    pub fn load(path: &Path) -> Result<UserMapping, MappingError> {
        let display = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|source| MappingError::Io { path: display.clone(), source })?;
        UserMapping::parse(&text, &display)
    }

    pub fn parse(text: &str, path: &str) -> Result<UserMapping, MappingError> {
        let table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| MappingError::Toml { path: path.into(), message: e.to_string() })?;
        let mut entries = Vec::new();
        for (key, value) in table {
            let landmark = Landmark::from_name(&key).ok_or_else(|| MappingError::UnknownLandmark {
                path: path.into(),
                key: key.clone(),
                valid: Landmark::all().map(Landmark::name).collect::<Vec<_>>().join(", "),
            })?;
            let (joint, end_site) = match &value {
                toml::Value::String(s) => (s.clone(), false),
                toml::Value::Table(t) if t.len() == 1 => match t.get("end_of") {
                    Some(toml::Value::String(s)) => (s.clone(), true),
                    _ => return Err(MappingError::BadValue { path: path.into(), key }),
                },
                _ => return Err(MappingError::BadValue { path: path.into(), key }),
            };
            entries.push((landmark, joint, end_site));
        }
        Ok(UserMapping { path: path.into(), entries })
    }
}
