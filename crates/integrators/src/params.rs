//! Estimator parameters: named values with where they came from (a scene file and line, the
//! command line, or the calling program), typed getters that check them, and one error type.
//!
//! The shape follows pbrt-v4's `ParameterDictionary`: the scene's `<integrator>` parameters and
//! the command-line flags become one ordered [`ParamSet`]; a settings type offers every
//! parameter to its own names in order (later ones win, so the command line overrides the
//! scene), reads it with a typed getter ([`Param::count`], [`Param::positive`],
//! [`Param::boolean`], [`Param::choice`]; the MIS getter `Param::mis` lives with the MIS names
//! in [`crate::reuse::settings`]) and gets back the parameters no name
//! claimed, with their source, to warn about. Values the command line already parsed stay typed
//! ([`ParamValue::Count`], …); text from scene files is parsed here, once.

use std::fmt;

use restir_scene::Location;

/// Largest count a parameter may have.
pub const MAX_COUNT: u32 = 1 << 20;

/// A parameter's value: text from a scene file, or a value the command line already parsed.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    /// Text, parsed by the getter.
    Text(String),
    /// A whole number.
    Count(u32),
    /// A number.
    Number(f32),
    /// A switch.
    Bool(bool),
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamValue::Text(s) => f.write_str(s),
            ParamValue::Count(n) => write!(f, "{n}"),
            ParamValue::Number(x) => write!(f, "{x}"),
            ParamValue::Bool(b) => write!(f, "{b}"),
        }
    }
}

impl From<&str> for ParamValue {
    fn from(s: &str) -> Self {
        ParamValue::Text(s.to_string())
    }
}
impl From<String> for ParamValue {
    fn from(s: String) -> Self {
        ParamValue::Text(s)
    }
}
impl From<u32> for ParamValue {
    fn from(n: u32) -> Self {
        ParamValue::Count(n)
    }
}
impl From<f32> for ParamValue {
    fn from(x: f32) -> Self {
        ParamValue::Number(x)
    }
}
impl From<bool> for ParamValue {
    fn from(b: bool) -> Self {
        ParamValue::Bool(b)
    }
}

/// Where a parameter was given.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamSource {
    /// The scene's `<integrator>` (file and line; the file may be empty for scenes built in
    /// memory).
    Scene(Location),
    /// A command-line flag of the same name.
    Flag,
    /// The calling program (an evaluation suite, a test).
    Caller,
}

impl fmt::Display for ParamSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamSource::Scene(location) => write!(f, "{location}"),
            ParamSource::Flag => f.write_str("command line"),
            ParamSource::Caller => f.write_str("caller"),
        }
    }
}

/// One named parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// The name as given (case and `-`/`_` as written).
    pub name: String,
    /// The value.
    pub value: ParamValue,
    /// Where it was given.
    pub source: ParamSource,
}

/// What is wrong with a parameter's value.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamProblem {
    /// Not a whole number.
    NotWholeNumber,
    /// A whole number out of `min ..= MAX_COUNT`.
    CountOutOfRange {
        /// The number.
        value: u32,
        /// The smallest allowed.
        min: u32,
    },
    /// Not a number.
    NotNumber,
    /// Not a positive finite number.
    NotPositive,
    /// Not a boolean.
    NotBool,
    /// Not one of the names; `expected` lists them as the message says it.
    NotChoice {
        /// The choices, e.g. `one of a, b, c` or `a or b`.
        expected: String,
    },
    /// An angle above 180 degrees.
    AngleTooLarge,
    /// A number not above 1.
    NotAboveOne,
    /// A number outside `0 ..= 1`.
    NotFraction,
    /// Not a number from 0 up to, but not including, 1.
    NotBelowOne,
    /// A parameter that no longer exists; `instead` says what does its work now.
    Removed {
        /// What to use instead.
        instead: String,
    },
    /// A parameter given to the `auto` estimator, which takes none.
    NotForAuto,
    /// A value that needs another parameter's value, which was not given (`needs` says which,
    /// e.g. `visibility = target`).
    Needs {
        /// What the value needs.
        needs: String,
    },
}

