//! Writing a run's files so that an output folder never mixes two runs and nothing is written
//! outside it.
//!
//! - [`check_file_name`]: names that come from specs and flags are file names only — no
//!   separator, no `..`, not absolute, not hidden — so a run writes inside its folder.
//! - Temporary files are created exclusively (`O_CREAT | O_EXCL`, which also refuses a planted
//!   symlink) under an unpredictable name, `.<file>.partial-<random>`, in the output folder.
//! - [`RunFiles`]: a run stages its whole set of files as temporaries, then [`RunFiles::commit`]
//!   renames them into place and removes the files of the previous run that the new one does
//!   not have (a 1-sheet run after a 6-sheet one leaves no `job-2…6.plt`). Which files a run
//!   wrote is kept in the folder's manifest, `.flatcut-files`; while a commit is under way the
//!   manifest lists both runs' files, so a run killed at any point leaves the next one enough
//!   to clean up. A run also removes stale `.partial` files that a killed run left behind.
//! - [`write_atomic`]: one file, complete or absent; [`write_in_run`] adds one to the last
//!   run's set (the simulator's picture and report, written after the job was sent).
//!
//! Choices: the random part of a temporary name comes from the standard library's per-process
//! random hash keys (no extra dependency); only names listed in the manifest or shaped like a
//! temporary are ever removed, so files a user put in the folder stay.

use super::OutputError;
use std::collections::BTreeSet;
use std::hash::{BuildHasher, Hasher};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The folder's list of the files its last run wrote.
pub const MANIFEST: &str = ".flatcut-files";

/// Whether `name` is a plain file name (see the module doc); the error says what is wrong.
pub fn check_file_name(name: &str) -> Result<(), String> {
    let problem = if name.trim().is_empty() {
        Some("is empty")
    } else if name.contains('/') || name.contains('\\') {
        Some("contains a path separator")
    } else if name.contains("..") {
        Some("contains `..`")
    } else if name.starts_with('.') {
        Some("starts with `.` (a hidden file)")
    } else if name.chars().any(|c| c.is_control()) {
        Some("contains a control character")
    } else if name.len() > 200 {
        Some("is longer than 200 bytes")
    } else {
        None
    };
    match problem {
        Some(p) => Err(format!(
            "must be a file name (no `/`, `\\` or `..`, not absolute, not hidden); {name:?} {p}"
        )),
        None => Ok(()),
    }
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> OutputError + '_ {
    move |source| OutputError::Write {
        path: path.to_path_buf(),
        source,
    }
}

/// An unpredictable 64-bit number (the standard library's random hash keys, plus a counter).
fn random() -> u64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNT: AtomicU64 = AtomicU64::new(0);
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(COUNT.fetch_add(1, Ordering::Relaxed));
    h.write_u32(std::process::id());
    h.finish()
}

fn is_partial(name: &str) -> bool {
    name.starts_with('.') && name.contains(".partial-")
}

/// Create a temporary file for `path` exclusively in its folder, write `bytes` and flush it
/// to disk; returns its path.
fn write_temporary(path: &Path, bytes: &[u8]) -> Result<PathBuf, OutputError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut last = None;
    for _ in 0..16 {
        let tmp = path.with_file_name(format!(".{name}.partial-{:016x}", random()));
        let opened = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp);
        let mut f = match opened {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                last = Some(e);
                continue;
            }
            Err(e) => return Err(io_err(path)(e)),
        };
        let written = f.write_all(bytes).and_then(|()| f.sync_all());
        if let Err(e) = written {
            let _ = std::fs::remove_file(&tmp);
            return Err(io_err(path)(e));
        }
        return Ok(tmp);
    }
    Err(io_err(path)(last.unwrap_or_else(|| {
        std::io::Error::other("no free temporary name")
    })))
}

/// Write a file so that it is either complete or absent: write an exclusive temporary file
/// beside it, flush it to disk, then rename it over the final name.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let tmp = write_temporary(path, bytes)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io_err(path)(e)
    })
}

/// Write one more file of the folder's last run after its commit (the simulated cutter's
/// picture and report, written once the job was sent): atomically, and listed in the
/// manifest so that the next run removes it if it does not write it again.
pub fn write_in_run(dir: &Path, name: &str, bytes: &[u8]) -> Result<(), OutputError> {
    let path = dir.join(name);
    check_file_name(name)
        .map_err(|m| io_err(&path)(std::io::Error::new(std::io::ErrorKind::InvalidInput, m)))?;
    write_atomic(&path, bytes)?;
    let run = RunFiles {
        dir: dir.to_path_buf(),
        staged: Vec::new(),
    };
    let mut names = run.previous();
    if names.insert(name.to_string()) {
        run.write_manifest(&names)?;
    }
    Ok(())
}

/// Create the output directory.
pub fn create_dir(dir: &Path) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(io_err(dir))
}

/// The files of one run, staged in its output folder until [`RunFiles::commit`].
#[derive(Debug)]
pub struct RunFiles {
    dir: PathBuf,
    /// (file name, temporary path), in the order written.
    staged: Vec<(String, PathBuf)>,
}

