//! Reading input files safely: regular files only (a FIFO would block for ever, `/dev/zero`
//! would never end), and at most a stated size, so that no input can hang the tool or exhaust
//! its memory. Every reader of an input file (meshes, URDFs, scenarios, hands, results files,
//! and the batch's input hash) goes through here. Every output file is written through
//! [`write_replacing`]: a temporary file beside it, then a rename onto a regular file or a new
//! path, so a reader never sees half a file and an error (a full disk) leaves none behind.

use std::io::{self, Read};
use std::path::Path;

/// The largest mesh file read `[bytes]`: 256 MiB, a binary STL of 5.6 million triangles (the
/// largest scans of the real-object set are under 15 MB).
pub const MAX_MESH_BYTES: u64 = 256 << 20;
/// The largest scenario, hand or URDF file read `[bytes]`: 16 MiB.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;
/// The largest results file read (`summarize`, `--resume`, `--merge`) `[bytes]`: 1 GiB.
pub const MAX_RESULTS_BYTES: u64 = 1 << 30;

/// The longest JSON line read from a results or grasps file `[bytes]`: 16 MiB, some 300 times
/// a batch record (45 KB) and 5,000 times a label line. A line of numbers parses to some 16
/// times its length in memory (32 times for a batch record read back), so a 1 GiB file of one
/// line would take more memory than a machine has.
pub const MAX_JSON_LINE_BYTES: usize = 16 << 20;

/// Parses one line of a JSON-lines file, refusing a line longer than [`MAX_JSON_LINE_BYTES`]
/// before the parser allocates for it.
///
/// # Errors
/// The line is too long, or not JSON (the parser's message).
pub fn parse_json_line(line: &str) -> Result<serde_json::Value, String> {
    if line.len() > MAX_JSON_LINE_BYTES {
        return Err(format!(
            "a line of {} bytes, longer than the {} a line may have",
            line.len(),
            size(MAX_JSON_LINE_BYTES as u64)
        ));
    }
    serde_json::from_str(line).map_err(|e| format!("not JSON ({e})"))
}

/// `n` bytes in the largest binary unit that keeps it whole-ish: `256 MiB`, `16 MiB`, `1 GiB`.
fn size(n: u64) -> String {
    if n >= 1 << 30 && n.is_multiple_of(1 << 30) {
        format!("{} GiB", n >> 30)
    } else if n >= 1 << 20 {
        format!("{} MiB", n >> 20)
    } else {
        format!("{n} bytes")
    }
}

/// What a path that is not a regular file is, in words.
fn kind(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a folder"
    } else {
        "not a file"
    }
}

/// Checks that `path` is a regular file (following symbolic links) of at most `limit` bytes,
/// without opening it; returns its length.
///
/// # Errors
/// The operating system's error (no such file, permission denied), or one saying what the
/// path is instead (`not a regular file (a FIFO)`) or how large it is against the limit.
pub fn check_regular(path: &Path, limit: u64) -> io::Result<u64> {
    let meta = std::fs::metadata(path)?;
    if !meta.file_type().is_file() {
        return Err(io::Error::other(format!(
            "not a regular file ({})",
            kind(meta.file_type())
        )));
    }
    if meta.len() > limit {
        return Err(too_large(meta.len(), limit));
    }
    Ok(meta.len())
}

fn too_large(len: u64, limit: u64) -> io::Error {
    io::Error::other(format!(
        "{} bytes, more than the {} a file may have here",
        len,
        size(limit)
    ))
}

/// Reads a regular file of at most `limit` bytes whole (a file that grows past the limit while
/// it is read is refused too).
///
/// # Errors
/// As [`check_regular`], and any error reading it.
pub fn read_regular(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let len = check_regular(path, limit)?;
    let mut bytes = Vec::with_capacity(len as usize);
    std::fs::File::open(path)?
        .take(limit + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64, limit));
    }
    Ok(bytes)
}

