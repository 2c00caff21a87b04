//! The suite file: scenes × integrator configurations × time budgets × seeds (RON, strict). A
//! scene with `frames` is an animated sequence (an animation suite's entry): every
//! configuration renders its frames in order with one estimator, each frame with the budget.

use std::path::{Path, PathBuf};

use serde::Deserialize;

/// A benchmark suite as written in a `.ron` file. Unknown fields are an error; `Option` fields
/// may be written bare (`width: 128`) or as `Some(128)`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Suite {
    /// Scenes to render.
    #[serde(default)]
    pub scenes: Vec<SuiteScene>,
    /// Generated families of scenes (`restir generate family`), each member a scene of the
    /// suite: written into the output directory on first use ([`Suite::expand_families`]).
    #[serde(default)]
    pub families: Vec<SuiteFamily>,
    /// Integrator configurations; each renders every scene.
    pub integrators: Vec<IntegratorConfig>,
    /// Time budgets in seconds (each render stops starting passes once its budget is spent).
    pub budgets: Vec<f64>,
    /// The clock the budgets count: `Wall` (default) or `Cpu`.
    #[serde(default)]
    pub clock: Clock,
    /// Seeds per (scene, configuration, budget): seeds `0..seeds`.
    #[serde(default = "one")]
    pub seeds: u32,
    /// Passes of the path-traced reference (rendered as two halves with different seeds), for
    /// scenes without a reference EXR.
    #[serde(default = "default_reference_spp")]
    pub reference_spp: u32,
    /// Budget whose first-seed renders go into the crop strips (default: the smallest budget).
    #[serde(default)]
    pub strip_budget: Option<f64>,
}

/// The clock a suite's time budgets count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum Clock {
    /// Elapsed (wall) seconds of the render.
    #[default]
    Wall,
    /// The process's CPU seconds (user and system, all threads) while the render runs: equal
    /// CPU time, which a shared machine that delivers fewer cores than it has does not skew.
    /// Efficiency is `1 / (relMSE · CPU seconds)` with either clock.
    Cpu,
}

/// One scene of a suite.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SuiteScene {
    /// Scene file (`.xml` or `.ron`), relative to the suite file.
    pub path: PathBuf,
    /// Name in the outputs (default: the file stem).
    #[serde(default)]
    pub name: Option<String>,
    /// Image width; overrides the scene's.
    #[serde(default)]
    pub width: Option<u32>,
    /// Image height; overrides the scene's.
    #[serde(default)]
    pub height: Option<u32>,
    /// Longest path; overrides the scene's (for every configuration and the reference).
    #[serde(default)]
    pub max_depth: Option<i32>,
    /// Reference EXR, relative to the suite file; default: a cached path-traced reference.
    #[serde(default)]
    pub reference: Option<PathBuf>,
    /// Reference passes for this scene; overrides the suite's `reference_spp`.
    #[serde(default)]
    pub reference_spp: Option<u32>,
    /// Crop rectangle `(x, y, width, height)` in pixels for the image strip (default: the
    /// central quarter of the image).
    #[serde(default)]
    pub crop: Option<(u32, u32, u32, u32)>,
    /// Labels of the integrator configurations that render this scene (default: all of them).
    #[serde(default)]
    pub integrators: Option<Vec<String>>,
    /// Frames `(first, last)` of the scene's animation (inclusive): the scene is rendered as a
    /// sequence, every frame with the budget by one estimator that carries its history across
    /// frames, against a reference per frame (default: a still image).
    #[serde(default)]
    pub frames: Option<(u32, u32)>,
    /// Frames per second of a sequence (default: the animation's).
    #[serde(default)]
    pub fps: Option<f32>,
}

/// A generated family of scenes in a suite: the training or test family of a study
/// (`restir generate family --kind ISSUE --split SPLIT`), every member (or those listed) a
/// scene with the settings given here.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SuiteFamily {
    /// The study: `di` or `pt` (the still families).
    pub kind: String,
    /// `train` or `test`.
    pub split: String,
    /// Indices of the members to render (default: all of them).
    #[serde(default)]
    pub members: Option<Vec<usize>>,
    /// Image width; overrides the scenes'.
    #[serde(default)]
    pub width: Option<u32>,
    /// Image height; overrides the scenes'.
    #[serde(default)]
    pub height: Option<u32>,
    /// Longest path; overrides the scenes'.
    #[serde(default)]
    pub max_depth: Option<i32>,
    /// Reference passes for these scenes; overrides the suite's `reference_spp`.
    #[serde(default)]
    pub reference_spp: Option<u32>,
    /// Labels of the integrator configurations that render these scenes (default: all).
    #[serde(default)]
    pub integrators: Option<Vec<String>>,
}

