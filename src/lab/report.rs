//! What the lab measured, and the files that present it: `results.json`, the convergence plot
//! (SVG + PNG) and a self-contained `index.html` that links every image relatively, so the
//! output directory can be moved or published as is.

use super::figures::Figure;
use crate::image::io::write_bytes_atomic;
use crate::image::plot::convergence_plot;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// Name of the JSON results file.
pub const RESULTS_JSON: &str = "results.json";
/// Name of the HTML report.
pub const INDEX_HTML: &str = "index.html";
/// Stem of the convergence plot files (`.svg`, `.png`).
pub const CONVERGENCE_STEM: &str = "convergence";

/// Where a scene's reference came from.
#[derive(Clone, Debug, Serialize)]
pub struct ReferenceInfo {
    /// Scene name or path.
    pub scene: String,
    /// `file` (given by --reference), `cache` (found in the output directory) or `rendered`.
    pub source: String,
    /// File name (relative to the output directory) or the given path.
    pub path: String,
    /// Eye rays per pixel when rendered by the lab (MIS).
    pub spp: Option<u32>,
    /// Render time in seconds (0 when not rendered in this run).
    pub time_s: f64,
    /// Fraction of its pixels away from edges (used by the smooth relMSE).
    pub smooth_fraction: f64,
    /// Light selection of a rendered reference (empty for a given file).
    pub light_selection: String,
}

/// One rendered panel and its measurements.
#[derive(Clone, Debug, Serialize)]
pub struct PanelResult {
    /// Figure id.
    pub figure: String,
    /// Panel label.
    pub label: String,
    /// Estimator name.
    pub strategy: String,
    /// Sample pattern name.
    pub pattern: String,
    /// Light selection name.
    pub light_selection: String,
    /// Lobe sampling, when the panel sets one.
    pub lobe: Option<String>,
    /// Eye rays per pixel (N).
    pub spp: u32,
    /// Shadow (or BSDF) rays per eye ray (M).
    pub shadow_rays: u32,
    /// Wall time of the render loop in seconds.
    pub time_s: f64,
    /// Rays traced.
    pub rays: u64,
    /// relMSE against the scene's reference.
    pub rel_mse: f64,
    /// relMSE over pixels away from edges (see `lab::mask`): the light-sampling noise.
    pub smooth_rel_mse: f64,
    /// MSE against the scene's reference.
    pub mse: f64,
    /// EXR file name.
    pub exr: String,
    /// PNG file name.
    pub png: String,
    /// False-colour relMSE map file name.
    pub error_png: String,
}

impl PanelResult {
    /// The montage label: strategy, N × M, time, relMSE (one per line).
    pub fn montage_label(&self) -> String {
        // The strategy gets its own line when the label names something else (pattern,
        // lobe, selector), so cells stay narrow.
        let what = if self.label == self.strategy {
            self.label.clone()
        } else {
            format!("{}\n{}", self.label, self.strategy)
        };
        format!(
            "{what}\n{} × {}\n{}\nrelMSE {:.2e}\nsmooth {:.2e}",
            self.spp,
            self.shadow_rays,
            format_seconds(self.time_s),
            self.rel_mse,
            self.smooth_rel_mse
        )
    }
}

/// Seconds with a precision that suits their size.
fn format_seconds(s: f64) -> String {
    if s < 10.0 {
        format!("{s:.3} s")
    } else {
        format!("{s:.1} s")
    }
}

/// One figure's outcome.
#[derive(Clone, Debug, Serialize)]
pub struct FigureResult {
    /// Figure id.
    pub id: String,
    /// Title.
    pub title: String,
    /// The lecture's claim.
    pub claim: String,
    /// Scene rendered (empty when the figure was skipped).
    pub scene: String,
    /// Montage file name, if any panel was rendered.
    pub montage: Option<String>,
    /// Rendered panels.
    pub panels: Vec<PanelResult>,
    /// Why panels (or the whole figure) were skipped.
    pub skipped: Vec<String>,
}

impl FigureResult {
    /// A figure with no panels, skipped for `why`.
    pub fn skipped(fig: &Figure, why: String) -> Self {
        Self {
            id: fig.id.to_string(),
            title: fig.title.to_string(),
            claim: fig.claim.to_string(),
            scene: String::new(),
            montage: None,
            panels: Vec::new(),
            skipped: vec![why],
        }
    }
}