/// Reads a regular UTF-8 text file of at most `limit` bytes.
///
/// # Errors
/// As [`read_regular`]; text that is not UTF-8 is [`io::ErrorKind::InvalidData`], as
/// [`std::fs::read_to_string`] reports it.
pub fn read_regular_string(path: &Path, limit: u64) -> io::Result<String> {
    String::from_utf8(read_regular(path, limit)?).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

/// Feeds a regular file of at most `limit` bytes to `sink` in chunks (for hashing without
/// holding it); returns how many bytes it had.
///
/// # Errors
/// As [`read_regular`].
pub fn stream_regular(path: &Path, limit: u64, sink: &mut dyn FnMut(&[u8])) -> io::Result<u64> {
    check_regular(path, limit)?;
    let mut file = std::fs::File::open(path)?.take(limit + 1);
    let mut buf = vec![0u8; 1 << 16];
    let mut total = 0u64;
    loop {
        let n = file.read(&mut buf)?;
        if n == 0 {
            break;
        }
        total += n as u64;
        if total > limit {
            return Err(too_large(total, limit));
        }
        sink(&buf[..n]);
    }
    Ok(total)
}

/// Checks that writing `path` by a rename would replace a regular file or make a new one:
/// renaming onto a device node or a symbolic link would replace the node or the link itself.
///
/// # Errors
/// One saying what the path is instead.
pub fn check_replaceable(path: &Path) -> io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
        Ok(m) if m.file_type().is_file() => Ok(()),
        Ok(m) if m.file_type().is_symlink() => Err(io::Error::other(
            "a symbolic link: outputs replace regular files only (give the file it points to)",
        )),
        Ok(m) => Err(io::Error::other(format!(
            "not a regular file ({}): outputs replace regular files only",
            kind(m.file_type())
        ))),
    }
}

/// The most bytes one name in a path may have: the common file systems' limit (`NAME_MAX`).
pub const MAX_NAME_BYTES: usize = 255;

/// The most bytes an output folder's name may have (a scenario's `name`): room under
/// [`MAX_NAME_BYTES`] for the `-N` a repeated name gets and a temporary file's suffix.
pub const MAX_FOLDER_NAME_BYTES: usize = 200;

/// What is wrong with `name` as the name of one folder inside an output folder (`--report
/// DIR`, `--export-mjcf DIR`, `--export-urdf DIR`), or `None` when nothing is: it must be one
/// name, not empty, not `.` or `..`, without `/` or `\` (an absolute name starts with `/`),
/// NUL or other control characters, and at most [`MAX_FOLDER_NAME_BYTES`] bytes. Joined onto
/// the folder given, such a name stays inside it.
pub fn folder_name_problem(name: &str) -> Option<String> {
    if name.is_empty() {
        return Some("is empty".to_string());
    }
    if name == "." || name == ".." {
        return Some(format!("is `{name}`, which names no folder of its own"));
    }
    if let Some(c) = name
        .chars()
        .find(|&c| c == '/' || c == '\\' || c.is_control())
    {
        let what = match c {
            '/' => "`/`".to_string(),
            '\\' => "`\\`".to_string(),
            '\0' => "a NUL byte".to_string(),
            c => format!("the control character U+{:04X}", u32::from(c)),
        };
        return Some(format!("contains {what}"));
    }
    if name.len() > MAX_FOLDER_NAME_BYTES {
        return Some(format!(
            "has {} bytes, more than the {MAX_FOLDER_NAME_BYTES} a folder name may have here",
            name.len()
        ));
    }
    None
}

/// `name` made a folder name ([`folder_name_problem`] finds nothing in it): each `/`, `\`
/// and control character replaced by `_`, `.` and `..` (and an empty name) prefixed with `_`,
/// and cut (at a character boundary) to [`MAX_FOLDER_NAME_BYTES`]. What a mesh's file stem
/// becomes when it names a run; a name that is one already is kept as it is.
pub fn folder_name(name: &str) -> String {
    let mut out: String = name
        .chars()
        .map(|c| {
            if c == '/' || c == '\\' || c.is_control() {
                '_'
            } else {
                c
            }
        })
        .collect();
    if out.is_empty() || out == "." || out == ".." {
        out.insert(0, '_');
    }
    let mut keep = out.len().min(MAX_FOLDER_NAME_BYTES);
    while !out.is_char_boundary(keep) {
        keep -= 1;
    }
    out.truncate(keep);
    out
}

/// A name no other writer of this or another process is using in `dir`: `.NAME.PID.N.tmp`,
/// `NAME` shortened (at a character boundary) to keep the whole within [`MAX_NAME_BYTES`].
fn temporary_name(dir: &Path, name: &str, what: &str) -> std::path::PathBuf {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let suffix = format!(".{}.{n}.{what}", std::process::id());
    let mut keep = MAX_NAME_BYTES
        .saturating_sub(1 + suffix.len())
        .min(name.len());
    while !name.is_char_boundary(keep) {
        keep -= 1;
    }
    dir.join(format!(".{}{suffix}", &name[..keep]))
}

