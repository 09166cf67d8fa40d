//! `penumbra compare`: error metrics of a render against a reference image.

use std::path::PathBuf;

use std::io::Write;

use penumbra::image::io::check_output_path;
use penumbra::image::metrics::comparison_warnings;
use penumbra::image::{compare, error_image, read_image, write_image};

/// Arguments of `penumbra compare`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The image to judge (EXR, PFM, PNG, HDR, ...).
    pub test: PathBuf,
    /// The reference image, same size.
    pub reference: PathBuf,
    /// Also write a false-colour per-pixel relMSE map (viridis, log10 range −4..1) here.
    #[arg(long, value_name = "OUT.png")]
    pub error_image: Option<PathBuf>,
}

/// Run the command: prints MSE, relMSE and MAE, one per line.
pub fn run(args: Args) -> anyhow::Result<()> {
    if let Some(out) = &args.error_image {
        check_output_path(out)?;
    }
    let test = read_image(&args.test)?;
    let reference = read_image(&args.reference)?;
    for w in comparison_warnings((&test, &args.test), (&reference, &args.reference))? {
        eprintln!("warning: {w}");
    }
    let stats = compare(&test, &reference)?;
    let mut out = std::io::stdout().lock();
    writeln!(out, "MSE     {:.4e}", stats.mse)?;
    writeln!(out, "relMSE  {:.4e}", stats.rel_mse)?;
    writeln!(out, "MAE     {:.4e}", stats.mae)?;
    if let Some(path) = &args.error_image {
        write_image(&error_image(&test, &reference)?, path, 0.0)?;
    }
    Ok(())
}
