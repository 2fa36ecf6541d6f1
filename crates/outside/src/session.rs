//! Sessions: one adapter process serving many problems (`session = true`).
//!
//! pushval writes one `pushval-problem/2` document per line; the adapter
//! answers each with the CSV header, its rows and a line `#end` (flushed),
//! or ends a failed answer with a line `#error MESSAGE` and goes on; closing
//! its standard input ends the session.
//!
//! A pool keeps the processes between runs: at most one per core
//! ([`std::thread::available_parallelism`]) over all engines, each serving
//! one run at a time; a run takes an idle session of its engine, else
//! starts one, else ends an idle session of another engine, else waits for
//! one to be handed back. A session that dies, times out, passes its output
//! cap or breaks the protocol is ended (with every process it started) and
//! the next run starts a fresh one. [`shutdown_sessions`] ends them all;
//! a dropped session ends its process too.

use std::io::Write;
use std::path::PathBuf;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc::{channel, Sender};
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use crate::config::Spec;
use crate::limits::{Limits, Meter};
use crate::process::ProcessError;
use crate::stream::{Chunks, Piece, Tail};
use crate::tree::{self, Mark};

/// How long a session whose standard input is closed is given to exit on
/// its own before it is killed, at shutdown.
const GRACE: Duration = Duration::from_secs(2);
/// How long the end of standard error is waited for after an `#error`
/// answer (the session goes on, so its standard error does not close).
const ERROR_TAIL_WAIT: Duration = Duration::from_millis(20);

/// Which process a session is: the engine's declaration.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Key {
    file: PathBuf,
    name: String,
    command: Vec<String>,
    dir: PathBuf,
}

impl Key {
    fn of(spec: &Spec) -> Self {
        Self {
            file: spec.file.clone(),
            name: spec.name.clone(),
            command: spec.command.clone(),
            dir: spec.dir.clone(),
        }
    }
}

/// One answer of a session.
#[derive(Debug)]
pub(crate) struct Answer {
    /// The CSV (header and rows), without the `#end` line.
    pub stdout: Vec<u8>,
    /// From writing the document to the `#end` line.
    pub elapsed: Duration,
    /// The session's process id.
    pub pid: u32,
    /// How many problems this process had answered before this one.
    pub answered_before: u64,
    /// The end of the session's standard error (earlier answers' lines
    /// included).
    pub stderr: Vec<u8>,
}

/// How an answer failed.
enum Fail {
    /// `#error MESSAGE`: the session goes on.
    Refused(String),
    /// Died, timed out, passed its cap: the session must end.
    Broken(String),
}

/// One adapter process serving problems.
struct Session {
    key: Key,
    child: Child,
    mark: Mark,
    /// Documents to write (a thread writes them, so a process that does not
    /// read cannot block a run past its timeout); None once closed.
    input: Option<Sender<Vec<u8>>>,
    out: Chunks,
    err: Tail,
    /// Bytes read after the last answer's `#end`.
    carry: Vec<u8>,
    answered: u64,
    ended: bool,
}

impl Session {
    fn start(spec: &Spec, key: Key) -> Result<Self, ProcessError> {
        let program = spec.program();
        let mut command = Command::new(&program);
        command
            .args(&spec.command[1..])
            .current_dir(&spec.dir)
            // How an adapter tells a session from a one-shot run (the kit,
            // `pushval.adapter`, reads it): documents one per line, each
            // answer ended by `#end` or `#error MESSAGE`.
            .env("PUSHVAL_SESSION", "1")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        let mark = Mark::apply(&mut command);
        let mut child = command.spawn().map_err(|e| ProcessError {
            what: format!("could not start `{}`: {e}", program.display()),
            stderr: Vec::new(),
        })?;
        let mut stdin = child.stdin.take().expect("piped");
        let out = Chunks::spawn(child.stdout.take().expect("piped"));
        let err = Tail::spawn(child.stderr.take().expect("piped"));
        let (tx, rx) = channel::<Vec<u8>>();
        std::thread::spawn(move || {
            for doc in rx {
                if stdin.write_all(&doc).and_then(|()| stdin.flush()).is_err() {
                    return;
                }
            }
            // The sender is gone: standard input closes here.
        });
        Ok(Self {
            key,
            child,
            mark,
            input: Some(tx),
            out,
            err,
            carry: Vec::new(),
            answered: 0,
            ended: false,
        })
    }

    fn alive(&mut self) -> bool {
        !self.ended && !tree::has_exited(&mut self.child)
    }