/// Creates a new file at a name no one else uses in `dir` (see [`temporary_name`]), never
/// through an existing file or link (`O_EXCL`); returns it with its path.
///
/// # Errors
/// The operating system's error creating it.
pub fn create_private(
    dir: &Path,
    name: &str,
    what: &str,
) -> io::Result<(std::fs::File, std::path::PathBuf)> {
    loop {
        let path = temporary_name(dir, name, what);
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
        {
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
            Ok(f) => return Ok((f, path)),
        }
    }
}

/// Writes `bytes` to `path` through a temporary file beside it (`.NAME.PID.N.tmp`, made new,
/// so that two writers never share one and no link is followed), synced, and a rename: `path`
/// is then either its old self or whole. On any error, a full disk included, the temporary
/// file is removed and `path` is left as it was. Only a regular file or a new path is replaced
/// ([`check_replaceable`], checked before the write and again before the rename): never a
/// symbolic link, a device or a FIFO, and nothing is ever opened at `path` itself, so a FIFO
/// there cannot block the write. Every output file of grasp-sim is written here.
///
/// Test hook, debug builds only: with `GRASP_SIM_TEST_FAULT=enospc:NAME`, writing a file whose
/// path contains `NAME` writes half its bytes and then fails as a full disk does (`ENOSPC`),
/// so the tests can show that nothing half-written remains. Release builds never read it.
///
/// # Errors
/// [`check_replaceable`]'s, or the error creating, writing, syncing or renaming the file.
pub fn write_replacing(path: &Path, bytes: &[u8]) -> io::Result<()> {
    use std::io::Write;
    check_replaceable(path)?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if name.len() > MAX_NAME_BYTES {
        return Err(io::Error::other(format!(
            "its name has {} bytes, more than the {MAX_NAME_BYTES} a file system takes",
            name.len()
        )));
    }
    let (mut f, tmp) = create_private(dir, &name, "tmp").map_err(|e| {
        if e.kind() == io::ErrorKind::NotFound {
            io::Error::other(format!("no folder {}", dir.display()))
        } else {
            e
        }
    })?;
    let written = if full_disk_fault(path) {
        f.write_all(&bytes[..bytes.len() / 2])
            .and_then(|()| Err(io::Error::from_raw_os_error(28)))
    } else {
        f.write_all(bytes).and_then(|()| f.sync_data())
    };
    drop(f);
    written
        .and_then(|()| check_replaceable(path))
        .and_then(|()| std::fs::rename(&tmp, path))
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
}

/// Checks that a file can be made in the folder `dir`: makes one at a name no one else uses
/// and removes it (two runs checking one folder at once do not see each other's).
///
/// # Errors
/// The operating system's error.
pub fn check_writable_dir(dir: &Path) -> io::Result<()> {
    let (f, probe) = create_private(dir, ".grasp-sim-write-test", "probe")?;
    drop(f);
    std::fs::remove_file(&probe)
}

/// Whether the debug-build fault hook of [`write_replacing`] asks this write to fail.
fn full_disk_fault(path: &Path) -> bool {
    #[cfg(debug_assertions)]
    if let Ok(fault) = std::env::var("GRASP_SIM_TEST_FAULT") {
        if let Some(("enospc", name)) = fault.split_once(':') {
            return path.to_string_lossy().contains(name);
        }
    }
    let _ = path;
    false
}

/// The lock one run holds on an output folder (`--report DIR`, `--export-mjcf DIR`,
/// `--export-urdf DIR`, `tune --out DIR`) for as long as it writes there: a file
/// `.grasp-sim.lock` in the folder, locked with `flock` (released if the run dies) and removed
/// when the run ends. A second run into the same folder is refused at once with the lock's
/// message, instead of the two runs' files mixing (or one run's check of the folder seeing the
/// other's files come and go).
#[derive(Debug)]
pub struct FolderLock {
    path: std::path::PathBuf,
    file: Option<std::fs::File>,
}

impl FolderLock {
    /// Locks the folder `dir`, which must exist.
    ///
    /// # Errors
    /// [`io::ErrorKind::WouldBlock`] with a message saying another run holds the folder, or
    /// the operating system's error making the lock file.
    pub fn take(dir: &Path) -> io::Result<FolderLock> {
        let path = dir.join(".grasp-sim.lock");
        // A run that ends removes the lock file while it holds it; a run that opened the name
        // just before would then hold a removed file. The lock counts only on the file the name
        // still is; otherwise the open is tried again.
        loop {
            let mut options = std::fs::OpenOptions::new();
            options.write(true).create(true).truncate(false);
            #[cfg(unix)]
            {
                use std::os::unix::fs::OpenOptionsExt;
                options.custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK);
            }
            let file = options.open(&path)?;
            if !lock_exclusive(&file)? {
                return Err(io::Error::new(
                    io::ErrorKind::WouldBlock,
                    "in use by another grasp-sim run (locked); one run per output folder",
                ));
            }
            if is_same_file(&file, &path) {
                return Ok(FolderLock {
                    path,
                    file: Some(file),
                });
            }
        }
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Removed while still held, so no other run can lock the name being removed.
        let _ = std::fs::remove_file(&self.path);
        drop(self.file.take());
    }
}

