//! `penumbra lab`: render the lecture's comparison figures with timings and relMSE, plus a
//! convergence plot, `results.json` and `index.html`.

use super::render::parse_res;
use glam::UVec2;
use penumbra::lab::runner::{DEFAULT_CONVERGENCE_SPP, DEFAULT_REFERENCE_SPP};
use penumbra::lab::{LabOptions, run_lab};
use penumbra::scene::builtin::BuiltinOptions;
use penumbra::scene::load::LoadOptions;
use std::path::PathBuf;

/// Arguments of `penumbra lab`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scene of figures 1–4 and of the convergence plot: built-in name or scene file.
    #[arg(default_value = "cornell")]
    pub scene: String,
    /// Output directory (created if missing; references are cached here).
    #[arg(long, default_value = "lab")]
    pub out: PathBuf,
    /// Resolution WxH of every panel (default: the reference's size, else 256x256).
    #[arg(long, value_parser = parse_res)]
    pub res: Option<UVec2>,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
    /// Reference image of the main scene (default: rendered with MIS and cached in --out).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Eye rays per pixel of the rendered references (many-light scenes use a quarter).
    #[arg(long, default_value_t = DEFAULT_REFERENCE_SPP)]
    pub reference_spp: u32,
    /// Largest spp of the convergence sweep (doubling from 1); 0 skips it.
    #[arg(long, default_value_t = DEFAULT_CONVERGENCE_SPP)]
    pub convergence_spp: u32,
    /// Only these figures (comma-separated ids, e.g. fig1,fig3).
    #[arg(long, value_delimiter = ',')]
    pub figures: Vec<String>,
    /// Seed of every panel.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Number of lights of the many-light built-in scenes.
    #[arg(long)]
    pub light_count: Option<u32>,
}

/// Run the command: prints one line per panel and where the report is.
pub fn run(args: Args) -> anyhow::Result<()> {
    let opts = LabOptions {
        scene: args.scene,
        out: args.out,
        res: args.res,
        reference: args.reference,
        reference_spp: args.reference_spp,
        convergence_spp: args.convergence_spp,
        seed: args.seed,
        progress: !args.quiet,
        figures: args.figures,
        load: LoadOptions {
            builtin: BuiltinOptions {
                light_count: args.light_count,
                ..BuiltinOptions::default()
            },
            ..LoadOptions::default()
        },
    };
    let r = run_lab(&opts)?;
    for f in &r.figures {
        for p in &f.panels {
            println!(
                "{:<5} {:<14} {:<17} {:>3} × {:<4} {:>8.3} s  relMSE {:.3e}  smooth {:.3e}",
                f.id,
                p.label,
                p.strategy,
                p.spp,
                p.shadow_rays,
                p.time_s,
                p.rel_mse,
                p.smooth_rel_mse
            );
        }
        for s in f.skipped.iter().filter(|s| !s.is_empty()) {
            println!("{:<5} skipped: {s}", f.id);
        }
    }
    for s in &r.convergence {
        let last = s.points.last();
        if let Some(p) = last {
            println!(
                "convergence {:<17} {:>4} spp {:>8.3} s  relMSE {:.3e}  smooth {:.3e}",
                s.strategy, p.spp, p.time_s, p.rel_mse, p.smooth_rel_mse
            );
        }
    }
    println!(
        "{:.1} s total -> {}",
        r.total_time_s,
        opts.out.join("index.html").display()
    );
    Ok(())
}
