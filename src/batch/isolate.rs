//! Per-object isolation: each object runs in a child process (the `grasp-sim` binary again), so
//! a panic, a crash (a signal, a stack overflow, an abort in a dependency), a run past the time
//! limit or memory exhaustion costs that object one error line and the batch goes on.
//!
//! The child is given the item's path and input hash and prints its record (one JSON line) on
//! stdout. The parent reads it, or, when there is none, writes the error line itself from how
//! the child ended: killed after `timeout` (`timed out`), ended by `SIGKILL` (on Linux, the
//! out-of-memory killer's signal, the cgroup limit of a Slurm job included), an allocation that
//! failed under the memory limit, another signal (`crashed`), or a nonzero exit. A child ended
//! by `SIGINT`, `SIGTERM`, `SIGHUP` or `SIGQUIT` was interrupted from outside (Ctrl-C, a
//! scheduler's preemption): it gets no line, so that `--resume` runs it again.

use super::record::{BatchInfo, Key, Record};
use super::Item;
use std::ffi::OsString;
use std::io::Read;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How to start the worker for one object.
#[derive(Debug, Clone)]
pub struct Worker {
    /// The program (the `grasp-sim` binary).
    pub program: PathBuf,
    /// Its arguments before the object's; the object's are `--input-hash HASH PATH`.
    pub args: Vec<OsString>,
    /// Kill a worker that runs longer than this.
    pub timeout: Option<Duration>,
    /// Limit each worker's memory (address space) to this many MiB.
    pub memory_limit_mib: Option<u64>,
    /// Threads each worker may use for the gravity directions of its physics check
    /// (`RAYON_NUM_THREADS`, unless set already): 1 when the batch's jobs are all busy with
    /// objects, more when there are fewer objects than jobs.
    pub threads: usize,
}

/// An object whose worker was interrupted from outside: no line, run it again on resume.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Interrupted(pub String);

/// Runs one object in a worker process and returns its record.
///
/// # Errors
/// [`Interrupted`] when the worker was ended by an interrupting signal.
pub fn run_isolated(item: &Item, key: &Key, worker: &Worker) -> Result<Record, Interrupted> {
    let t0 = Instant::now();
    let input = item.path().display().to_string();
    let fail = |message: String| {
        Record::from_error(
            &input,
            &format!("{input}: {message}"),
            BatchInfo {
                input: key.input.clone(),
                input_hash: key.input_hash.clone(),
                wall_ms: t0.elapsed().as_secs_f64() * 1000.0,
            },
        )
    };
    let child = match worker_command(item, key, worker).spawn() {
        Ok(c) => c,
        Err(e) => {
            return Ok(fail(format!(
                "cannot start the worker {}: {e}",
                worker.program.display()
            )))
        }
    };
    let ended = wait_for(child, worker.timeout);
    if ended.timed_out {
        let t = worker.timeout.unwrap_or_default().as_secs_f64();
        return Ok(fail(format!(
            "timed out: still running after {t} s (--object-timeout), stopped"
        )));
    }
    let status = match ended.status {
        Ok(s) => s,
        Err(e) => return Ok(fail(format!("lost the worker: {e}"))),
    };
    let last_err = last_error_line(&ended.stderr);
    if status.success() {
        return Ok(record_printed(&ended.stdout, key, &last_err).unwrap_or_else(fail));
    }
    failure(&status, &ended.stderr, &last_err, worker)
        .map(fail)
        .map_err(|sig| {
            Interrupted(format!(
                "{input}: interrupted ({}); --resume runs it again",
                signal_name(sig)
            ))
        })
}

/// Runs one object in a worker process that prints several lines (`label-worker`), calling
/// `on_line` with each complete line of its stdout as it comes, so that the caller can keep
/// what the worker finished before it failed. Returns `None` when the worker succeeded, or why
/// it failed in words (a timeout, a crash, memory, a nonzero exit).
///
/// # Errors
/// [`Interrupted`] when the worker was ended by an interrupting signal.
pub fn run_streaming(
    item: &Item,
    key: &Key,
    worker: &Worker,
    on_line: &(dyn Fn(&str) + Sync),
) -> Result<Option<String>, Interrupted> {
    let input = item.path().display().to_string();
    let mut child = match worker_command(item, key, worker).spawn() {
        Ok(c) => c,
        Err(e) => {
            return Ok(Some(format!(
                "cannot start the worker {}: {e}",
                worker.program.display()
            )))
        }
    };
    let stdout = child.stdout.take();
    let stderr = child.stderr.take().map(|mut s| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            let _ = s.read_to_end(&mut buf);
            buf
        })
    });
    let deadline = worker.timeout.map(|t| Instant::now() + t);
    let timed_out = std::sync::atomic::AtomicBool::new(false);
    let finished = std::sync::atomic::AtomicBool::new(false);
    let pid = child.id();
    std::thread::scope(|scope| {
        // The watchdog: kill the worker at the deadline.
        if let Some(deadline) = deadline {
            let (timed_out, finished) = (&timed_out, &finished);
            scope.spawn(move || watch(pid, deadline, timed_out, finished));
        }
        if let Some(out) = stdout {
            each_line(out, on_line);
        }
        finished.store(true, std::sync::atomic::Ordering::Relaxed);
    });
    let status = child.wait();
    let stderr = stderr.and_then(|h| h.join().ok()).unwrap_or_default();
    let stderr = String::from_utf8_lossy(&stderr).into_owned();
    if timed_out.load(std::sync::atomic::Ordering::Relaxed) {
        let t = worker.timeout.unwrap_or_default().as_secs_f64();
        return Ok(Some(format!(
            "timed out: still running after {t} s (--object-timeout), stopped"
        )));
    }
    let status = match status {
        Ok(s) => s,
        Err(e) => return Ok(Some(format!("lost the worker: {e}"))),
    };
    if status.success() {
        return Ok(None);
    }
    let last_err = last_error_line(&stderr);
    failure(&status, &stderr, &last_err, worker)
        .map(Some)
        .map_err(|sig| {
            Interrupted(format!(
                "{input}: interrupted ({}); --resume runs it again",
                signal_name(sig)
            ))
        })
}