/// Takes `flock`'s exclusive lock on `file` without waiting: false if another holds it. A
/// file system without locks (some network mounts) counts as locked by this run.
#[cfg(unix)]
fn lock_exclusive(file: &std::fs::File) -> io::Result<bool> {
    use std::os::fd::AsRawFd;
    // SAFETY: flock on a file descriptor borrowed for the call; no memory is passed.
    let r = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if r == 0 {
        return Ok(true);
    }
    let e = io::Error::last_os_error();
    Ok(e.raw_os_error() != Some(libc::EWOULDBLOCK))
}

#[cfg(not(unix))]
fn lock_exclusive(_file: &std::fs::File) -> io::Result<bool> {
    Ok(true)
}

/// Returns true if and only if `path` is (still) the file `file` has open.
#[cfg(unix)]
fn is_same_file(file: &std::fs::File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::symlink_metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn is_same_file(_file: &std::fs::File, _path: &Path) -> bool {
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_are_read_and_others_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("a.txt");
        std::fs::write(&f, b"hello").unwrap();
        assert_eq!(read_regular(&f, 5).unwrap(), b"hello");
        let e = read_regular(&f, 4).unwrap_err().to_string();
        assert_eq!(e, "5 bytes, more than the 4 bytes a file may have here");
        let e = read_regular(dir.path(), 100).unwrap_err().to_string();
        assert_eq!(e, "not a regular file (a folder)");
        #[cfg(unix)]
        {
            let e = read_regular(Path::new("/dev/zero"), 100)
                .unwrap_err()
                .to_string();
            assert_eq!(e, "not a regular file (a device)");
        }
        let mut seen: Vec<u8> = Vec::new();
        assert_eq!(stream_regular(&f, 5, &mut |b| seen.extend(b)).unwrap(), 5);
        assert_eq!(seen, b"hello");
        std::fs::write(&f, [0xff, 0xfe]).unwrap();
        let e = read_regular_string(&f, 5).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
        assert_eq!(size(MAX_MESH_BYTES), "256 MiB");
        assert_eq!(size(MAX_RESULTS_BYTES), "1 GiB");
    }

    #[test]
    fn folder_names_stay_inside_their_folder() {
        for bad in [
            "",
            ".",
            "..",
            "../../escape",
            "/abs",
            "a\\b",
            "a\0b",
            "a\nb",
        ] {
            assert!(folder_name_problem(bad).is_some(), "{bad:?}");
            let fixed = folder_name(bad);
            assert_eq!(folder_name_problem(&fixed), None, "{bad:?} -> {fixed:?}");
            let joined = Path::new("/out").join(&fixed);
            assert_eq!(joined.parent(), Some(Path::new("/out")), "{fixed:?}");
        }
        assert_eq!(folder_name("../../escape"), ".._.._escape");
        assert_eq!(folder_name(".."), "_..");
        assert_eq!(folder_name_problem("a\0b").unwrap(), "contains a NUL byte");
        for good in ["cup", "cup 2", "textured", ".hidden", "a..b", "é"] {
            assert_eq!(folder_name_problem(good), None, "{good:?}");
            assert_eq!(folder_name(good), good);
        }
        let long = "é".repeat(150);
        assert!(folder_name_problem(&long).unwrap().contains("300 bytes"));
        assert_eq!(folder_name(&long).len(), MAX_FOLDER_NAME_BYTES);
    }

    #[test]
    fn a_replacing_write_is_whole_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("out.json");
        std::fs::write(&f, b"old").unwrap();
        write_replacing(&f, b"new contents").unwrap();
        assert_eq!(std::fs::read(&f).unwrap(), b"new contents");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // A folder in the way of the rename: the error, the old folder kept, no temporary file.
        let d = dir.path().join("taken");
        std::fs::create_dir(&d).unwrap();
        std::fs::write(d.join("x"), b"x").unwrap();
        assert!(write_replacing(&d, b"data").is_err());
        assert!(d.is_dir());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }
}
