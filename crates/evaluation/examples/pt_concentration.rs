//! Where ReSTIR PT's squared error concentrates: classifies the pixels that hold the top 1 % of
//! an image's squared error by how the path of their brightest pass reached them.
//!
//! ```text
//! RESTIR_PT_DIAG=diag.csv restir render SCENE --integrator restir-pt --fallback off --spp N -o img.exr
//! cargo run --release -p restir-evaluation --example pt_concentration -- diag.csv img.exr ref.exr [other.exr]
//! ```
//!
//! With a fourth image (another estimator at the same passes, the path tracer's), it also says
//! how that image's squared error compares on the same pixels. It writes `img.top1.png`, the
//! image with the top 1 % painted magenta.
//!
//! `diag.csv` is what `RESTIR_PT_DIAG` writes (`crates/integrators/src/restir_pt/diag.rs`). For
//! each property (shift, path kind, which pixel found the path, the Jacobian of the shifts that
//! brought it, the lamp it ends on, its length, the reconnection distance and angle, how much of
//! the pixel its brightest pass is) the table gives the share of all pixels and the share of the
//! top 1 %'s squared error in each class.

use std::collections::BTreeMap;
use std::path::Path;

use restir_evaluation::metrics::{squared_errors, top_share};
use restir_image::Image;

/// One row of the diagnostic CSV, by column name.
struct Row(BTreeMap<String, String>);

impl Row {
    fn s(&self, k: &str) -> &str {
        self.0.get(k).map_or("", String::as_str)
    }
    fn f(&self, k: &str) -> f64 {
        self.s(k).parse().unwrap_or(f64::NAN)
    }
}

