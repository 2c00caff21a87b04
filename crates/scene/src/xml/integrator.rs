//! `<integrator>`: the estimator, its depth settings, and the ReSTIR parameters passed through.
//! An unknown type is an error listing the known ones (never a fallback to the path tracer).

use roxmltree::Node;

use super::props::Value;
use super::{Importer, Result};
use crate::desc::*;

/// The `<integrator>` types the importer reads: Mitsuba's `path`, `volpath` (read as `path`) and
/// `direct` (`path` with max_depth 2), and this renderer's estimators under their spellings.
const INTEGRATOR_TYPES: &[&str] = &[
    "path",
    "volpath",
    "direct",
    "restir-di",
    "restir_di",
    "restir",
    "restirdi",
    "restir-pt",
    "restir_pt",
    "restirpt",
];

impl<'a> Importer<'a> {
    pub(super) fn integrator<'i>(&self, node: Node<'a, 'i>, desc: &mut SceneDesc) -> Result<()> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("integrator '{ty}'"))?;
        let mut integ = IntegratorDesc::default();
        let mut keep_params = false;
        match ty.as_str() {
            "path" | "volpath" => integ.kind = "path".into(),
            "direct" => {
                integ.kind = "path".into();
                integ.max_depth = 2;
            }
            "restir" | "restir_di" | "restir-di" | "restirdi" => {
                integ.kind = "restir-di".into();
                keep_params = true;
            }
            "restir_pt" | "restir-pt" | "restirpt" => {
                integ.kind = "restir-pt".into();
                keep_params = true;
            }
            other => {
                return Err(self.unknown_type(node, "integrator", other, INTEGRATOR_TYPES));
            }
        }
        if keep_params {
            // Keep every parameter but the common ones for estimators that understand them.
            for p in &props.items {
                if matches!(p.name.as_str(), "max_depth" | "rr_depth" | "hide_emitters") {
                    continue;
                }
                let v = match &p.value {
                    Value::Float(v) => v.to_string(),
                    Value::Int(v) => v.to_string(),
                    Value::Bool(v) => v.to_string(),
                    Value::Str(v) => v.clone(),
                    _ => continue,
                };
                p.used.set(true);
                integ.params.push((p.name.clone(), v));
            }
        }
        if let Some(d) = props.int("max_depth")? {
            if d < -1 {
                return Err(self.err(
                    node,
                    format!("max_depth {d} must be -1 (unbounded) or non-negative"),
                ));
            }
            integ.max_depth = d.min(i32::MAX as i64) as i32;
        }
        if let Some(d) = props.int("rr_depth")? {
            if d <= 0 {
                return Err(self.err(node, format!("rr_depth {d} must be positive")));
            }
            integ.rr_depth = d.min(u32::MAX as i64) as u32;
        }
        if let Some(h) = props.bool("hide_emitters")? {
            integ.hide_emitters = h;
        }
        props.finish();
        integ.location = self.loc(node);
        desc.integrator = integ;
        Ok(())
    }
}
