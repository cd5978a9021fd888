//! The error of mesh loading: which file, where in it, and what is wrong.

use core::fmt;
use std::error::Error;
use std::io;
use std::string::String;

/// A mesh file could not be loaded.
///
/// Displays as `<file>:<line>: <message>` for text (ASCII PLY, OBJ, PLY headers),
/// `<file>: byte <offset>: <message>` for binary PLY bodies, and `<file>: <message>` where no
/// position applies (I/O, gzip, empty file).
#[derive(Debug)]
pub struct MeshError {
    /// The file (or the name given for in-memory data).
    pub path: String,
    /// 1-based line of the problem in a text file or header.
    pub line: Option<usize>,
    /// Byte offset of the problem in a binary PLY body (counted in the decompressed data).
    pub offset: Option<u64>,
    /// What is wrong.
    pub message: String,
    source: Option<io::Error>,
}

impl MeshError {
    /// An error with no position in the file.
    pub fn new(path: &str, message: impl Into<String>) -> MeshError {
        MeshError { path: path.into(), line: None, offset: None, message: message.into(), source: None }
    }

    /// An error at a 1-based line.
    pub fn at_line(path: &str, line: usize, message: impl Into<String>) -> MeshError {
        MeshError { line: Some(line), ..MeshError::new(path, message) }
    }

    /// An error at a byte offset of binary data.
    pub fn at_offset(path: &str, offset: u64, message: impl Into<String>) -> MeshError {
        MeshError { offset: Some(offset), ..MeshError::new(path, message) }
    }

    /// An I/O failure (file missing, unreadable, corrupt compressed stream), keeping the cause.
    pub fn io(path: &str, what: &str, err: io::Error) -> MeshError {
        MeshError { source: Some(err), ..MeshError::new(path, what) }
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.path)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(offset) = self.offset {
            write!(f, ": byte {offset}")?;
        }
        write!(f, ": {}", self.message)?;
        // The cause is part of the one-line message: most callers print only Display.
        if let Some(err) = &self.source {
            write!(f, ": {err}")?;
        }
        Ok(())
    }
}

impl Error for MeshError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        self.source.as_ref().map(|e| e as &(dyn Error + 'static))
    }
}
