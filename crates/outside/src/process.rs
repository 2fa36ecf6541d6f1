//! One outside run: start the process, write its input, read its output,
//! kill it at the deadline.

use std::io::{Read, Write};
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// What a finished process produced.
#[derive(Debug)]
pub struct ProcessOutput {
    /// Its standard output.
    pub stdout: Vec<u8>,
    /// Its standard error.
    pub stderr: Vec<u8>,
    /// How it exited.
    pub status: ExitStatus,
    /// From the start to the exit.
    pub elapsed: Duration,
}

/// Why a process produced no output to read: it did not start, or it ran
/// past the deadline (and was killed); with its standard error so far.
#[derive(Debug)]
pub struct ProcessError {
    /// What happened, one sentence.
    pub what: String,
    /// Its standard error up to then.
    pub stderr: Vec<u8>,
}

/// Starts `program args` in `dir` (in a process group of its own), writes
/// `input` to its standard input and closes it, and collects both outputs
/// until it exits. Past `timeout` the process group is killed and the run is
/// a [`ProcessError`].
pub fn run_process(
    program: &Path,
    args: &[String],
    dir: &Path,
    input: &[u8],
    timeout: Duration,
) -> Result<ProcessOutput, ProcessError> {
    use std::os::unix::process::CommandExt;
    let start = Instant::now();
    let mut child = Command::new(program)
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0)
        .spawn()
        .map_err(|e| ProcessError {
            what: format!("could not start `{}`: {e}", program.display()),
            stderr: Vec::new(),
        })?;
    let mut stdin = child.stdin.take().expect("piped");
    let mut stdout = child.stdout.take().expect("piped");
    let mut stderr = child.stderr.take().expect("piped");
    let input = input.to_vec();
    // A process that exits without reading its input closes the pipe: the
    // write fails then, and its exit status says the rest.
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut buf = Vec::new();
        let r = stdout.read_to_end(&mut buf);
        let _ = tx.send((buf, r.is_ok()));
    });
    let (etx, erx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut buf = Vec::new();
        let _ = stderr.read_to_end(&mut buf);
        let _ = etx.send(buf);
    });
    let deadline = start + timeout;
    let kill = |child: &mut std::process::Child| {
        let _ = rustix::process::kill_process_group(
            rustix::process::Pid::from_child(child),
            rustix::process::Signal::KILL,
        );
        let _ = child.kill();
        let _ = child.wait();
    };
    let remaining = || deadline.saturating_duration_since(Instant::now());
    // Standard output closes when the process exits (or closes it).
    let out = match rx.recv_timeout(remaining()) {
        Ok((buf, _)) => buf,
        Err(_) => {
            kill(&mut child);
            let stderr = erx
                .recv_timeout(Duration::from_millis(200))
                .unwrap_or_default();
            return Err(ProcessError {
                what: format!(
                    "still running after its timeout of {} s: killed",
                    timeout.as_secs_f64()
                ),
                stderr,
            });
        }
    };
    let mut pause = Duration::from_micros(50);
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break s,
            Ok(None) if Instant::now() >= deadline => {
                kill(&mut child);
                let stderr = erx
                    .recv_timeout(Duration::from_millis(200))
                    .unwrap_or_default();
                return Err(ProcessError {
                    what: format!(
                        "closed its standard output but was still running after its timeout of {} s: killed",
                        timeout.as_secs_f64()
                    ),
                    stderr,
                });
            }
            Ok(None) => {
                std::thread::sleep(pause.min(remaining()));
                pause = (pause * 2).min(Duration::from_millis(5));
            }
            Err(e) => {
                kill(&mut child);
                return Err(ProcessError {
                    what: format!("could not wait for it: {e}"),
                    stderr: Vec::new(),
                });
            }
        }
    };
    let elapsed = start.elapsed();
    let _ = writer.join();
    // A grandchild may hold standard error open: wait briefly, not forever.
    let stderr = erx
        .recv_timeout(remaining().max(Duration::from_millis(100)))
        .unwrap_or_default();
    Ok(ProcessOutput {
        stdout: out,
        stderr,
        status,
        elapsed,
    })
}

/// The last `n` non-empty lines of a process's standard error, indented,
/// or a note that it is empty.
pub(crate) fn last_lines(stderr: &[u8], n: usize) -> String {
    let text = String::from_utf8_lossy(stderr);
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    if lines.is_empty() {
        return "its standard error is empty".into();
    }
    let from = lines.len().saturating_sub(n);
    format!(
        "the last lines of its standard error:\n    {}",
        lines[from..].join("\n    ")
    )
}
