//! The XML file being read: its path, where each node sits (for `file:line` in messages), the
//! `<default>` variables that `$name` in attributes refers to, and the warnings collected so far.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::Path;

use roxmltree::{Document, Node};

use super::{Result, snake_case};
use crate::{Location, SceneError, SceneWarning};

/// One XML scene file while it is imported.
pub(super) struct Source<'a, 'i> {
    /// The scene file (named in every message).
    pub(super) file: &'a Path,
    doc: &'a Document<'i>,
    /// `<default>` variables (the command line's `-D` included).
    pub(super) defaults: HashMap<String, String>,
    /// Warnings so far, in file order.
    pub(super) warnings: RefCell<Vec<SceneWarning>>,
}

impl<'a, 'i> Source<'a, 'i> {
    /// A source for `doc`, parsed from `file`, with no variables yet.
    pub(super) fn new(file: &'a Path, doc: &'a Document<'i>) -> Self {
        Self {
            file,
            doc,
            defaults: HashMap::new(),
            warnings: RefCell::new(Vec::new()),
        }
    }

    /// Where `node` starts.
    pub(super) fn loc(&self, node: Node) -> Location {
        Location {
            file: self.file.to_path_buf(),
            line: self.doc.text_pos_at(node.range().start).row,
        }
    }

    /// An error at `node`.
    pub(super) fn err(&self, node: Node, msg: impl Into<String>) -> SceneError {
        SceneError::new(self.loc(node), msg)
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
