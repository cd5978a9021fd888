//! The `raytrail` command line: the main job (no arguments), `trace`, `rays`, `bench`, `render`,
//! `accuracy`, `explain` and `stress`. Flags are declared with clap in [`args`]; usage errors exit with status
//! 2, failures while working with status 1.

// `outln!`, `out!`, `errln!` and `err!` (raytrail_cli::output): printing that never panics.
#[macro_use]
extern crate raytrail_cli;

mod accuracy;
mod args;
mod auto;
mod bench;
mod explain;
mod failure;
mod flags;
mod gpu;
mod instances;
mod limits;
mod median;
mod nearest;
mod progress;
mod queries;
mod render;
mod run;
mod stress;
mod svg;
mod trace;

use args::{Cli, Command};
use clap::{CommandFactory, FromArgMatches};

fn main() {
    restore_sigpipe();
    let raw: Vec<String> = std::env::args_os().map(|a| a.to_string_lossy().into_owned()).collect();
    // Usage errors exit with status 2; `--help` and `--version` print and exit with 0, or with 1
    // and one line when stdout cannot take them.
    let cli = match parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            if let Err(io) = e.print() {
                raytrail_cli::output::stdout_failed(&io);
            }
            raytrail_cli::output::flush_stdout();
            std::process::exit(0)
        }
        Err(e) => e.exit(),
    };
    let result = match cli.command {
        None => run::main(cli.run),
        Some(Command::Run(a)) => run::main(a),
        Some(Command::Trace(a)) => trace::main(a),
        Some(Command::Nearest(a)) => nearest::main(a),
        Some(Command::Rays(a)) => trace::rays_main(a),
        // The report records the command as given.
        Some(Command::Bench(a)) => bench::main(a, &raw[2.min(raw.len())..]),
        Some(Command::Render(a)) => render::main(a),
        Some(Command::Accuracy(a)) => accuracy::main(a, &raw[2.min(raw.len())..]),
        Some(Command::Explain(a)) => explain::main(a),
        Some(Command::Stress(a)) => stress::main(a),
    };
    raytrail_cli::output::flush_stdout();
    match result {
        Ok(0) => {}
        Ok(code) => std::process::exit(code),
        Err(e) => {
            errln!("error: {}", e.message());
            std::process::exit(e.code());
        }
    }
}

/// The arguments, with a negative number after any flag read as its value, so that
/// `--max-mesh-bytes -5` is an error naming the flag rather than "unexpected argument '-5'".
fn parse() -> Result<Cli, clap::Error> {
    let negatives = |c: clap::Command| {
        c.mut_args(|a| {
            let takes_values = a.get_action().takes_values();
            a.allow_negative_numbers(takes_values)
        })
    };
    let command = negatives(Cli::command()).mut_subcommands(negatives);
    Cli::from_arg_matches(&command.try_get_matches()?)
}

/// Signal dispositions of a command-line tool.
///
/// Rust ignores SIGPIPE, so that printing to a closed pipe (`raytrail --help | head -3`) is an
/// error, and `outln!` panics on it. A command-line tool should do what the others do: end
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