/// A parameter that could not be read: its name, its value as given and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    /// The parameter's name as given.
    pub name: String,
    /// The value as given (trimmed).
    pub value: String,
    /// Where the parameter was given.
    pub source: ParamSource,
    /// What is wrong.
    pub problem: ParamProblem,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Errors in scene parameters name the integrator's file and line.
        if let ParamSource::Scene(location) = &self.source
            && !location.file.as_os_str().is_empty()
        {
            write!(f, "{location}: integrator: ")?;
        }
        let (name, v) = (&self.name, &self.value);
        match &self.problem {
            ParamProblem::NotWholeNumber => write!(f, "{name} = '{v}': expected a whole number"),
            ParamProblem::CountOutOfRange { value, min } => write!(
                f,
                "{name} = {value}: expected a number from {min} to {MAX_COUNT}"
            ),
            ParamProblem::NotNumber => write!(f, "{name} = '{v}': expected a number"),
            ParamProblem::NotPositive => {
                write!(f, "{name} = {v}: expected a positive finite number")
            }
            ParamProblem::NotBool => write!(f, "{name} = '{v}': expected true or false"),
            ParamProblem::NotChoice { expected } => {
                write!(f, "{name} = '{v}': expected {expected}")
            }
            ParamProblem::AngleTooLarge => {
                write!(f, "{name} = {v}: expected an angle in degrees up to 180")
            }
            ParamProblem::NotAboveOne => write!(f, "{name} = {v}: expected a number above 1"),
            ParamProblem::NotFraction => write!(f, "{name} = {v}: expected a number from 0 to 1"),
            ParamProblem::NotBelowOne => {
                write!(f, "{name} = {v}: expected a number from 0 to below 1")
            }
            ParamProblem::Removed { instead } => {
                write!(f, "{name} = '{v}': no such parameter any more: {instead}")
            }
            ParamProblem::NotForAuto => write!(
                f,
                "{name} = '{v}': the integrator auto takes no estimator parameters (it runs \
                 path, restir-di or restir-pt at its defaults); name the integrator to configure it"
            ),
            ParamProblem::Needs { needs } => write!(f, "{name} = '{v}' needs {needs}"),
        }
    }
}

impl std::error::Error for ParamError {}

/// Lower case with `_` for `-`: names and choices compare in this form.
fn normalize(s: &str, dash: char, to: char) -> String {
    s.to_ascii_lowercase().replace(dash, &to.to_string())
}

impl Param {
    /// A parameter with `value` from `source`.
    pub fn new(name: impl Into<String>, value: impl Into<ParamValue>, source: ParamSource) -> Self {
        Self {
            name: name.into(),
            value: value.into(),
            source,
        }
    }

    /// A command-line flag's value.
    pub fn flag(name: &str, value: impl Into<ParamValue>) -> Self {
        Self::new(name, value, ParamSource::Flag)
    }

    /// The name settings match on: lower case, `_` for `-`.
    pub fn key(&self) -> String {
        normalize(&self.name, '-', '_')
    }

    /// The value as text (trimmed), as messages quote it.
    fn text(&self) -> String {
        match &self.value {
            ParamValue::Text(s) => s.trim().to_string(),
            v => v.to_string(),
        }
    }

    /// An error about this parameter.
    pub fn error(&self, problem: ParamProblem) -> ParamError {
        ParamError {
            name: self.name.clone(),
            value: self.text(),
            source: self.source.clone(),
            problem,
        }
    }

    /// A whole number from `min` to [`MAX_COUNT`].
    pub fn count(&self, min: u32) -> Result<u32, ParamError> {
        let n = match self.value {
            ParamValue::Count(n) => n,
            _ => self
                .text()
                .parse()
                .map_err(|_| self.error(ParamProblem::NotWholeNumber))?,
        };
        if n < min || n > MAX_COUNT {
            return Err(self.error(ParamProblem::CountOutOfRange { value: n, min }));
        }
        Ok(n)
    }

    /// A number, as given or parsed from text.
    fn number(&self) -> Result<f32, ParamError> {
        match self.value {
            ParamValue::Number(x) => Ok(x),
            _ => self
                .text()
                .parse()
                .map_err(|_| self.error(ParamProblem::NotNumber)),
        }
    }

    /// A positive finite number.
    pub fn positive(&self) -> Result<f32, ParamError> {
        let x = self.number()?;
        if !(x > 0.0 && x.is_finite()) {
            return Err(self.error(ParamProblem::NotPositive));
        }
        Ok(x)
    }

    /// A number from 0 to 1.
    pub fn fraction(&self) -> Result<f32, ParamError> {
        let x = self.number()?;
        if !(0.0..=1.0).contains(&x) {
            return Err(self.error(ParamProblem::NotFraction));
        }
        Ok(x)
    }

    /// A boolean (`true`/`false`, `1`/`0`, `yes`/`no`, `on`/`off`).
    pub fn boolean(&self) -> Result<bool, ParamError> {
        if let ParamValue::Bool(b) = self.value {
            return Ok(b);
        }
        match self.text().to_ascii_lowercase().as_str() {
            "true" | "1" | "yes" | "on" => Ok(true),
            "false" | "0" | "no" | "off" => Ok(false),
            _ => Err(self.error(ParamProblem::NotBool)),
        }
    }

