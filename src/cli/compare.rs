//! `penumbra compare`: error metrics of a render against a reference image.

use std::path::PathBuf;

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
    let test = read_image(&args.test)?;
    let reference = read_image(&args.reference)?;
    for (img, path) in [(&test, &args.test), (&reference, &args.reference)] {
        let bad = img.count_non_finite();
        if bad > 0 {
            // The metrics will be NaN/Inf; say why rather than leave the user guessing.
            eprintln!("warning: {}: {bad} pixel(s) with NaN/Inf", path.display());
        }
    }
    let stats = compare(&test, &reference)?;
    println!("MSE     {:.4e}", stats.mse);
    println!("relMSE  {:.4e}", stats.rel_mse);
    println!("MAE     {:.4e}", stats.mae);
    if let Some(out) = &args.error_image {
        write_image(&error_image(&test, &reference)?, out, 0.0)?;
    }
    Ok(())
}
