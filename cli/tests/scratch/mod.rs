//! A scratch folder per test: made fresh under the system's temporary folder, removed when the test
//! ends, kept (its path printed) when the test fails, so that the files a failure left can be read.

use std::ffi::OsStr;
use std::ops::Deref;
use std::path::Path;

/// A test's own folder; see the module docs.
pub struct Scratch(tempfile::TempDir);

impl Scratch {
    /// A fresh folder named after `test`.
    pub fn new(test: &str) -> Self {
        Self(tempfile::Builder::new().prefix(&format!("raytrail-{test}-")).tempdir().expect("a scratch folder"))
    }
}

/// The folder's path: `dir.join(name)` names a file in it, `&dir` passes where a `&Path` goes.
impl Deref for Scratch {
    type Target = Path;

    fn deref(&self) -> &Path {
        self.0.path()
    }
}

/// For the file system's functions.
impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        self.0.path()
    }
}

/// For arguments of a command.
impl AsRef<OsStr> for Scratch {
    fn as_ref(&self) -> &OsStr {
        self.0.path().as_os_str()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.disable_cleanup(true);
            eprintln!("the failed test's files are kept in {}", self.0.path().display());
        }
    }
}
