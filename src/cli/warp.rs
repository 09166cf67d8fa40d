//! `penumbra warp`: plot and chi-square-test one sampling routine, dump its samples, or
//! evaluate its pdf at given points. Parsing only; the work is in `penumbra::lab::warp`.

use anyhow::{Context, bail};
use penumbra::lab::warp::io::{Table, read_table, write_table};
use penumbra::lab::warp::{RunConfig, build, list_text, pdf_at, plot, run};
use penumbra::sampling::PatternKind;
use penumbra::sampling::chi2::Chi2Config;
use std::path::PathBuf;

/// Arguments of `penumbra warp`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Routine name (see `--list`).
    #[arg(required_unless_present = "list")]
    pub name: Option<String>,
    /// List the routines with their parameters and defaults.
    #[arg(long)]
    pub list: bool,
    /// A routine parameter, KEY=VALUE (repeatable).
    #[arg(short = 'p', long = "param", value_name = "KEY=VALUE")]
    pub params: Vec<String>,
    /// Sampling attempts.
    #[arg(short = 'n', long, default_value_t = 200_000)]
    pub count: usize,
    /// Seed (default: the test suite's chi-square seed).
    #[arg(long, default_value_t = Chi2Config::default().seed)]
    pub seed: u64,
    /// Take the 2D inputs from a sample pattern (fixed, random, grid, stratified, lhs, sobol)
    /// instead of the harness's independent stream. The chi-square verdict then only counts
    /// for `random`: the test assumes independent samples.
    #[arg(long)]
    pub pattern: Option<PatternKind>,
    /// Output directory of the PNGs.
    #[arg(short, long, default_value = "warp-out")]
    pub out: PathBuf,
    /// Overall significance level α of the chi-square test.
    #[arg(long, default_value_t = Chi2Config::default().significance)]
    pub significance: f64,
    /// Histogram grid AxB: (cos θ, φ) cells for directions, (x, y) cells for points.
    #[arg(long, value_parser = parse_res)]
    pub res: Option<(usize, usize)>,
    /// Do not write PNGs.
    #[arg(long)]
    pub no_plots: bool,
    /// Write the accepted samples here: `x y z` or `u v` per line, or `.npy` (f32).
    #[arg(long, value_name = "FILE")]
    pub dump: Option<PathBuf>,
    /// Evaluate the routine's pdf at the points in FILE (same formats as --dump) and exit.
    #[arg(long, value_name = "FILE")]
    pub pdf_at: Option<PathBuf>,
    /// Where --pdf-at writes the densities (one per line, or `.npy` f64); default stdout.
    #[arg(long, value_name = "OUT", requires = "pdf_at")]
    pub dump_pdf: Option<PathBuf>,
}

/// Parse `AxB` (both ≥ 1).
fn parse_res(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected AxB, got {s:?}"))?;
    let p = |t: &str| {
        t.trim()
            .parse::<usize>()
            .ok()
            .filter(|&v| (1..=4096).contains(&v))
    };
    match (p(a), p(b)) {
        (Some(a), Some(b)) => Ok((a, b)),
        _ => Err(format!("expected AxB with 1 <= A, B <= 4096, got {s:?}")),
    }
}

/// Run the command. Fails (non-zero exit) on bad input and when the chi-square test rejects
/// independent samples at the chosen significance.
pub fn run_cmd(args: Args) -> anyhow::Result<()> {
    if args.list {
        print!("{}", list_text());
        return Ok(());
    }
    let Some(name) = args.name.as_deref() else {
        bail!("give a routine name (see `penumbra warp --list`)");
    };
    let warp = build(name, &args.params)?;

    if let Some(input) = &args.pdf_at {
        let points: Table<f32> = read_table(input)?;
        let pdf = pdf_at(&warp, points.cols, &points.values)
            .with_context(|| format!("--pdf-at {}", input.display()))?;
        let table = Table {
            cols: 1,
            values: pdf,
        };
        match &args.dump_pdf {
            Some(out) => {
                write_table(out, &table)?;
                println!(
                    "wrote {} pdf values to {}",
                    table.values.len(),
                    out.display()
                );
            }
            None => table.values.iter().for_each(|v| println!("{v}")),
        }
        return Ok(());
    }

    // Every accepted sample is kept for the plots and --dump: cap the memory at ~1.2 GB.
    const MAX_COUNT: usize = 100_000_000;
    if args.count == 0 || args.count > MAX_COUNT {
        bail!("--count must be in 1..={MAX_COUNT}, got {}", args.count);
    }
    if !(args.significance > 0.0 && args.significance < 1.0) {
        bail!(
            "--significance must be in (0, 1), got {}",
            args.significance
        );
    }
    let cfg = RunConfig {
        count: args.count,
        seed: args.seed,
        pattern: args.pattern,
        significance: args.significance,
        res: args.res,
    };
    let r = run(&warp, &cfg);
    r.check_enough_samples()?;
    let c = &r.chi2;
    println!("routine     {}", warp.label);
    println!(
        "samples     {} accepted of {} ({} lost)",
        r.samples.len(),
        r.attempts,
        c.failures
    );
    println!(
        "input       {}",
        match cfg.pattern {
            None => format!("harness PCG stream, seed {}", cfg.seed),
            Some(k) => format!("pattern {k}, seed {}", cfg.seed),
        }
    );
    println!("grid        {}x{}", c.res.0, c.res.1);
    println!("statistic   {}", c.statistic);
    println!("dof         {}", c.dof);
    println!("p-value     {:e}", c.p_value);
    println!("alpha       {:.3e}", c.alpha);
    let note = if r.independent {
        String::new()
    } else {
        format!(
            "pattern {}: samples are not independent, which the test assumes; verdict informational",
            cfg.pattern.map_or("?", |k| k.name())
        )
    };
    println!(
        "verdict     {}{}",
        if c.passed { "PASSED" } else { "REJECTED" },
        if note.is_empty() {
            String::new()
        } else {
            format!(" ({note})")
        }
    );

    if let Some(path) = &args.dump {
        let dim = warp.dim();
        let values = r
            .samples
            .iter()
            .flat_map(|s| s.to_array().into_iter().take(dim))
            .collect();
        write_table(path, &Table { cols: dim, values })?;
        println!("wrote {} samples to {}", r.samples.len(), path.display());
    }
    if !args.no_plots {
        let short = if r.independent {
            ""
        } else {
            "non-independent pattern"
        };
        for p in plot::write_plots(&args.out, &warp, &r, short)? {
            println!("wrote {}", p.display());
        }
    }
    if !c.passed && r.independent {
        bail!(
            "chi-square test rejected {} at significance {} (p = {:e})",
            warp.label,
            args.significance,
            c.p_value
        );
    }
    Ok(())
}
