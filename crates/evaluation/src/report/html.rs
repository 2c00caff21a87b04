//! The interactive comparison page (`report.html` of `restir bench`, `restir compare --html`),
//! in the style of the viewers rendering papers publish: the reference and every image, a split
//! view between any two, zoom with pixel inspection, exposure, false-colour relative-error and
//! FLIP maps, a metrics table and the error-versus-time plot.
//!
//! The page is one self-contained file: the template, style and script are the crate's
//! `assets/report.{html,css,js}` (compiled in with `include_str!`), and the data is one JSON
//! object in the page. Each image travels as its linear RGB in float16 (little-endian),
//! zlib-compressed and base64-encoded; the browser inflates it (`DecompressionStream`), tone-maps
//! it at the chosen exposure (clamp, sRGB) and computes the relative-error map against the
//! reference itself. FLIP maps (computed here, see [`crate::metrics`]) travel as 8-bit values;
//! both error maps use FLIP's magma colour map. Noisy renders barely compress: a 128×128 image
//! costs about 120 KB of page, a 320×240 one about 570 KB.

use std::fmt;
use std::io::Write as _;

use restir_image::{Image, compare};
use serde_json::{Value, json};

use crate::analysis::{sequence_runs, summarize};
use crate::measure::utc;
use crate::metrics::{flip_map, mape, mean};
use crate::records::{BenchResults, RunRecord};

const TEMPLATE: &str = include_str!("../../assets/report.html");
const STYLE: &str = include_str!("../../assets/report.css");
const SCRIPT: &str = include_str!("../../assets/report.js");

/// One image of a page besides the reference.
#[derive(Clone, Debug)]
pub struct PageImage<'a> {
    /// Its name (a configuration label, a file name).
    pub label: String,
    /// The time budget it was rendered with, if any.
    pub budget: Option<f64>,
    /// Render seconds, if known.
    pub seconds: Option<f64>,
    /// Passes, if known.
    pub passes: Option<u32>,
    /// The image (the size of the scene's reference).
    pub image: &'a Image,
}

/// One curve of the error-versus-time plot.
#[derive(Clone, Debug)]
pub struct PlotSeries {
    /// Legend text (the configuration label of its images).
    pub label: String,
    /// Per budget: `[median seconds, median relMSE, min relMSE, max relMSE, median MAPE, median
    /// FLIP, budget]`.
    pub medians: Vec<[f64; 7]>,
    /// Every run: `[seconds, relMSE, MAPE, FLIP]`.
    pub points: Vec<[f64; 4]>,
}

/// The error-versus-time plot of a scene.
#[derive(Clone, Debug)]
pub struct PagePlot {
    /// One curve per configuration.
    pub series: Vec<PlotSeries>,
    /// The reference's own relMSE, drawn as a horizontal line when known.
    pub noise: Option<f64>,
}

/// A scene of a page: a reference, images compared with it, optionally a plot.
#[derive(Clone, Debug)]
pub struct PageScene<'a> {
    /// Its name (the tab's text).
    pub name: String,
    /// A sentence about the scene and its reference, shown above the viewer.
    pub note: String,
    /// The reference's name.
    pub reference_label: String,
    /// The reference.
    pub reference: &'a Image,
    /// The other images.
    pub images: Vec<PageImage<'a>>,
    /// The plot, if any.
    pub plot: Option<PagePlot>,
}

/// Why a page cannot be made.
#[derive(Clone, Debug, PartialEq)]
pub enum PageError {
    /// An image is not the size of its scene's reference.
    Size {
        /// The scene.
        scene: String,
        /// The image.
        label: String,
        /// Its size.
        size: (u32, u32),
        /// The reference's.
        reference: (u32, u32),
    },
}

impl fmt::Display for PageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Size {
                scene,
                label,
                size,
                reference,
            } => write!(
                f,
                "{scene}: image '{label}' is {}×{}, the reference {}×{}",
                size.0, size.1, reference.0, reference.1
            ),
        }
    }
}

impl std::error::Error for PageError {}

