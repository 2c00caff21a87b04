//! `<integrator>`: the estimator, its depth settings, and the ReSTIR parameters passed through.

use roxmltree::Node;

use super::props::Value;
use super::{Importer, Result};
use crate::desc::*;

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
            "restir" | "restir_di" | "restir-di" => {
                integ.kind = "restir-di".into();
                keep_params = true;
            }
            "restir_pt" | "restir-pt" | "restirpt" => {
                integ.kind = "restir-pt".into();
                keep_params = true;
            }
            other => {
                self.warn(
                    node,
                    format!("unknown integrator type '{other}': using the path tracer"),
                );
                integ.kind = "path".into();
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
