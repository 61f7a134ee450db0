//! The `--out FILE --resume` file: records appended as objects finish, read back on resume.
//!
//! Crash safety: each record is written with one `write` of the whole line and its newline,
//! then `fdatasync`, so a killed run leaves whole lines and at most one partial last line (no
//! newline). A reader that takes only newline-terminated lines never takes it as data; resuming
//! cuts it off before appending. While a run appends, the file is locked (`flock`), so a second
//! run on the same file fails at once instead of interleaving with the first. At the end the
//! file is rewritten in input order through a temporary file and a rename.

use super::record::Record;
use super::BatchError;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Records read from a file, with their line numbers (1-based).
#[derive(Debug, Default)]
pub struct ReadRecords {
    /// The records, in file order, each with its line number.
    pub records: Vec<(usize, Record)>,
    /// Bytes after the last newline: a line an interrupted run left half written.
    pub partial_bytes: usize,
}

/// Reads the records of a batch file. A last line without its newline is not a record (it is
/// counted in `partial_bytes`); blank lines are skipped.
///
/// # Errors
/// [`BatchError::Io`] when the file cannot be read, [`BatchError::NotARecord`] for a complete
/// line that is not a batch record.
pub fn read_records(path: &Path) -> Result<ReadRecords, BatchError> {
    let bytes = crate::files::read_regular(path, crate::files::MAX_RESULTS_BYTES)
        .map_err(|e| BatchError::io(path, e))?;
    parse_records(path, &bytes)
}

/// The most records a batch file read back may hold (`--resume`, `--merge`): a batch of a
/// million objects. Each record read takes some 1.6 KB besides its line, so a file of short
/// lines within the 1 GiB cap (27 million) would take some 40 GB.
pub const MAX_RECORDS: usize = 1_000_000;

fn parse_records(path: &Path, bytes: &[u8]) -> Result<ReadRecords, BatchError> {
    let complete = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let mut out = ReadRecords {
        records: Vec::new(),
        partial_bytes: bytes.len() - complete,
    };
    let mut count = 0;
    for (i, line) in bytes[..complete].split(|&b| b == b'\n').enumerate() {
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        count += 1;
        if count > MAX_RECORDS {
            return Err(BatchError::NotARecord {
                path: path.to_path_buf(),
                line: i + 1,
                why: format!("more than the {MAX_RECORDS} records a batch file may hold"),
            });
        }
        let not_record = |why: String| BatchError::NotARecord {
            path: path.to_path_buf(),
            line: i + 1,
            why,
        };
        let text = std::str::from_utf8(line).map_err(|_| not_record("not UTF-8".into()))?;
        let record =
            Record::parse(text.trim_end_matches('\r')).map_err(|e| not_record(e.to_string()))?;
        out.records.push((i + 1, record));
    }
    Ok(out)
}

/// A batch file open for appending, locked against a second writer.
#[derive(Debug)]
pub struct Journal {
    path: PathBuf,
    file: Mutex<File>,
}

