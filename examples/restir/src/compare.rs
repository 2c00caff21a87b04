//! The `compare` command: error metrics of an image against a reference, and the comparison
//! page.

use std::path::Path;

use restir_image::Image;

use crate::say::{say, say_err};

/// `restir compare`: the metrics of `test` against `reference` on stdout, and with `html` an
/// interactive comparison page.
pub(crate) fn run(test: &Path, reference: &Path, html: Option<&Path>) -> Result<(), String> {
    if let Some(out) = html {
        if let Some(input) = [test, reference]
            .into_iter()
            .find(|i| restir_image::same_destination(out, i))
        {
            return Err(format!(
                "--html {}: the same file as the input {}",
                out.display(),
                input.display()
            ));
        }
        restir_image::check_writable(out).map_err(|e| e.to_string())?;
    }
    // Sizes from the headers first: images that cannot be compared are refused before either
    // is decoded (a small file may claim a large image).
    let size = |p: &Path| Image::read_dimensions(p).map_err(|e| e.to_string());
    let (ts, rs) = (size(test)?, size(reference)?);
    if ts != rs {
        return Err(format!(
            "{}: size {}×{} differs from the reference's {}×{}",
            test.display(),
            ts.0,
            ts.1,
            rs.0,
            rs.1
        ));
    }
    let t = Image::read_exr(test).map_err(|e| e.to_string())?;
    let r = Image::read_exr(reference).map_err(|e| e.to_string())?;
    let m = restir_evaluation::metrics::evaluate(&t, &r).ok_or_else(|| {
        format!(
            "{}: size {}×{} differs from the reference's {}×{}",
            test.display(),
            t.width,
            t.height,
            r.width,
            r.height
        )
    })?;
    if m.mse.is_nan() {
        return Err(format!(
            "{} against {}: no pixel is finite in both ({} NaN or infinite in the image, {} in the reference)",
            test.display(),
            reference.display(),
            m.nonfinite,
            m.reference_nonfinite
        ));
    }
    for (n, which) in [(m.nonfinite, test), (m.reference_nonfinite, reference)] {
        if n > 0 {
            say_err!(
                "warning: {}: {n} pixels are NaN or infinite (left out of every metric)",
                which.display()
            );
        }
    }
    if let Some(out) = html {
        let name = |p: &Path| {
            p.file_name()
                .map_or(p.display().to_string(), |n| n.to_string_lossy().into())
        };
        let page = restir_evaluation::html::compare_page(&name(test), &t, &name(reference), &r)
            .map_err(|e| e.to_string())?;
        restir_image::write_file_atomically(out, page.as_bytes()).map_err(|e| e.to_string())?;
    }
    say!(
        "relmse={:.6e} mse={:.6e} mean_ratio={:.6} nonfinite={} reference_nonfinite={} mape={:.6e} flip={:.6} top1_share={:.4}",
        m.relmse,
        m.mse,
        m.mean_ratio,
        m.nonfinite,
        m.reference_nonfinite,
        m.mape,
        m.flip,
        m.top1_share
    );
    Ok(())
}
