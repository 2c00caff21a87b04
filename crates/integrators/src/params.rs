//! Parsing of `name = value` estimator parameters, shared by the ReSTIR estimators.

use restir_gris::MisScheme;

use crate::restir_di::MIS_NAMES;

/// A whole number from `min` to 2^20.
pub(crate) fn parse_count(name: &str, v: &str, min: u32) -> Result<u32, String> {
    let n: u32 = v
        .parse()
        .map_err(|_| format!("{name} = '{v}': expected a whole number"))?;
    if n < min || n > 1 << 20 {
        return Err(format!(
            "{name} = {n}: expected a number from {min} to {}",
            1 << 20
        ));
    }
    Ok(n)
}

pub(crate) fn parse_positive(name: &str, v: &str) -> Result<f32, String> {
    let x: f32 = v
        .parse()
        .map_err(|_| format!("{name} = '{v}': expected a number"))?;
    if !(x > 0.0 && x.is_finite()) {
        return Err(format!("{name} = {v}: expected a positive finite number"));
    }
    Ok(x)
}

pub(crate) fn parse_bool(name: &str, v: &str) -> Result<bool, String> {
    match v.to_ascii_lowercase().as_str() {
        "true" | "1" | "yes" | "on" => Ok(true),
        "false" | "0" | "no" | "off" => Ok(false),
        _ => Err(format!("{name} = '{v}': expected true or false")),
    }
}

/// One of [`MIS_NAMES`] (`-` and `_` are the same).
pub(crate) fn parse_mis(name: &str, v: &str) -> Result<MisScheme, String> {
    MIS_NAMES
        .iter()
        .find(|(n, _)| n.replace('-', "_") == v.to_ascii_lowercase().replace('-', "_"))
        .map(|(_, s)| *s)
        .ok_or_else(|| {
            format!(
                "{name} = '{v}': expected one of {}",
                MIS_NAMES
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
}