/// Kills the worker `pid` at `deadline`, setting `timed_out`, unless `finished` is set first.
fn watch(
    pid: u32,
    deadline: Instant,
    timed_out: &std::sync::atomic::AtomicBool,
    finished: &std::sync::atomic::AtomicBool,
) {
    while !finished.load(std::sync::atomic::Ordering::Relaxed) {
        if Instant::now() >= deadline {
            timed_out.store(true, std::sync::atomic::Ordering::Relaxed);
            kill(pid);
            return;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Calls `on_line` with each line of `out` that is not blank, as it comes, until its end or
/// the first read that fails.
fn each_line(out: impl std::io::Read, on_line: &(dyn Fn(&str) + Sync)) {
    use std::io::BufRead;
    for line in std::io::BufReader::new(out).lines() {
        match line {
            Ok(l) if !l.trim().is_empty() => on_line(&l),
            Ok(_) => {}
            Err(_) => break,
        }
    }
}

/// Sends `SIGKILL` to the process `pid` (a worker past its time).
#[cfg(unix)]
fn kill(pid: u32) {
    // SAFETY: kill(2) on a child's pid; no memory is passed.
    unsafe {
        libc::kill(pid as libc::pid_t, libc::SIGKILL);
    }
}

#[cfg(not(unix))]
fn kill(_pid: u32) {}

/// The worker's command line for `item`: the worker's arguments, then `--input-hash HASH
/// PATH`, with its output piped, its threads and its memory limited.
fn worker_command(item: &Item, key: &Key, worker: &Worker) -> Command {
    let mut cmd = Command::new(&worker.program);
    cmd.args(&worker.args)
        .arg("--input-hash")
        .arg(&key.input_hash)
        .arg(item.path())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    // The batch's jobs are shared out: a worker's physics directions run on its share, as
    // they did on the batch's own threads.
    if std::env::var_os("RAYON_NUM_THREADS").is_none() {
        cmd.env("RAYON_NUM_THREADS", worker.threads.max(1).to_string());
    }
    limit_child(&mut cmd, worker.memory_limit_mib);
    cmd
}

/// How a worker ended: its exit status, what it printed, and whether it was killed at the
/// timeout.
struct Ended {
    status: std::io::Result<std::process::ExitStatus>,
    stdout: Vec<u8>,
    stderr: String,
    timed_out: bool,
}

/// Waits for `child` to close its stdout (it ends), up to `timeout`, killing it then; reads
/// its stdout and stderr on threads so that neither pipe fills up.
fn wait_for(mut child: std::process::Child, timeout: Option<Duration>) -> Ended {
    let (tx, rx) = std::sync::mpsc::channel();
    let stdout = child.stdout.take().map(|mut s| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            let _ = s.read_to_end(&mut buf);
            let _ = tx.send(());
            buf
        })
    });
    let stderr = child.stderr.take().map(|mut s| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            let _ = s.read_to_end(&mut buf);
            buf
        })
    });
    // The worker's stdout closes when it ends: wait for that, up to the timeout.
    let timed_out = match timeout {
        Some(t) => matches!(
            rx.recv_timeout(t),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout)
        ),
        None => {
            let _ = rx.recv();
            false
        }
    };
    if timed_out {
        let _ = child.kill();
    }
    let status = child.wait();
    let stdout = stdout.and_then(|h| h.join().ok()).unwrap_or_default();
    let stderr = stderr.and_then(|h| h.join().ok()).unwrap_or_default();
    Ended {
        status,
        stdout,
        stderr: String::from_utf8_lossy(&stderr).into_owned(),
        timed_out,
    }
}

/// The last line of a worker's stderr that says something (not a panic's notes about
/// backtraces), trimmed; empty when there is none.
fn last_error_line(stderr: &str) -> String {
    stderr
        .lines()
        .rev()
        .find(|l| {
            !l.trim().is_empty()
                && !l.starts_with("note: ")
                && !l.starts_with("stack backtrace")
                && !l.starts_with("skipping backtrace")
        })
        .unwrap_or("")
        .trim()
        .to_string()
}

