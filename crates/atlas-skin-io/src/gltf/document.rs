//! Checked access to the raw glTF JSON: every lookup that can fail names the JSON location
//! (e.g. `nodes[3].children`) in an [`IoError`] naming the file.

use super::budget::DecodeBudget;
use crate::IoError;
use serde_json::Value;
use std::fmt::{self, Display};
use std::path::Path;

/// A parsed glTF document with its loaded buffers and what it may still decode, borrowed
/// for reading.
#[derive(Clone, Copy)]
pub(crate) struct Document<'a> {
    pub json: &'a Value,
    pub buffers: &'a [Vec<u8>],
    pub path: &'a Path,
    pub budget: &'a DecodeBudget,
}

impl<'a> Document<'a> {
    /// An [`IoError::Invalid`] about this document.
    pub fn error(&self, message: impl Into<String>) -> IoError {
        IoError::invalid(self.path, message)
    }

    /// Takes `bytes` about to be decoded for `role` from the budget; an error past it.
    pub fn charge(&self, bytes: u64, role: &dyn Display) -> Result<(), IoError> {
        self.budget
            .charge(bytes)
            .map_err(|e| self.error(format!("{role}: {e}")))
    }

    /// The top-level array `key` (`nodes`, `meshes`, ...); empty when absent.
    pub fn array(&self, key: &str) -> Result<&'a [Value], IoError> {
        match self.json.get(key) {
            None => Ok(&[]),
            Some(Value::Array(items)) => Ok(items),
            Some(_) => Err(self.error(format!("\"{key}\" is not an array"))),
        }
    }

    /// Item `index` of the top-level array `key`, which must exist.
    pub fn item(&self, key: &str, index: usize) -> Result<&'a Value, IoError> {
        let items = self.array(key)?;
        items.get(index).ok_or_else(|| {
            self.error(format!(
                "{key}[{index}] is referenced but the document has {} {key}",
                items.len()
            ))
        })
    }

    /// The optional index field `key` of `object` (found at `location`).
    pub fn opt_index(
        &self,
        object: &Value,
        location: &dyn Display,
        key: &str,
    ) -> Result<Option<usize>, IoError> {
        match object.get(key) {
            None => Ok(None),
            Some(value) => value
                .as_u64()
                .and_then(|v| usize::try_from(v).ok())
                .map(Some)
                .ok_or_else(|| {
                    self.error(format!(
                        "{location}.{key} is {value}, not a non-negative integer"
                    ))
                }),
        }
    }

    /// The required index field `key` of `object` (found at `location`).
    pub fn index(
        &self,
        object: &Value,
        location: &dyn Display,
        key: &str,
    ) -> Result<usize, IoError> {
        self.opt_index(object, location, key)?
            .ok_or_else(|| self.error(format!("{location} has no \"{key}\"")))
    }

    /// The optional array of indices `key` of `object`; empty when absent.
    pub fn indices(
        &self,
        object: &Value,
        location: &dyn Display,
        key: &str,
    ) -> Result<Vec<usize>, IoError> {
        let Some(value) = object.get(key) else {
            return Ok(Vec::new());
        };
        let bad = || self.error(format!("{location}.{key} is not an array of indices"));
        value
            .as_array()
            .ok_or_else(bad)?
            .iter()
            .map(|v| {
                v.as_u64()
                    .and_then(|v| usize::try_from(v).ok())
                    .ok_or_else(bad)
            })
            .collect()
    }

    /// The optional array of exactly `N` finite numbers `key` of `object`.
    pub fn opt_floats<const N: usize>(
        &self,
        object: &Value,
        location: &dyn Display,
        key: &str,
    ) -> Result<Option<[f32; N]>, IoError> {
        let Some(value) = object.get(key) else {
            return Ok(None);
        };
        let bad = || {
            self.error(format!(
                "{location}.{key} is not an array of {N} finite numbers"
            ))
        };
        let items = value.as_array().filter(|a| a.len() == N).ok_or_else(bad)?;
        let mut out = [0.0; N];
        for (slot, item) in out.iter_mut().zip(items) {
            *slot = item
                .as_f64()
                .map(|v| v as f32)
                .filter(|v| v.is_finite())
                .ok_or_else(bad)?;
        }
        Ok(Some(out))
    }
}

/// A place in the JSON named in messages, such as `accessors[3]` or
/// `animations[0].channels[2]`: written out only when a message names it, so that reading
/// a valid document formats no location (a `format!` per accessor, view and animation
/// channel cost about 1 million instructions on RobotExpressive).
#[derive(Clone, Copy)]
pub(crate) struct Location<'a> {
    parent: Option<&'a dyn Display>,
    key: &'static str,
    index: Option<usize>,
}

impl<'a> Location<'a> {
    /// `key[index]`: item `index` of the top-level array `key`.
    pub fn item(key: &'static str, index: usize) -> Self {
        Self {
            parent: None,
            key,
            index: Some(index),
        }
    }

    /// `parent.key[index]`.
    pub fn child(parent: &'a dyn Display, key: &'static str, index: usize) -> Self {
        Self {
            parent: Some(parent),
            key,
            index: Some(index),
        }
    }

    /// `parent.key`.
    pub fn field(parent: &'a dyn Display, key: &'static str) -> Self {
        Self {
            parent: Some(parent),
            key,
            index: None,
        }
    }
}

impl Display for Location<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(parent) = self.parent {
            write!(f, "{parent}.")?;
        }
        f.write_str(self.key)?;
        match self.index {
            Some(index) => write!(f, "[{index}]"),
            None => Ok(()),
        }
    }
}

/// The optional string field `key` of `object`.
pub(crate) fn opt_str<'v>(object: &'v Value, key: &str) -> Option<&'v str> {
    object.get(key).and_then(Value::as_str)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Locations read as the `format!`s they stand for.
    #[test]
    fn locations_read_as_json_paths() {
        let animation = format!("animations[{}]", 2);
        let sampler = Location::child(&animation, "samplers", 5);
        assert_eq!(Location::item("accessors", 3).to_string(), "accessors[3]");
        assert_eq!(sampler.to_string(), "animations[2].samplers[5]");
        assert_eq!(
            Location::field(&sampler, "input").to_string(),
            "animations[2].samplers[5].input"
        );
        let channel = Location::child(&animation, "channels", 0);
        assert_eq!(
            format!("{channel}.target.node is 9"),
            "animations[2].channels[0].target.node is 9"
        );
    }
}