impl SuiteFamily {
    /// The family's members to render (checked: a known still study and split, members in
    /// range).
    pub fn chosen(&self) -> Result<Vec<restir_families::FamilyMember>, SuiteError> {
        use restir_families::{Family, Split, members};
        let family = Family::ALL
            .into_iter()
            .find(|i| i.name() == self.kind && !i.animated())
            .ok_or_else(|| {
                SuiteError::rule(format!(
                    "family kind '{}': expected di or pt (the moving families are sequences)",
                    self.kind
                ))
            })?;
        let split = match self.split.as_str() {
            "train" => Split::Train,
            "test" => Split::Test,
            other => {
                return Err(SuiteError::rule(format!(
                    "family split '{other}': expected train or test"
                )));
            }
        };
        let all = members(family, split);
        match &self.members {
            None => Ok(all),
            Some(list) => list
                .iter()
                .map(|&i| {
                    all.get(i).cloned().ok_or_else(|| {
                        SuiteError::rule(format!(
                            "the {} {} family has members 0 to {}, not {i}",
                            self.kind,
                            self.split,
                            all.len() - 1
                        ))
                    })
                })
                .collect(),
        }
    }
}

/// One integrator configuration: what `IntegratorOptions` takes, plus a label.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorConfig {
    /// Name in the outputs (unique within the suite).
    pub label: String,
    /// Estimator: `path`, `restir-di`, …
    pub integrator: String,
    /// Estimator parameters as `("name", "value")`, as `restir render --NAME VALUE` sets them.
    #[serde(default)]
    pub params: Vec<(String, String)>,
}

fn one() -> u32 {
    1
}

fn default_reference_spp() -> u32 {
    4096
}

impl IntegratorConfig {
    /// The parameters as `name=value` joined by spaces (empty for none).
    pub fn params_string(&self) -> String {
        self.params
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

impl SuiteScene {
    /// Whether the configuration labelled `label` renders this scene.
    pub fn runs(&self, label: &str) -> bool {
        self.integrators
            .as_ref()
            .is_none_or(|l| l.iter().any(|x| x == label))
    }

    /// The scene's name in the outputs.
    pub fn display_name(&self) -> String {
        self.name.clone().unwrap_or_else(|| {
            self.path
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("scene")
                .to_string()
        })
    }
}

/// A suite file that cannot be read or parsed, or a suite that breaks a rule: where (when
/// known) and what.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SuiteError {
    /// The suite file, when known.
    pub file: Option<PathBuf>,
    /// Line and column in the file, for syntax errors.
    pub position: Option<(usize, usize)>,
    /// What is wrong.
    pub message: String,
}

impl SuiteError {
    /// A broken rule, not yet tied to a file.
    fn rule(message: impl Into<String>) -> Self {
        Self {
            file: None,
            position: None,
            message: message.into(),
        }
    }

    /// The same error, in `file`.
    fn in_file(self, file: &Path) -> Self {
        Self {
            file: Some(file.to_path_buf()),
            ..self
        }
    }
}

impl std::fmt::Display for SuiteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // One line whatever the suite's strings hold (a path or label with a newline in it).
        let message: String = self
            .message
            .chars()
            .flat_map(|c| {
                let escaped = c.is_control().then(|| c.escape_default());
                escaped
                    .into_iter()
                    .flatten()
                    .chain((!c.is_control()).then_some(c))
            })
            .collect();
        match (&self.file, self.position) {
            (Some(file), Some((line, col))) => {
                write!(f, "{}:{line}:{col}: {message}", file.display())
            }
            (Some(file), None) => write!(f, "{}: {message}", file.display()),
            (None, _) => f.write_str(&message),
        }
    }
}

impl std::error::Error for SuiteError {}

impl Suite {
    /// Parses a suite; errors read `file:line:column: message`.
    pub fn parse(text: &str, file: &Path) -> Result<Suite, SuiteError> {
        let suite: Suite = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
            .from_str(text)
            .map_err(|e| SuiteError {
                file: Some(file.to_path_buf()),
                position: Some((e.span.start.line, e.span.start.col)),
                message: e.code.to_string(),
            })?;
        suite.validate().map_err(|e| e.in_file(file))?;
        Ok(suite)
    }

    /// Reads and parses a suite file.
    pub fn load(file: &Path) -> Result<Suite, SuiteError> {
        Self::load_located(file).map(|(suite, _)| suite)
    }

    /// Reads and parses a suite file, and finds the line of each scene, family member and
    /// integrator configuration in it ([`SuiteLines`]). Only a regular file of at most
    /// [`MAX_SUITE_BYTES`] is read: a FIFO, a device or a directory is an error, not a hang.
    pub fn load_located(file: &Path) -> Result<(Suite, SuiteLines), SuiteError> {
        let text = read_suite_text(file)
            .map_err(|e| SuiteError::rule(format!("cannot read suite: {e}")).in_file(file))?;
        let suite = Self::parse(&text, file)?;
        let lines = SuiteLines::locate(&suite, &text, file);
        Ok((suite, lines))
    }

