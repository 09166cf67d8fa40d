//! The render in rounds for `--light-selection online`: the sample indices of every pixel are
//! split into rounds of 1, 1, 2, 4, … (each round as many samples as all before it, the last
//! taking the rest); each round renders with the distribution learned from the rounds before
//! it, frozen for the round, and records what its light samples delivered; the tiles' records
//! are merged in tile order at the round's end ([`OnlineLearner::merge`]), so the image is the
//! same for any thread count. Each round is unbiased for its own distribution, and the rounds
//! are added by their sample counts ([`Accumulator`]). Once every vertex class has settled on
//! power selection ([`OnlineLearner::advance`]), the remaining samples are one round: nothing
//! is learned any more.

use super::RenderOptions;
use super::render::{RenderStats, render_with};
use crate::image::Image;
use crate::light_selection::online::{OnlineConfig, OnlineLearner};
use crate::progressive::Accumulator;
use crate::scene::Scene;
use glam::UVec2;
use std::ops::Range;

/// The rounds of sample indices `range`: 1, 1, 2, 4, … samples, the last taking the rest.
pub fn rounds(range: Range<u32>) -> Vec<Range<u32>> {
    let mut out = Vec::new();
    let mut at = range.start;
    while at < range.end {
        let done = at - range.start;
        let n = done.max(1).min(range.end - at);
        out.push(at..at + n);
        at += n;
    }
    out
}

/// [`super::render`] with online light selection.
pub fn render_online(
    scene: &Scene,
    res: UVec2,
    opts: &RenderOptions,
) -> anyhow::Result<(Image, RenderStats)> {
    anyhow::ensure!(opts.spp > 0, "--spp must be at least 1");
    let samples = opts.samples()?;
    let mut learner = OnlineLearner::new(scene, OnlineConfig::new(opts.seed));
    // Secondary vertices exist only when paths go past their first vertex.
    let secondary = opts.depth() > 1;
    let mut acc = Accumulator::new(res);
    let mut total: Option<RenderStats> = None;
    let all = rounds(samples.clone());
    let mut next = 0;
    while next < all.len() {
        let selector = learner.advance(scene, secondary);
        // Once every class has settled on power selection, the rest is one round: nothing
        // is learned any more, and a pixel's samples share its pattern set-up again.
        let round = if learner.settled(secondary) {
            all[next].start..samples.end
        } else {
            all[next].clone()
        };
        next = if round.end == samples.end {
            all.len()
        } else {
            next + 1
        };
        let count = round.len() as u32;
        let ropts = RenderOptions {
            sample_range: Some(round),
            ..opts.clone()
        };
        // The last round's records would teach no later round.
        let learn = (next < all.len() && learner.learning() != 0).then_some(&learner);
        let (img, stats, digests) = render_with(scene, res, &ropts, selector.as_ref(), learn)?;
        learner.merge(&digests);
        acc.add(&img, count);
        total = Some(match total {
            None => stats,
            Some(mut t) => {
                t.time += stats.time;
                t.rays += stats.rays;
                t.by_kind.add(&stats.by_kind);
                t.non_finite += stats.non_finite;
                t.rounds += stats.rounds;
                t
            }
        });
    }
    let stats = total.ok_or_else(|| anyhow::anyhow!("no samples to render"))?;
    Ok((acc.image(), stats))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounds_double_and_cover_the_range() {
        assert_eq!(rounds(0..1), vec![0..1]);
        assert_eq!(rounds(0..8), vec![0..1, 1..2, 2..4, 4..8]);
        assert_eq!(rounds(0..10), vec![0..1, 1..2, 2..4, 4..8, 8..10]);
        assert_eq!(rounds(4..7), vec![4..5, 5..6, 6..7]);
    }
}
