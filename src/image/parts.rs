//! Parts of a render split by sample index, the unit of distribution: a part holds the mean of
//! sample indices `[start, end)` of every pixel of an `spp`-sample render, and its EXR header
//! says which (and of which render). Because every sample is a pure function of (seed, pixel,
//! index, dimension), the parts of a render weighted by their sample counts are the whole
//! render up to float rounding; [`merge`] checks that they tile `0..spp` exactly once.

use std::ops::Range;
use std::path::Path;

use anyhow::{Context, bail};

use super::Image;
use super::io::{WriteControl, read_exr_attributes, read_image, write_image_tagged};
use crate::Rgb;

/// Header attribute: the sample indices of the part, `A..B`.
const ATTR_SAMPLES: &str = "penumbra.samples";
/// Header attribute: the sample count of the part, `B - A`.
const ATTR_COUNT: &str = "penumbra.sampleCount";
/// Header attribute: the samples per pixel of the whole render.
const ATTR_SPP: &str = "penumbra.spp";
/// Header attribute: everything else that decides the image (scene, resolution, seed,
/// estimator...), so that parts of different renders are not merged.
const ATTR_RENDER: &str = "penumbra.render";

/// Which samples of which render an image holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PartInfo {
    /// Sample indices `[start, end)` of every pixel.
    pub samples: Range<u32>,
    /// Samples per pixel of the whole render.
    pub spp: u32,
    /// The render's other settings (opaque; parts merge only when these are equal).
    pub render: String,
}

impl PartInfo {
    /// Samples per pixel in this part.
    pub fn count(&self) -> u32 {
        self.samples.end - self.samples.start
    }
}

/// One part: its image (the mean of its samples) and what it holds.
#[derive(Clone, Debug)]
pub struct Part {
    /// Mean radiance of the part's samples.
    pub image: Image,
    /// Its samples.
    pub info: PartInfo,
}

/// Parse `A..B` (A < B) into a range of sample indices.
pub fn parse_range(s: &str) -> Result<Range<u32>, String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("expected A..B (e.g. 0..16), got '{s}'"))?;
    let p = |t: &str| t.trim().parse::<u32>().ok();
    match (p(a), p(b)) {
        (Some(a), Some(b)) if a < b => Ok(a..b),
        _ => Err(format!(
            "expected A..B with whole numbers A < B (e.g. 0..16), got '{s}'"
        )),
    }
}

/// The [`PartInfo::render`] of a render: the scene as named, its load options, the resolution
/// and every render option but the sample range (and the progress bar and cancel flag, which
/// change no pixel). The CLI and the Python package both use it, so their parts merge.
pub fn render_key(
    scene: &str,
    load: &crate::scene::load::LoadOptions,
    res: glam::UVec2,
    opts: &crate::integrator::RenderOptions,
) -> String {
    let opts = crate::integrator::RenderOptions {
        sample_range: None,
        cancel: None,
        progress: false,
        ..opts.clone()
    };
    format!("{scene} {}x{} {load:?} {opts:?}", res.x, res.y)
}

/// Write a part as EXR with its header attributes (atomically, like every image).
pub fn write_part(part: &Part, path: &Path, ctl: &WriteControl) -> anyhow::Result<()> {
    let i = &part.info;
    let attributes = [
        (
            ATTR_SAMPLES,
            format!("{}..{}", i.samples.start, i.samples.end),
        ),
        (ATTR_COUNT, i.count().to_string()),
        (ATTR_SPP, i.spp.to_string()),
        (ATTR_RENDER, ascii(&i.render)),
    ];
    write_image_tagged(&part.image, path, 0.0, &attributes, ctl)
}

/// Read a part written by [`write_part`]; an EXR without the attributes is an error naming the
/// file.
pub fn read_part(path: &Path) -> anyhow::Result<Part> {
    let image = read_image(path)?;
    let attrs = read_exr_attributes(path)?;
    let get = |k: &str| {
        attrs
            .iter()
            .find(|(n, _)| n == k)
            .map(|(_, v)| v.as_str())
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: no {k} header attribute: not a part written by `penumbra render \
                     --spp-range`",
                    path.display()
                )
            })
    };
    let samples = parse_range(get(ATTR_SAMPLES)?)
        .map_err(|e| anyhow::anyhow!("{}: {ATTR_SAMPLES}: {e}", path.display()))?;
    let spp: u32 = get(ATTR_SPP)?
        .parse()
        .with_context(|| format!("{}: {ATTR_SPP} is not a whole number", path.display()))?;
    let count: u32 = get(ATTR_COUNT)?
        .parse()
        .with_context(|| format!("{}: {ATTR_COUNT} is not a whole number", path.display()))?;
    if count != samples.end - samples.start || samples.end > spp {
        bail!(
            "{}: inconsistent header: samples {}..{}, count {count}, spp {spp}",
            path.display(),
            samples.start,
            samples.end
        );
    }
    let render = get(ATTR_RENDER)?.to_string();
    Ok(Part {
        image,
        info: PartInfo {
            samples,
            spp,
            render,
        },
    })
}