    /// Writes the members of the suite's families that are not there yet into
    /// `dir/<kind>-<split>/` (the scene and its assets, as `restir generate family` writes
    /// them) and appends each as a scene. Afterwards the suite has no families left.
    pub fn expand_families(&mut self, dir: &Path) -> Result<(), SuiteError> {
        for f in std::mem::take(&mut self.families) {
            let out = dir.join(format!("{}-{}", f.kind, f.split));
            for member in f.chosen()? {
                let name = member.name();
                let path = out.join(format!("{name}.ron"));
                if !path.is_file() {
                    let generated = member
                        .generate()
                        .map_err(|e| SuiteError::rule(format!("{name}: {e}")))?;
                    generated
                        .write(&out, &name)
                        .map_err(|e| SuiteError::rule(format!("writing {}: {e}", out.display())))?;
                }
                self.scenes.push(SuiteScene {
                    path,
                    name: Some(name),
                    width: f.width,
                    height: f.height,
                    max_depth: f.max_depth,
                    reference: None,
                    reference_spp: f.reference_spp,
                    crop: None,
                    integrators: f.integrators.clone(),
                    frames: None,
                    fps: None,
                });
            }
        }
        Ok(())
    }

    /// Checks what the format cannot: non-empty lists, positive budgets, unique names.
    pub fn validate(&self) -> Result<(), SuiteError> {
        if self.scenes.is_empty() && self.families.is_empty() {
            return Err(SuiteError::rule("the suite has no scenes"));
        }
        for f in &self.families {
            f.chosen()?;
            if let Some(spp) = f.reference_spp
                && !(2..=1 << 24).contains(&spp)
            {
                return Err(SuiteError::rule(format!(
                    "family {}-{}: reference_spp {spp}: expected 2 to 16777216",
                    f.kind, f.split
                )));
            }
        }
        if self.integrators.is_empty() {
            return Err(SuiteError::rule("the suite has no integrators"));
        }
        check_budgets(&self.budgets)?;
        if self.seeds == 0 || self.seeds > 10_000 {
            return Err(SuiteError::rule(format!(
                "seeds {}: expected 1 to 10000",
                self.seeds
            )));
        }
        let check_spp = |spp: u32| {
            if (2..=1 << 24).contains(&spp) {
                Ok(())
            } else {
                Err(SuiteError::rule(format!(
                    "reference_spp {spp}: expected 2 to 16777216"
                )))
            }
        };
        check_spp(self.reference_spp)?;
        if let Some(b) = self.strip_budget.filter(|b| !self.budgets.contains(b)) {
            return Err(SuiteError::rule(format!(
                "strip_budget {b} is not one of the budgets"
            )));
        }
        let mut names = Vec::new();
        for s in &self.scenes {
            let name = s.display_name();
            if names.contains(&name) {
                return Err(SuiteError::rule(format!(
                    "two scenes are named '{name}': give one a `name`"
                )));
            }
            if name.is_empty()
                || !name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
            {
                return Err(SuiteError::rule(format!(
                    "scene name '{name}': use letters, digits, '-', '_' or '.'"
                )));
            }
            names.push(name);
            for (what, v) in [("width", s.width), ("height", s.height)] {
                if v.is_some_and(|v| !(1..=16384).contains(&v)) {
                    return Err(SuiteError::rule(format!(
                        "{}: {what} must be 1 to 16384",
                        s.path.display()
                    )));
                }
            }
            if let Some(spp) = s.reference_spp {
                check_spp(spp)?;
            }
            if let Some((first, last)) = s.frames
                && (first > last || last - first >= 10_000)
            {
                return Err(SuiteError::rule(format!(
                    "{}: frames ({first}, {last}): expected (first, last) with first ≤ last, at \
                     most 10000 frames",
                    s.path.display()
                )));
            }
            if s.frames.is_some() && s.reference.is_some() {
                return Err(SuiteError::rule(format!(
                    "{}: a sequence (`frames`) takes no `reference` image: every frame gets its \
                     own path-traced one",
                    s.path.display()
                )));
            }
            if let Some(fps) = s.fps {
                if s.frames.is_none() {
                    return Err(SuiteError::rule(format!(
                        "{}: `fps` without `frames`",
                        s.path.display()
                    )));
                }
                if !(fps.is_finite() && fps > 0.0) {
                    return Err(SuiteError::rule(format!(
                        "{}: fps {fps}: expected a positive number",
                        s.path.display()
                    )));
                }
            }
            if s.crop.is_some_and(|(_, _, w, h)| w == 0 || h == 0) {
                return Err(SuiteError::rule(format!(
                    "{}: empty crop rectangle",
                    s.path.display()
                )));
            }
        }
        let mut labels: Vec<&str> = Vec::new();
        for c in &self.integrators {
            if c.label.is_empty() || labels.contains(&c.label.as_str()) {
                return Err(SuiteError::rule(format!(
                    "integrator label '{}' is empty or used twice",
                    c.label
                )));
            }
            if c.label.contains(['\n', '"', '|']) {
                return Err(SuiteError::rule(format!(
                    "integrator label '{}': no newlines, quotes or '|'",
                    c.label
                )));
            }
            labels.push(&c.label);
        }
        for s in &self.scenes {
            let Some(list) = &s.integrators else {
                continue;
            };
            if list.is_empty() {
                return Err(SuiteError::rule(format!(
                    "{}: empty `integrators` list (leave it out for all)",
                    s.path.display()
                )));
            }
            if let Some(bad) = list.iter().find(|l| !labels.contains(&l.as_str())) {
                return Err(SuiteError::rule(format!(
                    "{}: `integrators` names '{bad}', which is not a configuration label",
                    s.path.display()
                )));
            }
        }
        Ok(())
    }
}