impl Journal {
    /// Opens `path` to resume: creates it when missing, locks it, cuts off a partial last line,
    /// and returns the records it holds.
    ///
    /// # Errors
    /// [`BatchError::Io`] when it cannot be opened, read or cut; [`BatchError::Locked`] when
    /// another run holds it; [`BatchError::NotARecord`] when a line is not a batch record (the
    /// file was not written by `batch`: it is left untouched).
    pub fn open(path: &Path) -> Result<(Journal, ReadRecords), BatchError> {
        // Opening a FIFO to append would block until a reader came: only a regular file, or
        // none yet.
        if path.exists() {
            crate::files::check_regular(path, crate::files::MAX_RESULTS_BYTES)
                .map_err(|e| BatchError::io(path, e))?;
        }
        let mut options = OpenOptions::new();
        options.read(true).append(true).create(true);
        // A link or a FIFO put there since the check above: never followed, never waited on.
        #[cfg(unix)]
        {
            use std::os::unix::fs::OpenOptionsExt;
            options.custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK);
        }
        let file = options.open(path).map_err(|e| BatchError::io(path, e))?;
        if !file.metadata().is_ok_and(|m| m.is_file()) {
            return Err(BatchError::io(
                path,
                std::io::Error::other("not a regular file: outputs replace regular files only"),
            ));
        }
        lock(&file, path)?;
        let bytes = crate::files::read_regular(path, crate::files::MAX_RESULTS_BYTES)
            .map_err(|e| BatchError::io(path, e))?;
        let read = parse_records(path, &bytes)?;
        if read.partial_bytes > 0 {
            file.set_len((bytes.len() - read.partial_bytes) as u64)
                .map_err(|e| BatchError::io(path, e))?;
        }
        Ok((
            Journal {
                path: path.to_path_buf(),
                file: Mutex::new(file),
            },
            read,
        ))
    }

    /// Opens `path` to resume a file of JSON lines of any kind (`label`'s): as [`Journal::open`]
    /// (created when missing, locked, a partial last line cut off) without reading its lines
    /// as batch records; returns the bytes cut off.
    ///
    /// # Errors
    /// As [`Journal::open`], but for the records.
    pub fn open_lines(path: &Path) -> Result<(Journal, usize), BatchError> {
        if path.exists() {
            crate::files::check_regular(path, crate::files::MAX_RESULTS_BYTES)
                .map_err(|e| BatchError::io(path, e))?;
        }
        let file = OpenOptions::new()
            .read(true)
            .append(true)
            .create(true)
            .open(path)
            .map_err(|e| BatchError::io(path, e))?;
        lock(&file, path)?;
        let bytes = crate::files::read_regular(path, crate::files::MAX_RESULTS_BYTES)
            .map_err(|e| BatchError::io(path, e))?;
        let complete = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let partial = bytes.len() - complete;
        if partial > 0 {
            file.set_len(complete as u64)
                .map_err(|e| BatchError::io(path, e))?;
        }
        Ok((
            Journal {
                path: path.to_path_buf(),
                file: Mutex::new(file),
            },
            partial,
        ))
    }

    /// Appends one line of text (no newline in it): one write of the line and its newline,
    /// then a sync to disk.
    ///
    /// # Errors
    /// [`BatchError::Io`] when the write or the sync fails.
    pub fn append_line(&self, line: &str) -> Result<(), BatchError> {
        let mut buf = Vec::with_capacity(line.len() + 1);
        buf.extend_from_slice(line.as_bytes());
        buf.push(b'\n');
        let mut file = self.file.lock().unwrap_or_else(|p| p.into_inner());
        file.write_all(&buf)
            .and_then(|()| file.sync_data())
            .map_err(|e| BatchError::io(&self.path, e))
    }

    /// Appends one record: one write of the line and its newline, then a sync to disk.
    ///
    /// # Errors
    /// [`BatchError::Io`] when the write or the sync fails.
    pub fn append(&self, record: &Record) -> Result<(), BatchError> {
        let mut buf = Vec::with_capacity(record.line.len() + 1);
        buf.extend_from_slice(record.line.as_bytes());
        buf.push(b'\n');
        let mut file = self.file.lock().unwrap_or_else(|p| p.into_inner());
        file.write_all(&buf)
            .and_then(|()| file.sync_data())
            .map_err(|e| BatchError::io(&self.path, e))
    }

    /// Replaces the file with `bytes` (the records in input order), atomically, and releases
    /// the lock.
    ///
    /// # Errors
    /// [`BatchError::Io`] when the new file cannot be written.
    pub fn finish(self, bytes: &[u8]) -> Result<(), BatchError> {
        // The lock is held (on the old file) until the new one has replaced it.
        let result = write_atomically(&self.path, bytes);
        drop(self.file);
        result
    }
}

/// Writes `bytes` to `path` through a temporary file beside it and a rename, so a reader never
/// sees half a file.
///
/// # Errors
/// [`BatchError::Io`] naming `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), BatchError> {
    crate::files::write_replacing(path, bytes).map_err(|e| BatchError::io(path, e))
}

