//! `penumbra merge`: combine the sample-range parts of a render into the whole image.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Context;
use penumbra::image::io::{WriteControl, check_output_path, write_image};
use penumbra::image::parts::{merge, read_part, write_part};

/// Arguments of `penumbra merge`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The parts (EXR files written by `penumbra render --spp-range`), in any order.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Output image; an `.exr` records the merged range, other formats just the pixels.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Run the command: read, check coverage, merge, write.
pub fn run(args: Args) -> anyhow::Result<()> {
    check_output_path(&args.output)?;
    let parts = args
        .parts
        .iter()
        .map(|p| read_part(p))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let merged = merge(&parts).context("merging the parts")?;
    let is_exr = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if is_exr {
        write_part(&merged, &args.output, &WriteControl::default())?;
    } else {
        write_image(&merged.image, &args.output, 0.0)?;
    }
    writeln!(
        std::io::stdout(),
        "merged {} parts: samples 0..{} of {}x{} -> {}",
        parts.len(),
        merged.info.spp,
        merged.image.width,
        merged.image.height,
        args.output.display()
    )
    .context("writing to standard output")
}
