//! `<integrator>`: the estimator, its depth settings, and the ReSTIR parameters passed through.
//! An unknown type is an error listing the known ones (never a fallback to the path tracer).

use roxmltree::Node;

use super::props::{PROPERTY_TAGS, Value};
use super::{Importer, Result, elements};
use crate::desc::*;

/// The `<integrator>` types the importer reads: Mitsuba's `path`, `volpath` (read as `path`) and
/// `direct` (`path` with max_depth 2), `moment` around one of them, this renderer's estimators
/// under their spellings, and Mitsuba's particle tracer `ptracer`, which is read (its depth
/// settings kept) but which no estimator here is: making it is an error that names the
/// estimators that render the same image, so such a scene renders when one is chosen.
const INTEGRATOR_TYPES: &[&str] = &[
    "path",
    "moment",
    "ptracer",
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
        if ty == "moment" {
            return self.moment(node, desc);
        }
        let props = self.props(node, format!("integrator '{ty}'"))?;
        let mut integ = IntegratorDesc::default();
        let mut keep_params = false;
        match ty.as_str() {
            "path" | "volpath" => integ.kind = "path".into(),
            "ptracer" => integ.kind = "ptracer".into(),
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
        // The sensor's sampler, if it came first, stays.
        integ.sampler = desc.integrator.sampler;
        desc.integrator = integ;
        Ok(())
    }

    /// Mitsuba 3's `moment` integrator: the nested integrator renders the image
    /// (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugins_integrators.html#moment-integrator-moment>).
    /// As Mitsuba, an EXR output also holds each pixel's mean and second moment under the
    /// nested integrator's `name` (Mitsuba's `_arg_0` without one): [`IntegratorDesc::moment`].
    /// Exactly one nested integrator is read.
    fn moment<'i>(&self, node: Node<'a, 'i>, desc: &mut SceneDesc) -> Result<()> {
        let props = self.props(node, "integrator 'moment'".into())?;
        let mut nested = Vec::new();
        for c in elements(node) {
            match c.tag_name().name() {
                "integrator" => nested.push(c),
                t if PROPERTY_TAGS.contains(&t) => {}
                t => {
                    return Err(self.err(
                        c,
                        format!(
                            "integrator 'moment': unexpected <{t}> (it holds one <integrator>)"
                        ),
                    ));
                }
            }
        }
        let inner = match nested.as_slice() {
            [one] => *one,
            [] => return Err(self.err(node, "integrator 'moment' needs a nested <integrator>")),
            [_, second, ..] => {
                return Err(self.err(
                    *second,
                    "integrator 'moment': only one nested <integrator> is supported",
                ));
            }
        };
        props.finish();
        self.integrator(inner, desc)?;
        // Mitsuba names the channels after the nested plugin's `name` attribute, or after its
        // position among the moment's children (the only one: `_arg_0`).
        let name = inner.attribute("name").unwrap_or("_arg_0");
        desc.integrator.moment = Some(name.to_string());
        Ok(())
    }
}
