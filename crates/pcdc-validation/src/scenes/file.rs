//! Scene files: the UCS and Brazilian scenes written as TOML (`scenes/ucs.toml`,
//! `scenes/brazilian.toml`). The first key names the scene (`scene = "ucs"` or
//! `scene = "brazilian"`); omitted tables and keys take the scene's full-size values
//! (a `[loading]` or `[output]` table, when given, gives all its keys), unknown keys are errors (with the line and the accepted keys), and
//! every value is range-checked with an error that names its key: lower bounds from
//! physics, upper bounds where a value is physically absurd for a laboratory test
//! (documented with their reasons in [`crate::scenes::limits`]), and the memory the mesh
//! would need against the [memory limit](pcdc_mesh::memory).
//!
//! ```
//! use pcdc_validation::scenes::file::SceneFile;
//! let scene = SceneFile::from_toml("scene = \"ucs\"\n[sample]\nmesh_size = 0.004\n").unwrap();
//! match scene {
//!     SceneFile::Ucs(p) => assert_eq!(p.sample.mesh_size, 0.004),
//!     SceneFile::Brazilian(_) => unreachable!(),
//! }
//! let err = SceneFile::from_toml("scene = \"ucs\"\n[rock]\npoisson = 0.5\n").unwrap_err();
//! assert!(err.to_string().contains("rock.poisson"));
//! ```

use std::path::Path;

use serde::Deserialize;

use super::platen_test::ParamError;
use super::{brazilian, ucs};

/// The scenes a file can hold.
const SCENES: &str = "\"ucs\" or \"brazilian\"";

/// A parsed and validated scene file.
#[derive(Clone, Debug, PartialEq)]
// Parsed once per run: boxing the larger variant would only burden every match.
#[allow(clippy::large_enum_variant)]
pub enum SceneFile {
    /// `scene = "ucs"`.
    Ucs(ucs::Params),
    /// `scene = "brazilian"`.
    Brazilian(brazilian::Params),
}

/// Why a scene file was rejected.
#[derive(Debug, thiserror::Error)]
pub enum SceneFileError {
    /// The file could not be read.
    #[error("cannot read scene file {path}: {source}")]
    Read {
        /// The path given.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Not valid TOML, an unknown key or a value of the wrong type (the message gives
    /// the line, the key and the accepted keys).
    #[error("{0}")]
    Toml(#[from] toml::de::Error),
    /// No `scene` key.
    #[error("missing key `scene`: a scene file starts with scene = {SCENES}")]
    MissingScene,
    /// An unknown scene name.
    #[error("scene = \"{0}\" is not a scene; accepted: {SCENES}")]
    UnknownScene(String),
    /// A value out of range (negative size, ν ≥ 0.5, ...).
    #[error("invalid value {0}")]
    Param(#[from] ParamError),
    /// The mesh the scene would build exceeds the memory limit (the message gives the
    /// estimate in bytes), or the limit's environment variable is malformed.
    #[error("{0}")]
    Memory(#[from] pcdc_mesh::MeshError),
    /// The scene could not be written as TOML.
    #[error("cannot write the scene as TOML: {0}")]
    Write(#[from] toml::ser::Error),
}

/// Only the scene tag; the other keys are read by the scene's own type.
#[derive(Deserialize)]
struct Head {
    scene: Option<String>,
}

impl SceneFile {
    /// Parses and validates a scene from TOML text.
    pub fn from_toml(text: &str) -> Result<Self, SceneFileError> {
        let head: Head = toml::from_str(text)?;
        let scene = match head.scene.as_deref() {
            Some("ucs") => {
                let p: ucs::Params = toml::from_str(text)?;
                p.validate()?;
                p.check_memory()?;
                SceneFile::Ucs(p)
            }
            Some("brazilian") => {
                let p: brazilian::Params = toml::from_str(text)?;
                p.validate()?;
                p.check_memory()?;
                SceneFile::Brazilian(p)
            }
            Some(other) => return Err(SceneFileError::UnknownScene(other.into())),
            None => return Err(SceneFileError::MissingScene),
        };
        Ok(scene)
    }

    /// Reads, parses and validates a scene file.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, SceneFileError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| SceneFileError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml(&text)
    }

    /// The scene as TOML (every key written out; reads back equal).
    pub fn to_toml(&self) -> Result<String, SceneFileError> {
        Ok(match self {
            SceneFile::Ucs(p) => toml::to_string(p)?,
            SceneFile::Brazilian(p) => toml::to_string(p)?,
        })
    }
}
