//! Filesystem-safe names: experiment names, unit keys and plot file stems become file and directory
//! names, so they are checked once, where they are made, and trusted everywhere after.

use std::fmt;

use serde::{Deserialize, Serialize};

/// The longest name accepted, in bytes; well under the 255-byte file-name limit of common file
/// systems once `.csv` and the runner's temporary suffix are added.
pub const MAX_NAME_BYTES: usize = 200;

/// Why a string is not a [`SafeName`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{name}' is not a filesystem-safe name: {what}")]
pub struct NameError {
    pub name: String,
    pub what: &'static str,
}

/// A non-empty name of at most `MAX_NAME_BYTES` ASCII letters, digits and `_ - . = +`, not
/// starting with `.`: the same file name on every operating system, never hidden, never a path.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct SafeName(String);

/// The name of an experiment: its directory under the output root and the stem of its CSV.
pub type ExperimentName = SafeName;

/// The stable key of a work unit: the stem of its `units/<key>.csv`, e.g. `pf__noise=0.1__trial=2`.
pub type UnitKey = SafeName;

impl SafeName {
    pub fn new(name: impl Into<String>) -> Result<Self, NameError> {
        let name = name.into();
        match problem(&name) {
            None => Ok(Self(name)),
            Some(what) => Err(NameError { name, what }),
        }
    }

    /// Starts a key `head__name=value__...`, the conventional shape of a unit key.
    pub fn builder(head: impl fmt::Display) -> KeyBuilder {
        KeyBuilder {
            key: head.to_string(),
        }
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }
}

fn problem(name: &str) -> Option<&'static str> {
    if name.is_empty() {
        Some("it is empty")
    } else if name.len() > MAX_NAME_BYTES {
        Some("it is longer than 200 bytes")
    } else if name.starts_with('.') {
        Some("it starts with '.' (hidden names are reserved for temporary files)")
    } else if !name
        .bytes()
        .all(|b| b.is_ascii_alphanumeric() || b"_-.=+".contains(&b))
    {
        Some("only ASCII letters, digits and _ - . = + are allowed")
    } else {
        None
    }
}

impl TryFrom<String> for SafeName {
    type Error = NameError;
    fn try_from(name: String) -> Result<Self, NameError> {
        Self::new(name)
    }
}

impl From<SafeName> for String {
    fn from(name: SafeName) -> String {
        name.0
    }
}

impl std::str::FromStr for SafeName {
    type Err = NameError;
    fn from_str(s: &str) -> Result<Self, NameError> {
        Self::new(s)
    }
}

impl fmt::Display for SafeName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// Builds `head__name=value__name=value`; the whole key is checked by [`build`](Self::build).
#[derive(Debug, Clone)]
pub struct KeyBuilder {
    key: String,
}

impl KeyBuilder {
    /// Appends `__name=value`, the value in its `Display` form (`0.1`, `2`, `polar-fourier`).
    pub fn param(mut self, name: &str, value: impl fmt::Display) -> Self {
        self.key.push_str("__");
        self.key.push_str(name);
        self.key.push('=');
        self.key.push_str(&value.to_string());
        self
    }

    pub fn build(self) -> Result<SafeName, NameError> {
        SafeName::new(self.key)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_keys_and_rejects_paths() {
        let key = SafeName::builder("pf")
            .param("noise", 0.1)
            .param("trial", 2)
            .build()
            .unwrap();
        assert_eq!(key.as_str(), "pf__noise=0.1__trial=2");
        for bad in ["", ".hidden", "a/b", "..", "a b", "é", "a\\b", &"x".repeat(201)] {
            assert!(SafeName::new(bad).is_err(), "{bad:?} accepted");
        }
        assert!(SafeName::new("x".repeat(200)).is_ok());
        let e = SafeName::new("a/b").unwrap_err().to_string();
        assert!(e.contains("'a/b'") && e.contains("allowed"), "{e}");
    }

    #[test]
    fn deserialising_checks_the_name() {
        let ok: SafeName = serde_json::from_str("\"noise=-0.5\"").unwrap();
        assert_eq!(ok.as_str(), "noise=-0.5");
        assert!(serde_json::from_str::<SafeName>("\"../etc\"").is_err());
    }
}
