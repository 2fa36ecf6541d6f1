//! One outside run: start the process, write its input, read its output
//! (within its cap), end it and everything it started.

use std::io::Write;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use crate::limits::{Limits, Meter};
use crate::stream::{Chunks, Piece, Tail};
use crate::tree::{self, Mark};

/// How often a process that keeps its standard output open (a descendant
/// holding the pipe) is checked for having exited.
const EXIT_POLL: Duration = Duration::from_millis(20);
/// How long, once the process and its descendants are ended, what is left
/// in the pipes is waited for.
const DRAIN: Duration = Duration::from_secs(1);

/// What a finished process produced.
#[derive(Debug)]
pub struct ProcessOutput {
    /// Its standard output (at most the run's `max_bytes`).
    pub stdout: Vec<u8>,
    /// The end of its standard error (its last 64 KiB).
    pub stderr: Vec<u8>,
    /// How it exited.
    pub status: ExitStatus,
    /// From the start to the exit.
    pub elapsed: Duration,
}

/// Why a process produced no output to read: it did not start, it ran
/// past the deadline, or its output passed its cap (then it was killed);
/// with the end of its standard error.
#[derive(Debug)]
pub struct ProcessError {
    /// What happened, one sentence.
    pub what: String,
    /// The end of its standard error up to then.
    pub stderr: Vec<u8>,
}

/// Starts `program args` in `dir` (in a process group of its own), writes
/// `input` to its standard input and closes it, and reads its standard
/// output as it comes until it exits; then ends every process it started
/// and is still running. Past `timeout`, or once the output passes
/// `limits`, the process and its descendants are killed and the run is a
/// [`ProcessError`] saying which; the output is never held beyond the cap.
pub fn run_process(
    program: &Path,
    args: &[String],
    dir: &Path,
    input: &[u8],
    timeout: Duration,
    limits: Limits,
) -> Result<ProcessOutput, ProcessError> {
    let start = Instant::now();
    let mut command = Command::new(program);
    command
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mark = Mark::apply(&mut command);
    let mut child = tree::spawn(&mut command).map_err(|e| ProcessError {
        what: format!("could not start `{}`: {e}", program.display()),
        stderr: Vec::new(),
    })?;
    let mut stdin = child.stdin.take().expect("piped");
    let mut out = Chunks::spawn(child.stdout.take().expect("piped"));
    let err = Tail::spawn(child.stderr.take().expect("piped"));
    let input = input.to_vec();
    // A process that exits without reading its input closes the pipe: the
    // write fails then, and its exit status says the rest.
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let deadline = start + timeout;
    let fail = |child: &mut std::process::Child, what: String, timed_out: bool| {
        let _ = tree::end(child, &mark);
        if timed_out {
            // What it left behind outside its group and environment.
            tree::end_orphans();
        }
        ProcessError {
            what,
            stderr: err.get(Duration::from_millis(200)),
        }
    };
    let mut meter = Meter::new(limits);
    let mut stdout = Vec::new();
    // Until the end of its standard output, or its exit while a descendant
    // holds the pipe open.
    let mut exited = false;
    loop {
        let now = Instant::now();
        if now >= deadline {
            return Err(fail(
                &mut child,
                format!(
                    "still running after its timeout of {} s: killed",
                    timeout.as_secs_f64()
                ),
                true,
            ));
        }
        match out.next(deadline.min(now + EXIT_POLL)) {
            Some(Piece::Bytes(b)) => {
                if let Err(what) = meter.add(&b) {
                    return Err(fail(&mut child, what, false));
                }
                stdout.extend_from_slice(&b);
            }
            Some(Piece::End) => break,
            None if tree::has_exited(&mut child) => {
                exited = true;
                break;
            }
            None => {}
        }
    }
    let mut pause = Duration::from_micros(50);
    while !exited && !tree::has_exited(&mut child) {
        let now = Instant::now();
        if now >= deadline {
            return Err(fail(
                &mut child,
                format!(
                    "closed its standard output but was still running after its timeout of {} s: killed",
                    timeout.as_secs_f64()
                ),
                true,
            ));
        }
        std::thread::sleep(pause.min(deadline - now));
        pause = (pause * 2).min(Duration::from_millis(5));
    }
    let elapsed = start.elapsed();
    // Whatever it left running ends with it.
    let status = tree::end(&mut child, &mark).map_err(|e| ProcessError {
        what: format!("could not wait for it: {e}"),
        stderr: Vec::new(),
    })?;
    let drain_until = Instant::now() + DRAIN;
    while let Some(Piece::Bytes(b)) = out.next(drain_until) {
        if let Err(what) = meter.add(&b) {
            return Err(ProcessError {
                what,
                stderr: err.get(Duration::from_millis(200)),
            });
        }
        stdout.extend_from_slice(&b);
    }
    let _ = writer.join();
    Ok(ProcessOutput {
        stdout,
        stderr: err.get(Duration::from_millis(200)),
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