/// Standard base64 with padding.
pub fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ABC[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

fn zlib(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    // Writing into a Vec cannot fail.
    e.write_all(bytes).expect("in-memory write");
    e.finish().expect("in-memory write")
}

/// The image's RGB as little-endian float16, zlib-compressed, base64-encoded.
fn hdr_f16(image: &Image) -> String {
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(|c| half::f16::from_f32(c).to_bits().to_le_bytes())
        .collect();
    base64(&zlib(&bytes))
}

/// `<`, `>` and `&` escaped for HTML text.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn image_json(
    scene: &PageScene,
    label: &str,
    image: &Image,
    extra: Option<&PageImage>,
) -> Result<Value, PageError> {
    let r = scene.reference;
    if (image.width, image.height) != (r.width, r.height) {
        return Err(PageError::Size {
            scene: scene.name.clone(),
            label: label.to_string(),
            size: (image.width, image.height),
            reference: (r.width, r.height),
        });
    }
    let mut v = json!({ "label": label, "hdr_f16": hdr_f16(image) });
    if let Some(p) = extra {
        let m = compare(image, r).expect("sizes checked");
        let map = flip_map(image, r).unwrap_or_default();
        let flip8: Vec<u8> = map
            .iter()
            .map(|&x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
            .collect();
        v["budget"] = json!(p.budget);
        v["seconds"] = json!(p.seconds);
        v["passes"] = json!(p.passes);
        v["relmse"] = json!(m.relmse);
        v["mape"] = json!(mape(image, r));
        v["flip"] = json!(if map.is_empty() { f64::NAN } else { mean(&map) });
        v["mean_ratio"] = json!(m.mean_ratio);
        v["flip_u8"] = json!(base64(&zlib(&flip8)));
    }
    Ok(v)
}

/// The page: `title` as its heading, `intro` (plain text) below it, one tab per scene.
pub fn page(title: &str, intro: &str, scenes: &[PageScene]) -> Result<String, PageError> {
    let mut out = Vec::new();
    for s in scenes {
        let mut images = vec![image_json(s, &s.reference_label, s.reference, None)?];
        for p in &s.images {
            images.push(image_json(s, &p.label, p.image, Some(p))?);
        }
        let plot = s.plot.as_ref().map(|p| {
            json!({
                "noise": p.noise,
                "series": p.series.iter().map(|q| json!({
                    "label": q.label, "medians": q.medians, "points": q.points,
                })).collect::<Vec<_>>(),
            })
        });
        out.push(json!({
            "name": s.name, "note": s.note,
            "width": s.reference.width, "height": s.reference.height,
            "images": images, "plot": plot,
        }));
    }
    let colormap = nv_flip::magma_lut().to_vec();
    let data = json!({ "scenes": out, "colormap": base64(&colormap) });
    // Inside <script>, "</script>" must not appear: '<' only occurs inside JSON strings, where
    // the escape \u003c means the same.
    let data = data.to_string().replace('<', "\\u003c");
    Ok(TEMPLATE
        .replace("__RESTIR_TITLE__", &escape(title))
        .replace("__RESTIR_INTRO__", &escape(intro))
        .replace("__RESTIR_STYLE__", STYLE)
        .replace("__RESTIR_SCRIPT__", SCRIPT)
        .replace("__RESTIR_DATA__", &data))
}

/// `restir compare TEST REFERENCE --html`: one scene, the test image against the reference.
pub fn compare_page(
    test_name: &str,
    test: &Image,
    reference_name: &str,
    reference: &Image,
) -> Result<String, PageError> {
    let scene = PageScene {
        name: test_name.to_string(),
        note: format!(
            "{test_name} ({}×{}) against the reference {reference_name}.",
            test.width, test.height
        ),
        reference_label: format!("reference: {reference_name}"),
        reference,
        images: vec![PageImage {
            label: test_name.to_string(),
            budget: None,
            seconds: None,
            passes: None,
            image: test,
        }],
        plot: None,
    };
    page(
        &format!("restir compare: {test_name}"),
        "Made by `restir compare --html`.",
        &[scene],
    )
}

/// The bench report's page: per scene the reference and seed 0 of every configuration at every
/// budget, and the error-versus-time plot over all seeds.
pub fn bench_page(results: &BenchResults) -> Result<String, PageError> {
    let summaries = summarize(results);
    let runs = sequence_runs(&results.records);
    let mut scenes = Vec::new();
    for (info, imgs) in results.references.iter().zip(&results.images) {
        let records: Vec<&RunRecord> = runs.iter().filter(|r| r.scene == info.scene).collect();
        let seed0 = |label: &str, budget: f64| {
            records
                .iter()
                .find(|r| r.label == label && r.budget == budget && r.seed == 0)
        };
        let images = imgs
            .renders
            .iter()
            .map(|(label, budget, image)| PageImage {
                label: label.clone(),
                budget: Some(*budget),
                seconds: seed0(label, *budget).map(|r| r.seconds),
                passes: seed0(label, *budget).map(|r| r.passes),
                image,
            })
            .collect();
        let series = results
            .suite
            .integrators
            .iter()
            .map(|c| PlotSeries {
                label: c.label.clone(),
                medians: summaries
                    .iter()
                    .filter(|x| x.scene == info.scene && x.label == c.label)
                    .map(|x| {
                        [
                            x.seconds,
                            x.relmse,
                            x.relmse_min,
                            x.relmse_max,
                            x.mape,
                            x.flip,
                            x.budget,
                        ]
                    })
                    .collect(),
                points: records
                    .iter()
                    .filter(|x| x.label == c.label)
                    .map(|x| [x.seconds, x.relmse, x.mape, x.flip])
                    .collect(),
            })
            .filter(|s| !s.points.is_empty())
            .collect();
        let reference = match (info.spp, info.noise_relmse) {
            (Some(spp), Some(n)) => {
                format!("path tracer, {spp} passes, its own relMSE ≈ {n:.2e}")
            }
            _ => format!("{} (given)", info.path.display()),
        };
        let (w, h) = (imgs.reference.width, imgs.reference.height);
        let frames = results
            .suite
            .scenes
            .iter()
            .find(|e| e.display_name() == info.scene)
            .and_then(|e| e.frames);
        scenes.push(PageScene {
            name: info.scene.clone(),
            note: match frames {
                None => format!(
                    "{} ({w}×{h}). Reference: {reference}. Images: seed 0 of every \
                     configuration at every budget; the plot has every seed.",
                    info.scene
                ),
                Some((a, b)) => format!(
                    "{} ({w}×{h}), frames {a} to {b}, the budget per frame. Reference of frame \
                     {b}: {reference} (the mean over frames). Images: frame {b} of seed 0 of \
                     every configuration at every budget; the plot has every seed, each \
                     sequence's mean relMSE over its frames against its time per frame.",
                    info.scene
                ),
            },
            reference_label: "reference".into(),
            reference: &imgs.reference,
            images,
            plot: Some(PagePlot {
                series,
                noise: info.noise_relmse,
            }),
        });
    }
    page(
        "restir bench results",
        &format!(
            "Generated by `{}` on {} ({} renders in {:.1} min). Metrics, plots and the tables \
             with every seed: report.md and results.csv beside this page.",
            results.command_line,
            utc(results.started_unix),
            results.records.len(),
            results.wall_seconds / 60.0
        ),
        &scenes,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_known_values() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
        assert_eq!(base64(&[0xff, 0xfe, 0x00]), "//4A");
    }

    #[test]
    fn page_embeds_data_and_escapes() {
        let r = Image::new(4, 2);
        let t = Image::new(4, 2);
        let html = compare_page("a<b>.exr", &t, "ref.exr", &r).unwrap();
        assert!(html.starts_with("<!DOCTYPE html>"));
        assert!(!html.contains("__RESTIR_"), "a placeholder is left");
        assert!(html.contains("<title>restir compare: a&lt;b&gt;.exr</title>"));
        // One </script> per script element: the data cannot close its element early.
        assert_eq!(html.matches("</script>").count(), 2);
        assert!(html.contains("a\\u003cb>.exr"));
        let small = Image::new(2, 2);
        assert_eq!(
            compare_page("s", &small, "r", &r).unwrap_err().to_string(),
            "s: image 's' is 2×2, the reference 4×2"
        );
    }
}
