use crate::Location;

/// An error in a scene: where and what.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// File and line (line 0 when unknown).
    pub location: Location,
    /// What is wrong.
    pub message: String,
}

impl SceneError {
    /// An error at `location`.
    pub fn new(location: Location, message: impl Into<String>) -> Self {
        Self {
            location,
            message: message.into(),
        }
    }
}

impl core::fmt::Display for SceneError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}: {}", self.location, self.message)
    }
}

impl std::error::Error for SceneError {}

/// A non-fatal remark about a scene (an ignored property, a fallback taken).
#[derive(Clone, Debug, PartialEq)]
pub struct SceneWarning {
    /// File and line.
    pub location: Location,
    /// What was noticed.
    pub message: String,
}

impl core::fmt::Display for SceneWarning {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}: warning: {}", self.location, self.message)
    }
}
