//! Atomic file output: every file snee writes goes to a temporary file in the destination's
//! folder, is flushed to disk, and is then renamed over the destination.
//!
//! A rename within one file system replaces the destination in one step (POSIX `rename(2)`), so
//! a reader — or a later `--resume` — sees either the previous complete file or the new complete
//! file, never a truncated one, whatever interrupts the writer (an error, a panic, `kill -9`, a
//! power cut after the data reached the disk). A failed write removes its temporary file; one left
//! by a killed process is named `.NAME.tmp-PID-N` beside the destination and is never read.

use anyhow::Context;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Where a write to `path` is staged: a hidden file in the same folder, unique per process and call.
fn temp_path_for(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "output".into());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()))
}

/// Removes the temporary file unless the write was committed.
struct TempGuard(Option<PathBuf>);

impl Drop for TempGuard {
    fn drop(&mut self) {
        if let Some(p) = self.0.take() {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// Write `path` atomically: `write` fills a temporary file (given by its path, in the same folder),
/// which is then synced and renamed onto `path`. On any error (or a panic in `write`) `path` is
/// left as it was and the temporary file is removed. The destination's folder must exist.
pub fn write_with<F>(path: &Path, write: F) -> anyhow::Result<()>
where
    F: FnOnce(&Path) -> anyhow::Result<()>,
{
    let tmp = temp_path_for(path);
    let mut guard = TempGuard(Some(tmp.clone()));
    write(&tmp)?;
    // Data first on disk, then the rename: a crash never publishes a file with missing blocks.
    File::open(&tmp)
        .and_then(|f| f.sync_all())
        .with_context(|| format!("writing {} (syncing {})", path.display(), tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("writing {} (renaming {})", path.display(), tmp.display()))?;
    guard.0 = None;
    // Make the rename itself durable (best effort: not every platform can sync a folder).
    if let Some(dir) = path.parent() {
        let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

/// Write `bytes` to `path` atomically (see [`write_with`]).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    write_with(path, |tmp| {
        let mut f =
            File::create(tmp).with_context(|| format!("writing {} (creating {})", path.display(), tmp.display()))?;
        f.write_all(bytes).with_context(|| format!("writing {}", path.display()))?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("snee-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn replaces_the_file() {
        let d = folder("replace");
        let p = d.join("a.txt");
        write_bytes(&p, b"first").unwrap();
        write_bytes(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        assert_eq!(entries(&d), ["a.txt"]);
    }

    /// A write that fails half way (an error after some bytes) or panics leaves the previous file
    /// intact and no temporary file behind.
    #[test]
    fn interrupted_write_keeps_previous_file() {
        let d = folder("interrupt");
        let p = d.join("image.exr");
        write_bytes(&p, b"previous complete file").unwrap();
        let err = write_with(&p, |tmp| {
            std::fs::write(tmp, b"half of the new fi")?;
            anyhow::bail!("disk full")
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"previous complete file");
        let panicked = std::panic::catch_unwind(|| {
            let _ = write_with(&p, |tmp| {
                std::fs::write(tmp, b"half")?;
                panic!("killed mid-write")
            });
        });
        assert!(panicked.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"previous complete file");
        assert_eq!(entries(&d), ["image.exr"]);
    }

    #[test]
    fn missing_folder_is_an_error_naming_the_file() {
        let d = folder("missing");
        let p = d.join("no/such/folder/x.json");
        let e = write_bytes(&p, b"{}").unwrap_err();
        assert!(format!("{e:#}").contains("x.json"), "{e:#}");
    }
}