/// The lock every batch run that writes `--out FILE` holds for its whole run, plain or
/// `--resume`: a file `.FILE.lock` beside it, locked with `flock` (released if the run dies),
/// and removed at the end. A second run on the same file is refused at once, before it runs
/// anything, instead of one run's lines replacing the other's.
#[derive(Debug)]
pub struct RunLock {
    path: PathBuf,
    file: Option<File>,
}

impl RunLock {
    /// Takes the run lock of the results file `out`.
    ///
    /// # Errors
    /// [`BatchError::Locked`] when another run holds it; [`BatchError::Io`] when the lock file
    /// cannot be made.
    pub fn take(out: &Path) -> Result<RunLock, BatchError> {
        let dir = out
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let name = out
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let path = dir.join(format!(".{name}.lock"));
        // A run that ends removes its lock file while it holds it: a run that opened the name
        // just before may then lock the removed file. It takes the lock only on the file the
        // name still is, and tries again otherwise.
        loop {
            let mut options = OpenOptions::new();
            options.write(true).create(true).truncate(false);
            #[cfg(unix)]
            {
                use std::os::unix::fs::OpenOptionsExt;
                options.custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK);
            }
            let file = options.open(&path).map_err(|e| BatchError::io(&path, e))?;
            lock(&file, out)?;
            if same_file(&file, &path) {
                return Ok(RunLock {
                    path,
                    file: Some(file),
                });
            }
        }
    }
}

impl Drop for RunLock {
    fn drop(&mut self) {
        // Removed while still held, so no other run can lock the name being removed.
        let _ = std::fs::remove_file(&self.path);
        drop(self.file.take());
    }
}

#[cfg(unix)]
fn lock(file: &File, path: &Path) -> Result<(), BatchError> {
    use std::os::fd::AsRawFd;
    // SAFETY: flock on a file descriptor this function borrows; no memory is passed.
    let r = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if r == 0 {
        return Ok(());
    }
    let e = std::io::Error::last_os_error();
    if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
        return Err(BatchError::Locked {
            path: path.to_path_buf(),
        });
    }
    // A filesystem without locks (some network mounts): go on unlocked.
    Ok(())
}

#[cfg(not(unix))]
fn lock(_file: &File, _path: &Path) -> Result<(), BatchError> {
    Ok(())
}

/// Returns true if and only if `path` is (still) the file `file` has open.
#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::symlink_metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_file: &File, _path: &Path) -> bool {
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::record::BatchInfo;

    fn record(input: &str) -> Record {
        Record::from_error(
            input,
            "e",
            BatchInfo {
                input: input.to_string(),
                input_hash: "sha256:1".to_string(),
                wall_ms: 0.0,
            },
        )
    }

    #[test]
    fn a_partial_last_line_is_cut_and_appends_follow_whole_lines() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.jsonl");
        let a = record("a");
        std::fs::write(&path, format!("{}\n{{\"scenario\":\"b\",\"err", a.line)).unwrap();
        let (j, read) = Journal::open(&path).unwrap();
        assert_eq!(read.records.len(), 1);
        assert_eq!(read.records[0].1, a);
        assert_eq!(read.partial_bytes, 20);
        let b = record("b");
        j.append(&b).unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            format!("{}\n{}\n", a.line, b.line)
        );
        // A second writer is refused while the first holds the file.
        match Journal::open(&path) {
            Err(BatchError::Locked { .. }) => {}
            other => panic!("expected Locked, got {other:?}"),
        }
        j.finish(format!("{}\n", b.line).as_bytes()).unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            format!("{}\n", b.line)
        );
        let (_, read) = Journal::open(&path).unwrap();
        assert_eq!(read.records.len(), 1);
    }

    #[test]
    fn a_file_of_other_lines_is_left_alone() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("notes.txt");
        std::fs::write(&path, "hello\n").unwrap();
        let e = Journal::open(&path).unwrap_err().to_string();
        assert!(e.contains("notes.txt") && e.contains("line 1"), "{e}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "hello\n");
    }
}
