//! The XML file being read: its path, where each node sits (for `file:line` in messages), the
//! `<default>` variables that `$name` in attributes refers to, and the warnings collected so far.
//!
//! Lines come from a [`LineIndex`] built once per file (the start of every line), so finding a
//! node's line is a binary search rather than a scan from the start of the file.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::Path;

use roxmltree::Node;

use super::{Result, snake_case};
use crate::desc::limits;
use crate::{Location, SceneError, SceneWarning};

/// One XML scene file while it is imported.
pub(super) struct Source<'a> {
    /// The scene file (named in every message).
    pub(super) file: &'a Path,
    lines: LineIndex,
    /// `<default>` variables (the command line's `-D` included).
    pub(super) defaults: HashMap<String, String>,
    /// Warnings so far, in file order.
    pub(super) warnings: RefCell<Vec<SceneWarning>>,
}

impl<'a> Source<'a> {
    /// A source for `text`, read from `file`, with no variables yet.
    pub(super) fn new(file: &'a Path, text: &str) -> Self {
        Self {
            file,
            lines: LineIndex::new(text),
            defaults: HashMap::new(),
            warnings: RefCell::new(Vec::new()),
        }
    }

    /// Where `node` starts.
    pub(super) fn loc(&self, node: Node) -> Location {
        Location {
            file: self.file.to_path_buf(),
            line: self.lines.line(node.range().start),
        }
    }

    /// An error at `node`.
    pub(super) fn err(&self, node: Node, msg: impl Into<String>) -> SceneError {
        SceneError::new(self.loc(node), msg)
    }

    /// "unknown `family` type 'ty' (known: a, b, …)", at `node`.
    pub(super) fn unknown_type(
        &self,
        node: Node,
        family: &str,
        ty: &str,
        known: &[&str],
    ) -> SceneError {
        self.err(
            node,
            format!("unknown {family} type '{ty}' (known: {})", known.join(", ")),
        )
    }

    /// Records a warning at `node`.
    pub(super) fn warn(&self, node: Node, msg: impl Into<String>) {
        let location = self.loc(node);
        self.warnings.borrow_mut().push(SceneWarning {
            location,
            message: msg.into(),
        });
    }

    /// Replaces `$name` references with `<default>` values.
    pub(super) fn subst(&self, node: Node, s: &str) -> Result<String> {
        if !s.contains('$') {
            return Ok(s.to_string());
        }
        let mut out = String::new();
        let mut rest = s;
        while let Some(pos) = rest.find('$') {
            out.push_str(&rest[..pos]);
            let after = &rest[pos + 1..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..len];
            if name.is_empty() {
                return Err(self.err(node, format!("'$' without a variable name in \"{s}\"")));
            }
            let value = self.defaults.get(name).ok_or_else(|| {
                self.err(
                    node,
                    format!("undefined variable ${name} (declare it with <default name=\"{name}\" value=\"…\"/> or -D {name}=…)"),
                )
            })?;
            out.push_str(value);
            if out.len() > limits::MAX_SUBSTITUTED_BYTES {
                return Err(self.err(
                    node,
                    format!(
                        "the value grows beyond {} bytes through <default> substitution",
                        limits::MAX_SUBSTITUTED_BYTES
                    ),
                ));
            }
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(out)
    }

    /// Attribute `name` of `node` with variables substituted, if present.
    pub(super) fn attr(&self, node: Node, name: &str) -> Result<Option<String>> {
        match node.attribute(name) {
            Some(v) => Ok(Some(self.subst(node, v)?)),
            None => Ok(None),
        }
    }

    /// Attribute `name` of `node`, which must be present.
    pub(super) fn req_attr(&self, node: Node, name: &str) -> Result<String> {
        self.attr(node, name)?.ok_or_else(|| {
            self.err(
                node,
                format!("<{}> needs a '{name}' attribute", node.tag_name().name()),
            )
        })
    }

    /// A plugin element's `type`, in snake_case.
    pub(super) fn plugin_type(&self, node: Node) -> Result<String> {
        Ok(snake_case(&self.req_attr(node, "type")?))
    }
}

/// The byte offsets at which the lines of a text start, for turning offsets into line numbers.
pub(super) struct LineIndex {
    /// Offsets of the `\n` bytes.
    newlines: Vec<usize>,
}

impl LineIndex {
    /// Indexes `text` (one pass over its bytes).
    pub(super) fn new(text: &str) -> Self {
        Self {
            newlines: text
                .bytes()
                .enumerate()
                .filter_map(|(i, b)| (b == b'\n').then_some(i))
                .collect(),
        }
    }

    /// The 1-based line holding byte `offset`: one more than the number of line breaks before
    /// it, as `roxmltree::Document::text_pos_at` counts.
    pub(super) fn line(&self, offset: usize) -> u32 {
        (self.newlines.partition_point(|&nl| nl < offset) + 1) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::LineIndex;

    #[test]
    fn lines_agree_with_roxmltree() {
        let text = "<scene>\n  <a/>\n\n\r\n<b>ü\n</b>\n</scene>";
        let doc = roxmltree::Document::parse(text).unwrap();
        let index = LineIndex::new(text);
        for offset in 0..=text.len() + 3 {
            if text.is_char_boundary(offset.min(text.len())) {
                assert_eq!(
                    index.line(offset),
                    doc.text_pos_at(offset).row,
                    "offset {offset}"
                );
            }
        }
    }

    #[test]
    fn a_text_without_line_breaks_is_line_one() {
        let index = LineIndex::new("<scene/>");
        assert_eq!(index.line(0), 1);
        assert_eq!(index.line(100), 1);
        assert_eq!(LineIndex::new("").line(0), 1);
    }
}
