//! `penumbra render`. TODO(issue 3).

/// Arguments of `penumbra render`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Built-in scene name or scene file path.
    #[arg(default_value = "cornell")]
    pub scene: String,
}

impl Args {
    /// What `penumbra` with no subcommand renders.
    pub fn default_scene() -> Self {
        Self {
            scene: "cornell".into(),
        }
    }
}

/// Run the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    anyhow::bail!("render of {} not implemented yet (issue 3)", args.scene)
}