/// Combine parts into the whole render: each part weighted by its sample count, summed in
/// order of sample index (so the result does not depend on the order `parts` come in), divided
/// by the spp. The parts must be of one render (same size, spp and settings) and cover
/// `0..spp` exactly once: a gap or an overlap is an error naming the samples.
pub fn merge(parts: &[Part]) -> anyhow::Result<Part> {
    let Some(first) = parts.first() else {
        bail!("no parts to merge");
    };
    let mut order: Vec<&Part> = parts.iter().collect();
    order.sort_by_key(|p| (p.info.samples.start, p.info.samples.end));
    let (w, h, spp) = (first.image.width, first.image.height, first.info.spp);
    for p in &order {
        if !p.image.same_size(&first.image) {
            bail!(
                "parts differ in size: {}x{} and {w}x{h}",
                p.image.width,
                p.image.height
            );
        }
        if p.info.spp != spp || p.info.render != first.info.render {
            bail!(
                "parts of different renders: samples {}..{} of {} spp ({}) and {}..{} of {spp} \
                 spp ({})",
                p.info.samples.start,
                p.info.samples.end,
                p.info.spp,
                p.info.render,
                first.info.samples.start,
                first.info.samples.end,
                first.info.render
            );
        }
    }
    let mut next = 0u32;
    for p in &order {
        let s = &p.info.samples;
        if s.start > next {
            bail!("samples {next}..{} are missing", s.start);
        }
        if s.start < next {
            bail!(
                "parts overlap: samples {}..{} are in more than one part",
                s.start,
                next.min(s.end)
            );
        }
        next = s.end;
    }
    if next != spp {
        bail!("samples {next}..{spp} are missing");
    }
    // f64 sums: each part's mean times its count is its sample sum, up to one rounding.
    let mut sum = vec![[0f64; 3]; first.image.pixels.len()];
    for p in &order {
        let n = f64::from(p.info.count());
        for (acc, px) in sum.iter_mut().zip(&p.image.pixels) {
            for c in 0..3 {
                acc[c] += f64::from(px[c]) * n;
            }
        }
    }
    let inv = 1.0 / f64::from(spp);
    let pixels = sum
        .iter()
        .map(|s| {
            Rgb::new(
                (s[0] * inv) as f32,
                (s[1] * inv) as f32,
                (s[2] * inv) as f32,
            )
        })
        .collect();
    Ok(Part {
        image: Image {
            width: w,
            height: h,
            pixels,
        },
        info: PartInfo {
            samples: 0..spp,
            spp,
            render: first.info.render.clone(),
        },
    })
}

/// `s` with anything outside printable ASCII escaped: EXR text attributes are bytes.
fn ascii(s: &str) -> String {
    s.chars()
        .flat_map(|c| {
            if c.is_ascii_graphic() || c == ' ' {
                vec![c]
            } else {
                c.escape_default().collect()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn part(samples: Range<u32>, value: f32) -> Part {
        Part {
            image: Image::from_fn(2, 1, |x, _| Rgb::splat(value + x as f32)),
            info: PartInfo {
                samples,
                spp: 8,
                render: "r".into(),
            },
        }
    }

    #[test]
    fn merge_weights_by_count_and_ignores_order() {
        let a = [part(0..2, 1.0), part(2..8, 3.0)];
        let b = [part(2..8, 3.0), part(0..2, 1.0)];
        let (ma, mb) = (merge(&a).unwrap(), merge(&b).unwrap());
        assert_eq!(ma.image.pixels[0], Rgb::splat((2.0 + 18.0) / 8.0));
        assert_eq!(ma.image, mb.image);
        assert_eq!(ma.info.samples, 0..8);
    }

    #[test]
    fn gaps_overlaps_and_foreign_parts_are_errors() {
        let msg = |p: &[Part]| merge(p).unwrap_err().to_string();
        assert!(msg(&[part(0..2, 1.0), part(3..8, 1.0)]).contains("samples 2..3 are missing"));
        assert!(msg(&[part(0..4, 1.0), part(3..8, 1.0)]).contains("parts overlap: samples 3..4"));
        assert!(msg(&[part(0..4, 1.0)]).contains("samples 4..8 are missing"));
        assert!(msg(&[part(1..8, 1.0)]).contains("samples 0..1 are missing"));
        let mut other = part(4..8, 1.0);
        other.info.render = "s".into();
        assert!(msg(&[part(0..4, 1.0), other]).contains("different renders"));
        assert!(msg(&[]).contains("no parts"));
    }

    #[test]
    fn ranges_parse_and_reject_nonsense() {
        assert_eq!(parse_range("3..17"), Ok(3..17));
        for bad in ["3..3", "5..2", "a..b", "7", "-1..4"] {
            assert!(parse_range(bad).is_err(), "{bad}");
        }
    }
}
