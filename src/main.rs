//! The `penumbra` command line: parses arguments and calls the library. Nothing else.

mod cli;

use clap::Parser;

fn main() {
    quiet_on_broken_pipe();
    let args = cli::Cli::parse();
    if let Err(e) = cli::run(args) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

/// `penumbra bench | head` closes our stdout early; `println!` then panics. Exit quietly
/// instead, as Unix tools do when their reader goes away.
fn quiet_on_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("failed printing to stdout") && msg.contains("Broken pipe") {
            std::process::exit(0);
        }
        default(info);
    }));
}