fn bin(v: f64, edges: &[(f64, &'static str)], nan: &'static str) -> &'static str {
    if v.is_nan() {
        return nan;
    }
    for &(e, name) in edges {
        if v < e {
            return name;
        }
    }
    "above"
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (diag, image, reference, other) = match args.as_slice() {
        [d, i, r] => (d, i, r, None),
        [d, i, r, o] => (d, i, r, Some(o)),
        _ => {
            return Err(
                "usage: pt_concentration DIAG.csv IMAGE.exr REFERENCE.exr [OTHER.exr]".into(),
            );
        }
    };
    let text = std::fs::read_to_string(diag).map_err(|e| format!("{diag}: {e}"))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or(format!("{diag}: empty"))?
        .split(',')
        .map(String::from)
        .collect();
    let rows: Vec<Row> = lines
        .map(|l| {
            Row(header
                .iter()
                .cloned()
                .zip(l.split(',').map(String::from))
                .collect())
        })
        .collect();
    let read = |p: &str| Image::read_exr(Path::new(p)).map_err(|e| format!("{p}: {e}"));
    let (img, r) = (read(image)?, read(reference)?);
    let errors = squared_errors(&img, &r).ok_or("the image and the reference differ in size")?;
    if errors.len() != rows.len() {
        return Err(format!(
            "{diag}: {} pixels, the image {}",
            rows.len(),
            errors.len()
        ));
    }
    let mut order: Vec<usize> = (0..errors.len())
        .filter(|&i| errors[i].is_finite())
        .collect();
    order.sort_by(|&a, &b| errors[b].total_cmp(&errors[a]));
    let total: f64 = order.iter().map(|&i| errors[i]).sum();
    let n = (order.len() as f64 * 0.01).ceil() as usize;
    let top = &order[..n];
    let top_total: f64 = top.iter().map(|&i| errors[i]).sum();
    let lum = |p: glam::Vec3| 0.2126 * p.x + 0.7152 * p.y + 0.0722 * p.z;
    let brighter: f64 = top
        .iter()
        .filter(|&&i| lum(img.pixels[i]) > lum(r.pixels[i]))
        .map(|&i| errors[i])
        .sum();
    println!(
        "{image}: MSE {:.4e}, top 1 % ({n} pixels) hold {:.1} % of the squared error ({:.1} % of it \
         in pixels brighter than the reference)",
        total / order.len() as f64,
        100.0 * top_share(&errors, 0.01),
        100.0 * brighter / top_total
    );
    if let Some(o) = other {
        let oe = squared_errors(&read(o)?, &r).ok_or("the other image differs in size")?;
        let on_top: f64 = top.iter().map(|&i| oe[i]).sum();
        let o_total: f64 = order.iter().map(|&i| oe[i]).sum();
        println!(
            "{o} on the same pixels: squared error {:.3}× this image's there, {:.3}× elsewhere; \
             its own top 1 % share {:.1} %",
            on_top / top_total,
            (o_total - on_top) / (total - top_total),
            100.0 * top_share(&oe, 0.01)
        );
    }
    let mut marked = img.clone();
    for &i in top {
        marked.pixels[i] = glam::Vec3::new(1.0, 0.0, 1.0);
    }
    let png = image.trim_end_matches(".exr").to_string() + ".top1.png";
    marked
        .write(Path::new(&png))
        .map_err(|e| format!("{png}: {e}"))?;
    type Classify = fn(&Row) -> String;
    let props: [(&str, Classify); 11] = [
        ("camera sees an emitter", |r| {
            let (seen, passes) = (r.f("seen_passes"), r.f("passes"));
            if seen == 0.0 {
                "in no pass".into()
            } else if seen == passes {
                "in every pass".into()
            } else {
                "in some passes (its silhouette)".into()
            }
        }),
        ("shift", |r| r.s("shift").to_string()),
        ("kind", |r| r.s("kind").to_string()),
        ("found by", |r| match (r.s("origin_dx"), r.s("origin_dy")) {
            ("", _) => "not found".into(),
            ("0", "0") => "the pixel itself".into(),
            _ => "a neighbour".into(),
        }),
        ("Jacobian of the shifts", |r| {
            bin(
                r.f("jacobian"),
                &[
                    (0.1, "< 0.1"),
                    (0.5, "0.1–0.5"),
                    (0.999, "0.5–1"),
                    (1.001, "1"),
                    (2.0, "1–2"),
                    (10.0, "2–10"),
                ],
                "n/a",
            )
            .replace("above", "> 10")
        }),
        ("light at x_k (size / scene radius)", |r| {
            if r.s("shift").is_empty() {
                return "none".into();
            }
            bin(
                r.f("lamp"),
                &[
                    (1e-9, "point light"),
                    (0.01, "lamp < 0.01"),
                    (0.05, "lamp 0.01–0.05"),
                    (0.2, "lamp 0.05–0.2"),
                    (f64::INFINITY, "lamp ≥ 0.2"),
                ],
                "path continues past x_k",
            )
            .replace("above", "environment")
        }),
        ("length (segments)", |r| match r.s("length") {
            "" => "none".into(),
            l if l.parse::<u32>().unwrap_or(0) >= 5 => "5+".into(),
            l => l.into(),
        }),
        ("reconnection distance / scene radius (k = 2)", |r| {
            bin(
                r.f("distance"),
                &[
                    (0.02, "< 0.02"),
                    (0.05, "0.02–0.05"),
                    (0.1, "0.05–0.1"),
                    (0.3, "0.1–0.3"),
                ],
                "n/a",
            )
            .replace("above", "≥ 0.3")
        }),
        ("|cos| at x2 (k = 2)", |r| {
            bin(
                r.f("cos"),
                &[(0.1, "< 0.1"), (0.3, "0.1–0.3"), (0.6, "0.3–0.6")],
                "n/a",
            )
            .replace("above", "≥ 0.6")
        }),
        ("brightest pass's share of the pixel", |r| {
            let share = r.f("max") / (r.f("mean") * r.f("passes"));
            bin(
                share,
                &[(0.1, "< 10 %"), (0.3, "10–30 %"), (0.6, "30–60 %")],
                "n/a",
            )
            .replace("above", "≥ 60 %")
        }),
        ("brightest pass over the path's value where found", |r| {
            bin(
                r.f("max") / r.f("origin_value"),
                &[(0.5, "< 0.5"), (2.0, "0.5–2"), (10.0, "2–10")],
                "n/a",
            )
            .replace("above", "> 10")
        }),
    ];
    for (name, classify) in props {
        let mut classes: BTreeMap<String, (usize, f64)> = BTreeMap::new();
        for &i in &order {
            classes.entry(classify(&rows[i])).or_default().0 += 1;
        }
        for &i in top {
            classes.entry(classify(&rows[i])).or_default().1 += errors[i];
        }
        println!("\n| {name} | share of pixels | share of the top 1 %'s squared error |");
        println!("|---|---|---|");
        for (c, (count, e)) in classes {
            println!(
                "| {c} | {:.1} % | {:.1} % |",
                100.0 * count as f64 / order.len() as f64,
                100.0 * e / top_total
            );
        }
    }
    Ok(())
}
