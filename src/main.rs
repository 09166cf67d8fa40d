//! The `penumbra` command line: parses arguments and calls the library. Nothing else.

mod cli;

use clap::Parser;

fn main() {
    quiet_on_stdout_errors();
    let args = cli::Cli::parse();
    if let Err(e) = cli::run(args) {
        let broken_pipe = e.chain().any(|c| {
            c.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
        });
        if broken_pipe {
            std::process::exit(0);
        }
        eprintln!("error: {}", cli::messages::format_error(&e));
        let code = e
            .downcast_ref::<cli::interrupt::Interrupted>()
            .map_or(1, cli::interrupt::Interrupted::exit_code);
        std::process::exit(code);
    }
}

/// `println!` panics when stdout fails: `penumbra bench | head` closes it early (exit quietly,
/// as Unix tools do when their reader goes away), `penumbra scenes > /dev/full` fills it (say
/// so and exit 1). Neither is a bug worth a panic message and a backtrace.
fn quiet_on_stdout_errors() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("failed printing to stdout") {
            if msg.contains("Broken pipe") {
                std::process::exit(0);
            }
            let why = msg.trim_start_matches("failed printing to stdout: ");
            eprintln!("error: cannot write to standard output: {why}");
            std::process::exit(1);
        }
        default(info);
    }));
}