/// One point of a convergence curve.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ConvergencePoint {
    /// Eye rays per pixel (one light and/or BSDF sample each).
    pub spp: u32,
    /// Wall time in seconds.
    pub time_s: f64,
    /// relMSE against the reference.
    pub rel_mse: f64,
    /// relMSE over pixels away from edges.
    pub smooth_rel_mse: f64,
}

/// The convergence curve of one estimator.
#[derive(Clone, Debug, Serialize)]
pub struct ConvergenceSeries {
    /// Estimator name.
    pub strategy: String,
    /// Points at doubling spp.
    pub points: Vec<ConvergencePoint>,
}

/// Everything the lab measured (serialised as `results.json`).
#[derive(Clone, Debug, Serialize)]
pub struct LabResults {
    /// Main scene.
    pub scene: String,
    /// Resolution of every image.
    pub resolution: [u32; 2],
    /// Seed of every panel.
    pub seed: u64,
    /// The references used, one per scene.
    pub references: Vec<ReferenceInfo>,
    /// Figures in order.
    pub figures: Vec<FigureResult>,
    /// Convergence curves of the four estimators on the main scene.
    pub convergence: Vec<ConvergenceSeries>,
    /// Convergence plot SVG file name.
    pub convergence_svg: Option<String>,
    /// Convergence plot PNG file name.
    pub convergence_png: Option<String>,
    /// Skipped work and loader warnings.
    pub notes: Vec<String>,
    /// Wall time of the whole lab in seconds.
    pub total_time_s: f64,
}

/// Draw the convergence plot into `out` and record its file names in `results`.
pub fn write_convergence_plot(out: &Path, results: &mut LabResults) -> anyhow::Result<()> {
    let series: Vec<(String, Vec<(f64, f64)>)> = results
        .convergence
        .iter()
        .map(|s| {
            let pts = s.points.iter().map(|p| (p.time_s, p.rel_mse)).collect();
            (s.strategy.clone(), pts)
        })
        .collect();
    let svg = format!("{CONVERGENCE_STEM}.svg");
    let png = format!("{CONVERGENCE_STEM}.png");
    let title = format!(
        "{}: relMSE vs time ({}x{}, spp 1..{})",
        results.scene,
        results.resolution[0],
        results.resolution[1],
        results
            .convergence
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.spp))
            .max()
            .unwrap_or(0)
    );
    convergence_plot(&series, &title, &out.join(&svg), &out.join(&png))?;
    results.convergence_svg = Some(svg);
    results.convergence_png = Some(png);
    Ok(())
}

/// Write `results.json`.
pub fn write_json(out: &Path, results: &LabResults) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(results)?;
    write_bytes_atomic(&out.join(RESULTS_JSON), text.as_bytes())
}

/// Escape text for HTML element content and attribute values.
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            _ => o.push(c),
        }
    }
    o
}

