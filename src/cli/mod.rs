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
    /// List the built-in scenes.
    Scenes,
    /// Print rays/s and time per image on the standard scenes.
    Bench(bench::Args),
    /// Compare an image with a reference: MSE, relMSE, MAE.
    Compare(compare::Args),
    /// Render the lecture's comparison figures with timings, relMSE and an HTML report.
    Lab(lab::Args),
    /// Plot and chi-square-test a sampling routine; dump samples, evaluate its pdf.
    Warp(warp::Args),
    /// Combine the sample-range parts of a render (`render --spp-range`) into the whole image.
    Merge(merge::Args),
    /// Watch a render converge in the browser: a local web server with A/B comparison.
    View(view::Args),
}

pub mod bench;
pub mod compare;
pub mod interrupt;
pub mod lab;
pub mod memory;
pub mod merge;
pub mod messages;
pub mod render;
pub mod view;
pub mod warp;

/// Dispatch a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Some(Command::Render(a)) => render::run(a),
        Some(Command::Compare(a)) => compare::run(a),
        Some(Command::Lab(a)) => lab::run(a),
        Some(Command::Scenes) => {
            use anyhow::Context;
            use std::io::Write;
            let mut out = std::io::stdout().lock();
            for b in penumbra::scene::builtin::BUILTINS {
                writeln!(out, "{:<16} {}", b.name, b.description)
                    .context("writing to standard output")?;
            }
            out.flush().context("writing to standard output")
        }
        Some(Command::Bench(a)) => bench::run(a),
        Some(Command::Warp(a)) => warp::run_cmd(a),
        Some(Command::Merge(a)) => merge::run(a),
        Some(Command::View(a)) => view::run(a),
        None => match Cli::try_parse_from(["penumbra", "render"])?.command {
            Some(Command::Render(a)) => render::run(a),
            _ => unreachable!("`render` parses to the render command"),
        },
    }
}