/// The largest suite file read: 16 MiB (a suite lists scenes and settings; anything larger is
/// not one).
pub const MAX_SUITE_BYTES: u64 = 16 << 20;

/// The text of a suite file: a regular file (checked before opening, since opening a FIFO
/// blocks), at most [`MAX_SUITE_BYTES`], UTF-8.
fn read_suite_text(file: &Path) -> std::io::Result<String> {
    use std::io::Read as _;
    let too_large = |n: u64| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("the file has {n} bytes or more, more than the limit of {MAX_SUITE_BYTES}"),
        )
    };
    let f = restir_image::input::open_regular(file)?;
    let len = f.metadata()?.len();
    if len > MAX_SUITE_BYTES {
        return Err(too_large(len));
    }
    let mut bytes = Vec::new();
    f.take(MAX_SUITE_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_SUITE_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|e| {
        std::io::Error::new(std::io::ErrorKind::InvalidData, format!("not UTF-8: {e}"))
    })
}

/// Where a suite's entries are written in its file, for errors found while running it: the
/// 1-based line of each scene (then of the family that made each family member, in the order
/// [`Suite::expand_families`] appends them) and of each integrator configuration; `None` where
/// the entry could not be found in the text.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SuiteLines {
    /// The suite file.
    pub file: Option<PathBuf>,
    /// Per scene of the expanded suite.
    pub scenes: Vec<Option<usize>>,
    /// Per integrator configuration.
    pub integrators: Vec<Option<usize>>,
}

impl SuiteLines {
    /// Finds the entries of `suite` (as parsed from `text`, before its families are expanded):
    /// a scene on the first line not yet taken that holds `path` and its quoted path, a family
    /// on the line that holds `kind` and its quoted study, a configuration on the line that
    /// holds `label` and its quoted label.
    pub fn locate(suite: &Suite, text: &str, file: &Path) -> SuiteLines {
        let lines: Vec<&str> = text.lines().collect();
        let mut taken = vec![false; lines.len()];
        let mut find = |key: &str, value: &str, take: bool| -> Option<usize> {
            let quoted = format!("\"{value}\"");
            let i = lines
                .iter()
                .enumerate()
                .position(|(i, l)| !taken[i] && l.contains(key) && l.contains(&quoted))?;
            if take {
                taken[i] = true;
            }
            Some(i + 1)
        };
        let mut scenes: Vec<Option<usize>> = suite
            .scenes
            .iter()
            .map(|s| find("path", &s.path.to_string_lossy(), true))
            .collect();
        for f in &suite.families {
            let line = find("kind", &f.kind, true);
            let members = f.chosen().map_or(0, |m| m.len());
            scenes.extend(std::iter::repeat_n(line, members));
        }
        let integrators = suite
            .integrators
            .iter()
            .map(|c| find("label", &c.label, false))
            .collect();
        SuiteLines {
            file: Some(file.to_path_buf()),
            scenes,
            integrators,
        }
    }
}

/// Budgets must be positive, finite and at most a day.
pub fn check_budgets(budgets: &[f64]) -> Result<(), SuiteError> {
    if budgets.is_empty() {
        return Err(SuiteError::rule("no time budgets"));
    }
    for &b in budgets {
        if !(b.is_finite() && b > 0.0 && b <= 86_400.0) {
            return Err(SuiteError::rule(format!(
                "time budget {b}: expected a positive number of seconds (at most 86400)"
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