    /// One of `choices` (case-insensitive, `-` and `_` the same); `expected` words the choices
    /// for the error message (`one of a, b, c`, `a or b`).
    pub fn choice<T: Copy>(&self, choices: &[(&str, T)], expected: &str) -> Result<T, ParamError> {
        let v = normalize(&self.text(), '_', '-');
        choices
            .iter()
            .find(|(n, _)| normalize(n, '_', '-') == v)
            .map(|(_, t)| *t)
            .ok_or_else(|| {
                self.error(ParamProblem::NotChoice {
                    expected: expected.to_string(),
                })
            })
    }
}

/// Parameters in the order they apply: the scene's, then the command line's.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamSet {
    params: Vec<Param>,
}

impl ParamSet {
    /// No parameters.
    pub fn new() -> Self {
        Self::default()
    }

    /// The scene's `name = value` parameters, declared at `location`.
    pub fn from_scene(params: &[(String, String)], location: &Location) -> Self {
        params
            .iter()
            .map(|(k, v)| Param::new(k, v.as_str(), ParamSource::Scene(location.clone())))
            .collect()
    }

    /// Adds `p` after the others (it wins over earlier ones of the same name).
    pub fn push(&mut self, p: Param) {
        self.params.push(p);
    }

    /// Adds every parameter of `other` after these.
    pub fn extend(&mut self, other: &ParamSet) {
        self.params.extend(other.params.iter().cloned());
    }

    /// The parameters in order.
    pub fn iter(&self) -> impl Iterator<Item = &Param> {
        self.params.iter()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// Offers every parameter in order to `take` with its [`Param::key`]; `take` returns whether
    /// the name is one of its own. Returns the parameters nobody took, or the first error.
    pub fn apply(
        &self,
        mut take: impl FnMut(&str, &Param) -> Result<bool, ParamError>,
    ) -> Result<Vec<Param>, ParamError> {
        let mut unused = Vec::new();
        for p in &self.params {
            if !take(&p.key(), p)? {
                unused.push(p.clone());
            }
        }
        Ok(unused)
    }
}

impl FromIterator<Param> for ParamSet {
    fn from_iter<I: IntoIterator<Item = Param>>(iter: I) -> Self {
        Self {
            params: iter.into_iter().collect(),
        }
    }
}

/// `name = value` text pairs from the calling program.
impl<K: AsRef<str>, V: AsRef<str>> From<&[(K, V)]> for ParamSet {
    fn from(pairs: &[(K, V)]) -> Self {
        pairs
            .iter()
            .map(|(k, v)| Param::new(k.as_ref(), v.as_ref(), ParamSource::Caller))
            .collect()
    }
}

impl<K: AsRef<str>, V: AsRef<str>> From<Vec<(K, V)>> for ParamSet {
    fn from(pairs: Vec<(K, V)>) -> Self {
        Self::from(pairs.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_values_read_as_their_text_would() {
        let c = Param::flag("candidates", 0u32);
        assert_eq!(
            c.count(1).unwrap_err().to_string(),
            "candidates = 0: expected a number from 1 to 1048576"
        );
        let r = Param::flag("radius", f32::NAN);
        assert_eq!(
            r.positive().unwrap_err().to_string(),
            "radius = NaN: expected a positive finite number"
        );
        let t = Param::new("temporal", " maybe ", ParamSource::Caller);
        assert_eq!(
            t.boolean().unwrap_err().to_string(),
            "temporal = 'maybe': expected true or false"
        );
        let loc = Location {
            file: "s.xml".into(),
            line: 2,
        };
        let s = Param::new("reservior_size", "x", ParamSource::Scene(loc));
        assert_eq!(
            s.count(1).unwrap_err().to_string(),
            "s.xml:2: integrator: reservior_size = 'x': expected a whole number"
        );
        assert_eq!(
            Param::flag("mis", "One_Over_Z").mis().unwrap(),
            restir_gris::MisScheme::OneOverZ
        );
        assert_eq!(Param::flag("duplication", "0.8").fraction().unwrap(), 0.8);
        assert_eq!(
            Param::flag("duplication", f32::NAN)
                .fraction()
                .unwrap_err()
                .to_string(),
            "duplication = NaN: expected a number from 0 to 1"
        );
        assert_eq!(
            Param::flag("duplication", "1.5")
                .fraction()
                .unwrap_err()
                .to_string(),
            "duplication = 1.5: expected a number from 0 to 1"
        );
    }
}
