//! Progressive rendering: a render of `spp` samples per pixel done in passes, each pass a
//! sample-index range of the same render (`RenderOptions::sample_range`). Because every sample
//! is a pure function of (seed, pixel, index, dimension) and the patterns hand out their
//! `spp` samples in a random order of strata, the first `k` indices are an unbiased `k`-sample
//! estimate at any `k`, and passes added up by their sample counts are the one-pass render up
//! to float rounding, whatever the pass sizes (so a time budget, a signal or a resume, which
//! change the pass sizes, change no estimate).
//!
//! The pass loop stays outside the render loop: it only calls [`crate::integrator::render`]
//! with a range and the cancellation flag, and drops a pass that was cancelled part-way.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use glam::UVec2;

use crate::Rgb;
use crate::image::Image;
use crate::integrator::{Cancelled, RenderOptions, render};
use crate::scene::Scene;

/// The running sum of the completed passes: per pixel, Σ pass mean × pass sample count (in
/// f64, so thousands of passes lose nothing to rounding), over sample indices `0..count`.
#[derive(Clone, Debug)]
pub struct Accumulator {
    width: u32,
    height: u32,
    sum: Vec<[f64; 3]>,
    count: u32,
}

impl Accumulator {
    /// No samples yet.
    pub fn new(res: UVec2) -> Self {
        Self {
            width: res.x,
            height: res.y,
            sum: vec![[0.0; 3]; res.x as usize * res.y as usize],
            count: 0,
        }
    }

    /// Start from an image holding the mean of sample indices `0..count` (a partial render
    /// read back for `--resume`).
    pub fn from_mean(mean: &Image, count: u32) -> Self {
        let mut a = Self::new(UVec2::new(mean.width, mean.height));
        a.add(mean, count);
        a
    }

    /// Add a pass: `mean` is the mean of `count` new samples of every pixel.
    pub fn add(&mut self, mean: &Image, count: u32) {
        assert!(
            mean.width == self.width && mean.height == self.height,
            "pass of {}x{} added to a {}x{} accumulator",
            mean.width,
            mean.height,
            self.width,
            self.height
        );
        let n = f64::from(count);
        for (acc, px) in self.sum.iter_mut().zip(&mean.pixels) {
            for c in 0..3 {
                acc[c] += f64::from(px[c]) * n;
            }
        }
        self.count += count;
    }

    /// Samples per pixel accumulated so far.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// Resolution.
    pub fn resolution(&self) -> UVec2 {
        UVec2::new(self.width, self.height)
    }

    /// The image of the samples so far, normalised by their count (black with none).
    pub fn image(&self) -> Image {
        let inv = if self.count == 0 {
            0.0
        } else {
            1.0 / f64::from(self.count)
        };
        Image {
            width: self.width,
            height: self.height,
            pixels: self
                .sum
                .iter()
                .map(|s| {
                    Rgb::new(
                        (s[0] * inv) as f32,
                        (s[1] * inv) as f32,
                        (s[2] * inv) as f32,
                    )
                })
                .collect(),
        }
    }
}

/// How the passes grow.
#[derive(Clone, Copy, Debug)]
pub struct PassPolicy {
    /// Stop starting passes once this much render time has been spent (`--time`).
    pub budget: Option<Duration>,
    /// Keep a pass below about this long (from the measured rate), so that the image on
    /// screen or disk refreshes often and an interrupted pass loses little.
    pub max_pass: Duration,
}

impl Default for PassPolicy {
    fn default() -> Self {
        Self {
            budget: None,
            max_pass: Duration::from_secs(2),
        }
    }
}

/// The sample count of the next pass after `done` of `spp` samples: double the samples so far
/// (one pass of 1 first), but no more than `max_pass` at `rate` samples per second and no more
/// than what the remaining budget fits (at least 1, so every pass makes progress).
pub fn next_pass(
    done: u32,
    spp: u32,
    rate: Option<f64>,
    time_left: Option<Duration>,
    max_pass: Duration,
) -> u32 {
    let left = spp.saturating_sub(done);
    let mut n = done.max(1).min(left);
    if let Some(rate) = rate.filter(|r| r.is_finite() && *r > 0.0) {
        let fit = |d: Duration| {
            (d.as_secs_f64() * rate)
                .floor()
                .max(1.0)
                .min(f64::from(u32::MAX)) as u32
        };
        n = n.min(fit(max_pass));
        if let Some(t) = time_left {
            n = n.min(fit(t));
        }
    }
    n.max(1).min(left)
}

/// What one completed pass measured.
#[derive(Clone, Debug)]
pub struct PassReport {
    /// The sample indices of the pass.
    pub samples: Range<u32>,
    /// Wall time of the pass.
    pub time: Duration,
    /// Rays it traced.
    pub rays: u64,
}