/// The record a worker that succeeded printed as its last line, or what is wrong with it.
fn record_printed(stdout: &[u8], key: &Key, last_err: &str) -> Result<Record, String> {
    let text = String::from_utf8_lossy(stdout);
    let line = text.lines().rev().find(|l| !l.trim().is_empty());
    match line.map(Record::parse) {
        Some(Ok(r)) if r.key == *key => Ok(r),
        Some(Ok(r)) => Err(format!(
            "the worker answered for {} ({}), not for this input",
            r.key.input, r.key.input_hash
        )),
        Some(Err(why)) => Err(format!("the worker's line is unreadable: {why}")),
        None => Err(format!("the worker printed no line ({last_err})")),
    }
}

/// Why a worker that did not succeed failed, in words, from its status and stderr.
///
/// # Errors
/// The signal, when an interrupting signal ended it (it gets no line).
fn failure(
    status: &std::process::ExitStatus,
    stderr: &str,
    last_err: &str,
    worker: &Worker,
) -> Result<String, i32> {
    let with_err = |s: String| {
        if last_err.is_empty() {
            s
        } else {
            format!("{s}: {last_err}")
        }
    };
    let oom = stderr
        .lines()
        .find(|l| l.starts_with("memory allocation of"))
        .map(str::trim);
    match signal_of(status) {
        Some(sig) if is_interrupt(sig) => Err(sig),
        Some(sig) if oom.is_some() => Ok(format!(
            "out of memory{} ({}): {}",
            worker.memory_limit_mib.map_or(String::new(), |m| format!(
                " (limit {m} MiB, --object-memory)"
            )),
            signal_name(sig),
            oom.unwrap_or_default()
        )),
        Some(sig) if is_kill(sig) => Ok(format!(
            "killed ({}): out of memory? (the kernel's out-of-memory killer sends it)",
            signal_name(sig)
        )),
        Some(sig) => Ok(with_err(format!("crashed ({})", signal_name(sig)))),
        None => Ok(with_err(format!(
            "the worker exited with status {}",
            status.code().unwrap_or(-1)
        ))),
    }
}

#[cfg(unix)]
fn signal_of(status: &std::process::ExitStatus) -> Option<i32> {
    use std::os::unix::process::ExitStatusExt;
    status.signal()
}

#[cfg(not(unix))]
fn signal_of(_status: &std::process::ExitStatus) -> Option<i32> {
    None
}

#[cfg(unix)]
fn is_interrupt(sig: i32) -> bool {
    [libc::SIGINT, libc::SIGTERM, libc::SIGHUP, libc::SIGQUIT].contains(&sig)
}

#[cfg(not(unix))]
fn is_interrupt(_sig: i32) -> bool {
    false
}

#[cfg(unix)]
fn is_kill(sig: i32) -> bool {
    sig == libc::SIGKILL
}

#[cfg(not(unix))]
fn is_kill(_sig: i32) -> bool {
    false
}

/// `signal 9, SIGKILL`.
fn signal_name(sig: i32) -> String {
    #[cfg(unix)]
    let name = match sig {
        libc::SIGABRT => "SIGABRT",
        libc::SIGBUS => "SIGBUS",
        libc::SIGFPE => "SIGFPE",
        libc::SIGHUP => "SIGHUP",
        libc::SIGILL => "SIGILL",
        libc::SIGINT => "SIGINT",
        libc::SIGKILL => "SIGKILL",
        libc::SIGQUIT => "SIGQUIT",
        libc::SIGSEGV => "SIGSEGV",
        libc::SIGTERM => "SIGTERM",
        _ => "",
    };
    #[cfg(not(unix))]
    let name = "";
    if name.is_empty() {
        format!("signal {sig}")
    } else {
        format!("signal {sig}, {name}")
    }
}

/// In the child, before it runs: die with the parent (a killed batch leaves no workers behind)
/// and cap its address space.
#[cfg(unix)]
fn limit_child(cmd: &mut Command, memory_limit_mib: Option<u64>) {
    use std::os::unix::process::CommandExt;
    let parent = std::process::id() as libc::pid_t;
    // SAFETY: only async-signal-safe calls (prctl, getppid, setrlimit, _exit) between fork
    // and exec, on values computed before the fork.
    unsafe {
        cmd.pre_exec(move || {
            #[cfg(target_os = "linux")]
            {
                libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL as libc::c_ulong);
                if libc::getppid() != parent {
                    libc::_exit(1);
                }
            }
            #[cfg(not(target_os = "linux"))]
            let _ = parent;
            if let Some(mib) = memory_limit_mib {
                let bytes = mib.saturating_mul(1 << 20) as libc::rlim_t;
                let lim = libc::rlimit {
                    rlim_cur: bytes,
                    rlim_max: bytes,
                };
                if libc::setrlimit(libc::RLIMIT_AS, &lim) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
            }
            Ok(())
        });
    }
}

#[cfg(not(unix))]
fn limit_child(_cmd: &mut Command, _memory_limit_mib: Option<u64>) {}
