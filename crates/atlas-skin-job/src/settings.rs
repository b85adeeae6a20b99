//! The method's settings for one job: a settings file ([`SkinParams`] as JSON, any subset,
//! and the quality gate's `fail_on`), then the options given beside it, which override it.

use crate::quality::Condition;
use atlas_skin::pipeline::SkinParams;
use atlas_skin::weights::blend::Blend;
use atlas_skin::weights::rigid::Binding;
use atlas_skin_io::gltf::MAX_INFLUENCES;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// What is wrong with a settings file or an option.
#[derive(Debug, Error)]
pub enum SettingsError {
    #[error("cannot read {}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{} is not a valid settings file", path.display())]
    Parse {
        path: PathBuf,
        #[source]
        source: serde_json::Error,
    },
    #[error("{}: max_influences {value} is outside 1..={MAX_INFLUENCES}", path.display())]
    FileMaxInfluences { path: PathBuf, value: usize },
    #[error("max_influences {value} is outside 1..={MAX_INFLUENCES}")]
    MaxInfluences { value: usize },
    #[error("{}: fail_on must be a list of the quality gate's conditions", path.display())]
    FailOn {
        path: PathBuf,
        #[source]
        source: serde_json::Error,
    },
}

/// The key of the quality gate's conditions in a settings file.
const FAIL_ON_KEY: &str = "fail_on";

/// A settings file as read: the method's parameters and the gate's `fail_on`, as JSON.
struct SettingsFile<'a> {
    path: &'a Path,
    params: serde_json::Value,
    fail_on: Option<serde_json::Value>,
}

/// The settings of a job: each field left empty keeps the settings file's value, or the
/// method's default.
#[derive(Debug, Clone, Default)]
pub struct Settings {
    /// A settings file: [`SkinParams`] as JSON (any subset of `decompose`, `overlap`
    /// {`factor`, `per_joint`}, `blend`, `binding`, `loose_pieces`, `max_influences`), and
    /// `fail_on` (the quality gate's conditions, [`Condition`] names).
    pub config: Option<PathBuf>,
    /// Overlap half-width as a multiple of each boundary's diameter.
    pub overlap: Option<f64>,
    /// Overlap factor of single joints, by name.
    pub overlap_joints: Vec<(String, f64)>,
    /// How overlapping regions are blended.
    pub blend: Option<Blend>,
    /// Blended weights or one joint per vertex.
    pub binding: Option<Binding>,
    /// Joints given a boundary even where the rules would not.
    pub force: Vec<String>,
    /// Joints given no boundary.
    pub forbid: Vec<String>,
    /// Influences kept per vertex, `1..=`[`MAX_INFLUENCES`].
    pub max_influences: Option<usize>,
    /// The quality gate's conditions; empty keeps the settings file's (or none).
    pub fail_on: Vec<Condition>,
}

