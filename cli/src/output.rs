//! Printing that never panics: `println!` and `eprintln!` panic when their stream cannot be
//! written (stdout on a full disk: `raytrail bench > /dev/full`). [`outln!`](crate::outln) and
//! [`out!`](crate::out) end the process with status 1 and one line on stderr instead;
//! [`errln!`](crate::errln) and [`err!`](crate::err) drop what stderr cannot take, since there is nowhere left to say so.

use std::fmt;
use std::io::{self, Write};

/// Writes `args` to stdout, then a newline if `newline`; a failed write ends the process
/// ([`stdout_failed`]).
pub fn to_stdout(args: fmt::Arguments<'_>, newline: bool) {
    let mut out = io::stdout().lock();
    let written = out.write_fmt(args).and_then(|()| if newline { out.write_all(b"\n") } else { Ok(()) });
    if let Err(e) = written {
        drop(out);
        stdout_failed(&e);
    }
}

/// Writes `args` to stderr, then a newline if `newline`; what stderr cannot take is dropped.
pub fn to_stderr(args: fmt::Arguments<'_>, newline: bool) {
    let mut err = io::stderr().lock();
    let _ = err.write_fmt(args).and_then(|()| if newline { err.write_all(b"\n") } else { Ok(()) });
}

/// Ends the process after stdout failed: quietly for a closed pipe (what the other tools do, and
/// what SIGPIPE would have done), with status 1 and one line on stderr for any other error.
pub fn stdout_failed(e: &io::Error) -> ! {
    if e.kind() != io::ErrorKind::BrokenPipe {
        to_stderr(format_args!("error: cannot write to stdout: {e}"), true);
    }
    std::process::exit(1)
}

/// Flushes stdout before the process ends, so that an error in the last buffered bytes is
/// reported too ([`stdout_failed`]).
pub fn flush_stdout() {
    if let Err(e) = io::stdout().lock().flush() {
        stdout_failed(&e);
    }
}

/// `println!` to stdout through [`to_stdout`]: a write error ends the process with status 1.
#[macro_export]
macro_rules! outln {
    () => { $crate::output::to_stdout(format_args!(""), true) };
    ($($arg:tt)*) => { $crate::output::to_stdout(format_args!($($arg)*), true) };
}

/// `print!` to stdout through [`to_stdout`]: a write error ends the process with status 1.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => { $crate::output::to_stdout(format_args!($($arg)*), false) };
}

/// `eprintln!` through [`to_stderr`]: never panics.
#[macro_export]
macro_rules! errln {
    () => { $crate::output::to_stderr(format_args!(""), true) };
    ($($arg:tt)*) => { $crate::output::to_stderr(format_args!($($arg)*), true) };
}

/// `eprint!` through [`to_stderr`]: never panics.
#[macro_export]
macro_rules! err {
    ($($arg:tt)*) => { $crate::output::to_stderr(format_args!($($arg)*), false) };
}