/// The HTML report as a string (no external resources; images linked relatively).
pub fn render_html(r: &LabResults) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>penumbra lab: {scene}</title>\n<style>\
         body{{font-family:sans-serif;margin:2em;max-width:1200px}}\
         table{{border-collapse:collapse;margin:1em 0}}\
         td,th{{border:1px solid #bbb;padding:4px 8px;text-align:right}}\
         td:first-child,th:first-child{{text-align:left}}\
         img{{max-width:100%;image-rendering:pixelated}}\
         .note{{color:#a40}}</style></head><body>\n\
         <h1>penumbra lab: {scene}</h1>\n<p>{w}×{hh} pixels, seed {seed}, total {t:.1} s. \
         relMSE = mean (x − ref)² / (ref² + 0.01) against the reference; \
         <em>smooth relMSE</em> is the same mean over pixels whose 3×3 reference neighbourhood \
         has no edge: with few eye rays, edge aliasing dominates relMSE and hides the \
         light-sampling noise the figures are about.</p>\n",
        scene = esc(&r.scene),
        w = r.resolution[0],
        hh = r.resolution[1],
        seed = r.seed,
        t = r.total_time_s
    );
    h.push_str("<h2>References</h2>\n<table><tr><th>scene</th><th>source</th><th>spp (MIS)</th><th>smooth pixels</th><th>file</th></tr>\n");
    for re in &r.references {
        let link = if re.source == "file" {
            esc(&re.path)
        } else {
            format!("<a href=\"{0}\">{0}</a>", esc(&re.path))
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.1}%</td><td>{link}</td></tr>",
            esc(&re.scene),
            esc(&re.source),
            re.spp.map(|s| s.to_string()).unwrap_or_else(|| "–".into()),
            100.0 * re.smooth_fraction,
        );
    }
    h.push_str("</table>\n");
    h.push_str(
        "<h2>Results</h2>\n<table><tr><th>figure</th><th>panel</th><th>strategy</th>\
         <th>pattern</th><th>light selection</th><th>N × M</th><th>time [s]</th>\
         <th>relMSE</th><th>smooth relMSE</th><th>images</th></tr>\n",
    );
    for f in &r.figures {
        for p in &f.panels {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{} × {}</td>\
                 <td>{:.3}</td><td>{:.4e}</td><td>{:.4e}</td><td><a href=\"{}\">png</a> <a href=\"{}\">exr</a> \
                 <a href=\"{}\">error</a></td></tr>",
                esc(&f.id),
                esc(&p.label),
                esc(&p.strategy),
                esc(&p.pattern),
                esc(&p.light_selection),
                p.spp,
                p.shadow_rays,
                p.time_s,
                p.rel_mse,
                p.smooth_rel_mse,
                esc(&p.png),
                esc(&p.exr),
                esc(&p.error_png)
            );
        }
    }
    h.push_str("</table>\n");
    for f in &r.figures {
        let _ = writeln!(
            h,
            "<h2>{}: {}</h2>\n<p>{}{}</p>",
            esc(&f.id),
            esc(&f.title),
            esc(&f.claim),
            if f.scene.is_empty() {
                String::new()
            } else {
                format!(" (scene <code>{}</code>)", esc(&f.scene))
            }
        );
        if let Some(m) = &f.montage {
            let _ = writeln!(
                h,
                "<p><img src=\"{0}\" alt=\"{1}\"></p>",
                esc(m),
                esc(&f.title)
            );
        }
        if !f.panels.is_empty() {
            h.push_str("<p>relMSE maps (viridis, log10 −4..1): ");
            for p in &f.panels {
                let _ = write!(
                    h,
                    "<img src=\"{}\" alt=\"error {}\" width=\"160\"> ",
                    esc(&p.error_png),
                    esc(&p.label)
                );
            }
            h.push_str("</p>\n");
        }
        for s in f.skipped.iter().filter(|s| !s.is_empty()) {
            let _ = writeln!(h, "<p class=\"note\">skipped: {}</p>", esc(s));
        }
    }
    if let (Some(png), Some(svg)) = (&r.convergence_png, &r.convergence_svg) {
        let _ = writeln!(
            h,
            "<h2>Convergence</h2>\n<p>relMSE against wall time, spp doubling, one light \
             and/or BSDF sample per eye ray (<a href=\"{1}\">SVG</a>).</p>\n\
             <p><img src=\"{0}\" alt=\"convergence plot\"></p>",
            esc(png),
            esc(svg)
        );
        h.push_str("<table><tr><th>strategy</th>");
        if let Some(s) = r.convergence.first() {
            for p in &s.points {
                let _ = write!(h, "<th>{} spp</th>", p.spp);
            }
        }
        h.push_str("</tr>\n");
        for s in &r.convergence {
            let _ = write!(h, "<tr><td>{}</td>", esc(&s.strategy));
            for p in &s.points {
                let _ = write!(
                    h,
                    "<td>{:.3e}<br>smooth {:.3e}<br>{:.3} s</td>",
                    p.rel_mse, p.smooth_rel_mse, p.time_s
                );
            }
            h.push_str("</tr>\n");
        }
        h.push_str("</table>\n");
    }
    if !r.notes.is_empty() {
        h.push_str("<h2>Notes</h2>\n<ul>\n");
        for n in &r.notes {
            let _ = writeln!(h, "<li>{}</li>", esc(n));
        }
        h.push_str("</ul>\n");
    }
    h.push_str("<p><a href=\"results.json\">results.json</a></p>\n</body></html>\n");
    h
}

/// Write `index.html`.
pub fn write_html(out: &Path, results: &LabResults) -> anyhow::Result<()> {
    write_bytes_atomic(&out.join(INDEX_HTML), render_html(results).as_bytes())
}