impl Settings {
    /// The files these settings read (the settings file).
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.config.as_deref().into_iter()
    }

    /// The settings file, read and parsed as JSON, its `fail_on` taken apart.
    fn file(&self) -> Result<Option<SettingsFile<'_>>, SettingsError> {
        let Some(path) = &self.config else {
            return Ok(None);
        };
        let text = std::fs::read_to_string(path).map_err(|source| SettingsError::Read {
            path: path.clone(),
            source,
        })?;
        let mut params: serde_json::Value =
            serde_json::from_str(&text).map_err(|source| SettingsError::Parse {
                path: path.clone(),
                source,
            })?;
        let fail_on = params
            .as_object_mut()
            .and_then(|object| object.remove(FAIL_ON_KEY));
        Ok(Some(SettingsFile {
            path,
            params,
            fail_on,
        }))
    }

    /// The quality gate's conditions: the options' when given, else the settings file's
    /// `fail_on`, else none.
    pub fn fail_on(&self) -> Result<Vec<Condition>, SettingsError> {
        if !self.fail_on.is_empty() {
            return Ok(self.fail_on.clone());
        }
        let Some(SettingsFile {
            path,
            fail_on: Some(list),
            ..
        }) = self.file()?
        else {
            return Ok(Vec::new());
        };
        serde_json::from_value(list).map_err(|source| SettingsError::FailOn {
            path: path.to_path_buf(),
            source,
        })
    }

    /// The method's parameters: the settings file's (or the defaults), then the options.
    pub fn params(&self) -> Result<SkinParams, SettingsError> {
        let mut params: SkinParams = match self.file()? {
            Some(file) => {
                serde_json::from_value(file.params).map_err(|source| SettingsError::Parse {
                    path: file.path.to_path_buf(),
                    source,
                })?
            }
            None => SkinParams::default(),
        };
        if let Some(factor) = self.overlap {
            params.overlap.factor = factor;
        }
        for (name, factor) in &self.overlap_joints {
            params.overlap.per_joint.insert(name.clone(), *factor);
        }
        if let Some(blend) = self.blend {
            params.blend = blend;
        }
        if let Some(binding) = self.binding {
            params.binding = binding;
        }
        if let Some(n) = self.max_influences {
            params.max_influences = n;
        }
        if !(1..=MAX_INFLUENCES).contains(&params.max_influences) {
            let value = params.max_influences;
            return Err(match (&self.config, self.max_influences) {
                (Some(path), None) => SettingsError::FileMaxInfluences {
                    path: path.clone(),
                    value,
                },
                _ => SettingsError::MaxInfluences { value },
            });
        }
        params.decompose.force.extend(self.force.iter().cloned());
        params.decompose.forbid.extend(self.forbid.iter().cloned());
        Ok(params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_override_the_defaults() {
        let settings = Settings {
            overlap: Some(0.25),
            overlap_joints: vec![("elbow".into(), 0.1)],
            blend: Some(Blend::Paper),
            binding: Some(Binding::Rigid),
            force: vec!["neck".into()],
            max_influences: Some(2),
            ..Settings::default()
        };
        let params = settings.params().unwrap();
        assert_eq!(params.overlap.factor, 0.25);
        assert_eq!(params.overlap.per_joint["elbow"], 0.1);
        assert_eq!(params.blend, Blend::Paper);
        assert_eq!(params.binding, Binding::Rigid);
        assert_eq!(params.max_influences, 2);
        assert!(params.decompose.force.contains(&"neck".to_string()));
        assert_eq!(Settings::default().params().unwrap(), SkinParams::default());
    }

    /// `fail_on` of a settings file, overridden by the option; the rest of the file is the
    /// method's parameters, unknown keys refused as before.
    #[test]
    fn the_gate_comes_from_the_settings_file_or_the_option() {
        let dir = std::env::temp_dir().join(format!("atlas-skin-settings-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = |name: &str, text: &str| {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            Settings {
                config: Some(path),
                ..Settings::default()
            }
        };
        let gated = file(
            "gated.json",
            r#"{"fail_on": ["placement", "soft-joints"], "overlap": {"factor": 0.25}}"#,
        );
        assert_eq!(
            gated.fail_on().unwrap(),
            [Condition::Placement, Condition::SoftJoints]
        );
        assert_eq!(gated.params().unwrap().overlap.factor, 0.25);
        let overridden = Settings {
            fail_on: vec![Condition::Warnings],
            ..gated
        };
        assert_eq!(overridden.fail_on().unwrap(), [Condition::Warnings]);
        let plain = file("plain.json", r#"{"blend": "paper"}"#);
        assert_eq!(plain.fail_on().unwrap(), []);
        assert_eq!(Settings::default().fail_on().unwrap(), []);

        let unknown = file("unknown.json", r#"{"fail_on": ["warnings", "typos"]}"#);
        let message = crate::error_chain(&unknown.fail_on().unwrap_err());
        assert!(
            message.contains("fail_on must be a list") && message.contains("typos"),
            "{message}"
        );
        assert!(unknown.params().is_ok());
        let misspelt = file("misspelt.json", r#"{"fail_on": [], "overlpa": 1}"#);
        let message = crate::error_chain(&misspelt.params().unwrap_err());
        assert!(message.contains("unknown field `overlpa`"), "{message}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn influences_outside_the_writer_range_are_refused() {
        for n in [0, MAX_INFLUENCES + 1] {
            let settings = Settings {
                max_influences: Some(n),
                ..Settings::default()
            };
            let message = settings.params().unwrap_err().to_string();
            assert_eq!(
                message,
                format!("max_influences {n} is outside 1..={MAX_INFLUENCES}")
            );
        }
    }
}