impl RunFiles {
    /// Start a run in `dir` (created if needed); stale temporaries of killed runs are removed.
    pub fn begin(dir: &Path) -> Result<RunFiles, OutputError> {
        create_dir(dir)?;
        if let Ok(entries) = std::fs::read_dir(dir) {
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                let file = e.file_type().is_ok_and(|t| t.is_file() || t.is_symlink());
                if file && is_partial(&name) {
                    let _ = std::fs::remove_file(e.path());
                }
            }
        }
        Ok(RunFiles {
            dir: dir.to_path_buf(),
            staged: Vec::new(),
        })
    }

    /// The output folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Stage file `name` (a plain file name, [`check_file_name`]) with its bytes.
    pub fn write(&mut self, name: &str, bytes: &[u8]) -> Result<(), OutputError> {
        let path = self.dir.join(name);
        check_file_name(name)
            .map_err(|m| io_err(&path)(std::io::Error::new(std::io::ErrorKind::InvalidInput, m)))?;
        if let Some(k) = self.staged.iter().position(|(n, _)| n == name) {
            let (_, old) = self.staged.remove(k);
            let _ = std::fs::remove_file(old);
        }
        let tmp = write_temporary(&path, bytes)?;
        self.staged.push((name.to_string(), tmp));
        Ok(())
    }

    /// The previous run's files, from the manifest.
    fn previous(&self) -> BTreeSet<String> {
        let text = std::fs::read_to_string(self.dir.join(MANIFEST)).unwrap_or_default();
        text.lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && check_file_name(l).is_ok())
            .map(String::from)
            .collect()
    }

    fn write_manifest(&self, names: &BTreeSet<String>) -> Result<(), OutputError> {
        let mut text = String::new();
        for n in names {
            text.push_str(n);
            text.push('\n');
        }
        write_atomic(&self.dir.join(MANIFEST), text.as_bytes())
    }

    /// Put the staged files in place and remove the previous run's files that this run does
    /// not have (see the module doc).
    pub fn commit(mut self) -> Result<(), OutputError> {
        let old = self.previous();
        let new: BTreeSet<String> = self.staged.iter().map(|(n, _)| n.clone()).collect();
        let both: BTreeSet<String> = old.union(&new).cloned().collect();
        self.write_manifest(&both)?;
        for (name, tmp) in std::mem::take(&mut self.staged) {
            let path = self.dir.join(&name);
            std::fs::rename(&tmp, &path).map_err(|e| {
                let _ = std::fs::remove_file(&tmp);
                io_err(&path)(e)
            })?;
        }
        for gone in old.difference(&new) {
            let path = self.dir.join(gone);
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(io_err(&path)(e)),
                _ => {}
            }
        }
        self.write_manifest(&new)
    }
}

impl Drop for RunFiles {
    /// A run that did not commit leaves no temporaries.
    fn drop(&mut self) {
        for (_, tmp) in self.staged.drain(..) {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("flatcut-files-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn listing(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn names_must_be_plain_file_names() {
        for bad in [
            "../../escaped",
            "/etc/passwd",
            "a/b",
            "..",
            ".hidden",
            "",
            "a\\b",
            "x\0",
        ] {
            assert!(check_file_name(bad).is_err(), "{bad:?}");
        }
        for good in ["cube", "lamp shade", "job-1.plt", "taco_2"] {
            assert!(check_file_name(good).is_ok(), "{good:?}");
        }
    }

    #[test]
    fn a_run_replaces_the_previous_set() {
        let d = dir("set");
        let mut r = RunFiles::begin(&d).unwrap();
        for k in 1..=6 {
            r.write(&format!("job-{k}.plt"), b"IN;").unwrap();
        }
        r.write("report.json", b"{}").unwrap();
        r.commit().unwrap();
        std::fs::write(d.join("notes.txt"), "mine").unwrap();
        std::fs::write(d.join(".job.plt.partial-1234"), "stale").unwrap();
        let mut r = RunFiles::begin(&d).unwrap();
        r.write("job.plt", b"IN;").unwrap();
        r.write("report.json", b"{ }").unwrap();
        r.commit().unwrap();
        assert_eq!(
            listing(&d),
            vec![MANIFEST, "job.plt", "notes.txt", "report.json"]
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_planted_symlink_is_not_followed() {
        let d = dir("link");
        let target = d.join("target.txt");
        std::fs::write(&target, "keep").unwrap();
        #[cfg(unix)]
        for k in 0..4 {
            let _ = std::os::unix::fs::symlink(&target, d.join(format!(".out.plt.partial-{k}")));
        }
        write_atomic(&d.join("out.plt"), b"IN;").unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
        assert_eq!(std::fs::read(d.join("out.plt")).unwrap(), b"IN;");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn an_uncommitted_run_leaves_nothing() {
        let d = dir("drop");
        {
            let mut r = RunFiles::begin(&d).unwrap();
            r.write("a.svg", b"<svg/>").unwrap();
        }
        assert!(listing(&d).is_empty(), "{:?}", listing(&d));
        let _ = std::fs::remove_dir_all(&d);
    }
}
