//! The `raytrail` command line: the main job (no arguments), `trace`, `rays`, `bench`, `render`,
//! `accuracy`, `explain` and `stress`. Flags are declared with clap in [`args`]; usage errors exit with status
//! 2, failures while working with status 1.

mod accuracy;
mod args;
mod auto;
mod bench;
mod explain;
mod failure;
mod flags;
mod gpu;
mod limits;
mod median;
mod progress;
mod render;
mod run;
mod stress;
mod svg;
mod trace;

use args::{Cli, Command};
use clap::Parser;

fn main() {
    restore_sigpipe();
    let raw: Vec<String> = std::env::args_os().map(|a| a.to_string_lossy().into_owned()).collect();
    // Usage errors exit with status 2; `--help` and `--version` print and exit with 0.
    let cli = Cli::parse();
    let result = match cli.command {
        None => run::main(cli.run),
        Some(Command::Run(a)) => run::main(a),
        Some(Command::Trace(a)) => trace::main(a),
        Some(Command::Rays(a)) => trace::rays_main(a),
        // The report records the command as given.
        Some(Command::Bench(a)) => bench::main(a, &raw[2.min(raw.len())..]),
        Some(Command::Render(a)) => render::main(a),
        Some(Command::Accuracy(a)) => accuracy::main(a, &raw[2.min(raw.len())..]),
        Some(Command::Explain(a)) => explain::main(a),
        Some(Command::Stress(a)) => stress::main(a),
    };
    match result {
        Ok(0) => {}
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("error: {}", e.message());
            std::process::exit(e.code());
        }
    }
}

/// Signal dispositions of a command-line tool.
///
/// Rust ignores SIGPIPE, so that printing to a closed pipe (`raytrail --help | head -3`) is an
/// error, and `println!` panics on it. A command-line tool should do what the others do: end
/// quietly. Restoring the default action makes the process end on the signal.
///
/// SIGXFSZ (a write beyond the file size limit, `ulimit -f`) would kill the process in the middle
/// of a write, leaving its temporary file behind; ignored, the write fails with an error instead,
/// and the atomic write removes the temporary file and keeps the previous output.
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: setting signal actions at the start of main, before any other thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}