    /// Writes `doc` (one line) and reads the answer up to its `#end`.
    fn answer(&mut self, doc: Vec<u8>, limits: Limits, timeout: Duration) -> Result<Vec<u8>, Fail> {
        let deadline = Instant::now() + timeout;
        let sent = self.input.as_ref().is_some_and(|tx| tx.send(doc).is_ok());
        if !sent {
            return Err(Fail::Broken(
                "its standard input is closed (the session has ended)".into(),
            ));
        }
        let mut meter = Meter::new(limits);
        let mut answer = std::mem::take(&mut self.carry);
        meter.add(&answer).map_err(Fail::Broken)?;
        let mut scanned = 0;
        loop {
            while let Some(i) = answer[scanned..].iter().position(|&b| b == b'\n') {
                let end = scanned + i;
                let line = answer[scanned..end]
                    .strip_suffix(b"\r")
                    .unwrap_or(&answer[scanned..end]);
                if line == b"#end" {
                    self.carry = answer.split_off(end + 1);
                    answer.truncate(scanned);
                    self.answered += 1;
                    return Ok(answer);
                }
                if let Some(rest) = line.strip_prefix(b"#error") {
                    if rest.is_empty() || rest[0] == b' ' {
                        let message = String::from_utf8_lossy(rest).trim().to_string();
                        self.carry = answer.split_off(end + 1);
                        self.answered += 1;
                        return Err(Fail::Refused(message));
                    }
                }
                scanned = end + 1;
            }
            match self.out.next(deadline) {
                Some(Piece::Bytes(b)) => {
                    meter.add(&b).map_err(Fail::Broken)?;
                    answer.extend_from_slice(&b);
                }
                Some(Piece::End) => {
                    return Err(Fail::Broken(
                        "closed its standard output before the answer's `#end` line (the session ended mid-answer)".into(),
                    ))
                }
                None => {
                    return Err(Fail::Broken(format!(
                        "gave no `#end` line within its timeout of {} s: killed",
                        timeout.as_secs_f64()
                    )))
                }
            }
        }
    }

    /// Ends the process and everything it started, at once.
    fn end(&mut self) -> Option<ExitStatus> {
        if self.ended {
            return None;
        }
        self.ended = true;
        self.input = None;
        tree::end(&mut self.child, &self.mark).ok()
    }

    /// Closes standard input, gives the process until `until` to exit,
    /// then ends it and everything it started.
    fn close(&mut self, until: Instant) {
        self.input = None;
        while !tree::has_exited(&mut self.child) && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(2));
        }
        self.end();
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        self.end();
    }
}

/// The sessions kept between runs.
struct Pool {
    idle: Vec<Session>,
    /// Sessions started and not ended (idle or serving a run).
    live: usize,
}

static POOL: Mutex<Pool> = Mutex::new(Pool {
    idle: Vec::new(),
    live: 0,
});
static FREED: Condvar = Condvar::new();

fn pool() -> MutexGuard<'static, Pool> {
    POOL.lock().unwrap_or_else(|e| e.into_inner())
}

/// At most this many sessions at once: one per core.
fn most() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// A session of `spec`'s engine, for one run.
fn checkout(spec: &Spec) -> Result<Session, ProcessError> {
    let key = Key::of(spec);
    let mut g = pool();
    loop {
        if let Some(i) = g.idle.iter().position(|s| s.key == key) {
            let mut s = g.idle.remove(i);
            drop(g);
            if s.alive() {
                return Ok(s);
            }
            release(s);
            g = pool();
            continue;
        }
        if g.live < most() {
            g.live += 1;
            drop(g);
            return Session::start(spec, key).inspect_err(|_| {
                pool().live -= 1;
                FREED.notify_all();
            });
        }
        if !g.idle.is_empty() {
            // The least recently used session of another engine.
            let s = g.idle.remove(0);
            drop(g);
            release(s);
            g = pool();
            continue;
        }
        g = FREED.wait(g).unwrap_or_else(|e| e.into_inner());
    }
}

/// Hands a healthy session back.
fn checkin(s: Session) {
    pool().idle.push(s);
    FREED.notify_all();
}

/// Ends a session and frees its place.
fn release(mut s: Session) {
    s.end();
    pool().live -= 1;
    FREED.notify_all();
}

/// Answers one problem (`doc`: one line, its newline included) on a
/// session of `spec`'s engine, within `timeout` and `limits`.
pub(crate) fn answer(
    spec: &Spec,
    doc: Vec<u8>,
    limits: Limits,
    timeout: Duration,
) -> Result<Answer, ProcessError> {
    let mut s = checkout(spec)?;
    let start = Instant::now();
    let answered_before = s.answered;
    let pid = s.child.id();
    match s.answer(doc, limits, timeout) {
        Ok(stdout) => {
            let elapsed = start.elapsed();
            let stderr = s.err.get(Duration::ZERO);
            checkin(s);
            Ok(Answer {
                stdout,
                elapsed,
                pid,
                answered_before,
                stderr,
            })
        }
        Err(Fail::Refused(message)) => {
            let stderr = s.err.get(ERROR_TAIL_WAIT);
            checkin(s);
            Err(ProcessError {
                what: format!("answered `#error {message}` (session process {pid})"),
                stderr,
            })
        }
        Err(Fail::Broken(what)) => {
            let status = s.end();
            let stderr = s.err.get(Duration::from_millis(200));
            release(s);
            let how = match status.map(|st| (st.code(), st)) {
                Some((Some(c), _)) => format!("; its process {pid} exited with status {c}"),
                Some((None, st)) => format!("; its process {pid} was ended by a signal ({st})"),
                None => String::new(),
            };
            Err(ProcessError {
                what: format!(
                    "{what}{how}; the session is ended and the next run starts a new one"
                ),
                stderr,
            })
        }
    }
}

/// Ends every idle session (pushval calls it before it exits): closes their
/// standard input, gives them a moment to exit on their own, then ends each
/// with every process it started. A session serving a run is left to it.
pub fn shutdown_sessions() {
    let idle = {
        let mut g = pool();
        let idle = std::mem::take(&mut g.idle);
        g.live -= idle.len();
        idle
    };
    FREED.notify_all();
    let mut idle = idle;
    for s in &mut idle {
        s.input = None;
    }
    let until = Instant::now() + GRACE;
    for s in &mut idle {
        s.close(until);
    }
}

/// How many session processes are running (idle or serving a run).
pub fn live_sessions() -> usize {
    pool().live
}
