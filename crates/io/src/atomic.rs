//! Atomic file output: write `<name>.tmp-<pid>-<seq>` beside the target, then
//! rename. A failed or panicking writer leaves no file behind.

use crate::IoError;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static SEQ: AtomicU64 = AtomicU64::new(0);

/// Removes the temp file unless `done` was set (covers errors and panics).
struct TempGuard {
    tmp: PathBuf,
    done: bool,
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// The temp path used for `path`: same directory, so the rename is atomic.
/// The sequence number keeps threads of one process apart.
fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    let mut tmp = name;
    tmp.push(format!(
        ".tmp-{}-{}",
        std::process::id(),
        SEQ.fetch_add(1, Ordering::Relaxed)
    ));
    path.with_file_name(tmp)
}

/// Runs `f` on a buffered writer to a temp file, then renames it to `path`.
/// On any error the temp file is removed and `path` is left untouched.
pub fn write_atomic<F>(path: &Path, f: F) -> Result<(), IoError>
where
    F: FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
{
    let io = |source| IoError::Io {
        path: path.to_path_buf(),
        source,
    };
    if path.file_name().is_none() {
        return Err(IoError::BadInput {
            path: path.to_path_buf(),
            msg: "not a file name".into(),
        });
    }
    let tmp = temp_path(path);
    let file = File::create(&tmp).map_err(io)?;
    let mut guard = TempGuard { tmp, done: false };
    let mut w = BufWriter::with_capacity(1 << 20, file);
    f(&mut w).map_err(io)?;
    w.flush().map_err(io)?;
    drop(w);
    std::fs::rename(&guard.tmp, path).map_err(io)?;
    guard.done = true;
    Ok(())
}