/// Why the pass loop ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// All `spp` samples are done.
    Done,
    /// The time budget is spent.
    Budget,
    /// The cancellation flag was set (the pass in flight was dropped).
    Cancelled,
}

/// Totals of a progressive render.
#[derive(Clone, Debug)]
pub struct Progress {
    /// Why it ended.
    pub stop: Stop,
    /// Render time of the completed passes (the dropped one excluded).
    pub time: Duration,
    /// Rays of the completed passes.
    pub rays: u64,
    /// Completed passes.
    pub passes: u32,
}

/// Render passes of `opts` (its `spp` is the total) on top of `acc` until `acc` holds all
/// `opts.spp` samples, the budget is spent or `cancel` is set. `post` turns each pass's image
/// into what is accumulated (the film's sensor response, say); `on_pass` sees the accumulator
/// after every completed pass (to write or display it). A pass interrupted by `cancel` is
/// dropped: its samples are not in `acc`.
pub fn render_passes(
    scene: &Scene,
    opts: &RenderOptions,
    acc: &mut Accumulator,
    policy: &PassPolicy,
    cancel: &Arc<AtomicBool>,
    post: &dyn Fn(&mut Image),
    on_pass: &mut dyn FnMut(&Accumulator, &PassReport) -> anyhow::Result<()>,
) -> anyhow::Result<Progress> {
    let start = Instant::now();
    let mut progress = Progress {
        stop: Stop::Done,
        time: Duration::ZERO,
        rays: 0,
        passes: 0,
    };
    let mut rate = None;
    let res = acc.resolution();
    loop {
        if acc.count() >= opts.spp {
            progress.stop = Stop::Done;
            break;
        }
        let time_left = policy.budget.map(|b| b.saturating_sub(start.elapsed()));
        if time_left == Some(Duration::ZERO) {
            progress.stop = Stop::Budget;
            break;
        }
        if cancel.load(std::sync::atomic::Ordering::SeqCst) {
            progress.stop = Stop::Cancelled;
            break;
        }
        let n = next_pass(acc.count(), opts.spp, rate, time_left, policy.max_pass);
        let samples = acc.count()..acc.count() + n;
        let pass_opts = RenderOptions {
            sample_range: Some(samples.clone()),
            cancel: Some(Arc::clone(cancel)),
            ..opts.clone()
        };
        let pass_start = Instant::now();
        let (mut img, stats) = match render(scene, res, &pass_opts) {
            Ok(r) => r,
            Err(e) if e.is::<Cancelled>() => {
                progress.stop = Stop::Cancelled;
                break;
            }
            Err(e) => return Err(e),
        };
        let time = pass_start.elapsed();
        post(&mut img);
        acc.add(&img, n);
        progress.time += time;
        progress.rays += stats.rays;
        progress.passes += 1;
        rate = Some(f64::from(n) / time.as_secs_f64().max(1e-6));
        on_pass(
            acc,
            &PassReport {
                samples,
                time,
                rays: stats.rays,
            },
        )?;
    }
    Ok(progress)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_double_then_respect_time_and_the_total() {
        let long = Duration::from_secs(3600);
        let mut done = 0;
        let mut sizes = vec![];
        while done < 20 {
            let n = next_pass(done, 20, None, None, long);
            sizes.push(n);
            done += n;
        }
        assert_eq!(sizes, [1, 1, 2, 4, 8, 4]);
        // 10 samples/s: a 2 s cap allows 20, a 0.35 s budget 3.
        assert_eq!(
            next_pass(64, 1000, Some(10.0), None, Duration::from_secs(2)),
            20
        );
        assert_eq!(
            next_pass(64, 1000, Some(10.0), Some(Duration::from_millis(350)), long),
            3
        );
        // At least one sample, never past the total.
        assert_eq!(
            next_pass(64, 1000, Some(1.0), Some(Duration::from_millis(1)), long),
            1
        );
        assert_eq!(next_pass(999, 1000, None, None, long), 1);
    }

    #[test]
    fn accumulator_weights_passes_by_their_counts() {
        let res = UVec2::new(2, 1);
        let mut a = Accumulator::new(res);
        assert_eq!(a.image().pixels, vec![Rgb::ZERO; 2]);
        a.add(&Image::from_fn(2, 1, |x, _| Rgb::splat(1.0 + x as f32)), 1);
        a.add(&Image::from_fn(2, 1, |x, _| Rgb::splat(4.0 + x as f32)), 3);
        assert_eq!(a.count(), 4);
        assert_eq!(a.image().pixels[0], Rgb::splat((1.0 + 12.0) / 4.0));
        assert_eq!(a.image().pixels[1], Rgb::splat((2.0 + 15.0) / 4.0));
    }
}
