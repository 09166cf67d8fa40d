//! Subcommands, one file each.

use clap::{Parser, Subcommand};

/// penumbra: BRDF importance sampling and direct lighting on the CPU.
#[derive(Parser, Debug)]
#[command(name = "penumbra", version, about)]
pub struct Cli {
    /// What to do (default: render the built-in `cornell` scene to penumbra.png).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene (built-in name or file) to an image.
    Render(render::Args),
    /// Compare an image with a reference: MSE, relMSE, MAE.
    Compare(compare::Args),
}

pub mod compare;
pub mod render;

/// Dispatch a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Some(Command::Render(a)) => render::run(a),
        Some(Command::Compare(a)) => compare::run(a),
        None => render::run(render::Args::default_scene()),
    }
}
