//! Sessions: one adapter process serving many requests (`session = true`).
//!
//! pushval starts the process with `PUSHVAL_SESSION=1` in its environment
//! (no argument) and writes one JSON document per line, each carrying
//! `"request": N` (1, 2, … for each process: unique and increasing). With
//! protocol 2 a document is a whole `pushval-problem/2` problem, answered by
//! the CSV header, its rows and `#end N`; with protocol 3 it is a `start`
//! (answered `#ok N`), an `advance` (its rows, then `#end N`) or a `finish`
//! (`#end N`). `#error N MESSAGE` fails that request and the session goes
//! on; closing its standard input ends the session. A closing line without
//! a number, with another request's number (a second answer to an earlier
//! document), with the wrong word, or output after an answer was closed and
//! before the next request, is a protocol error: the session is ended and
//! the run fails naming the engine and the request. A process that has not
//! answered its first document after 5 s gets a warning naming the likely
//! cause (a protocol 1 adapter under `session = true`).
//!
//! A pool keeps the processes between runs: at most one per core
//! ([`std::thread::available_parallelism`]) over all engines, each serving
//! one run (or one stepping session) at a time; a run takes an idle session
//! of its engine, else starts one, else ends an idle session of another
//! engine, else waits for one to be handed back. A session that dies, times
//! out, passes its output cap or breaks the protocol is ended (with every
//! process it started) and the next run starts a fresh one.
//! [`shutdown_sessions`] ends them all; a dropped session ends its process
//! too.

use std::os::fd::{AsFd, OwnedFd};
use std::path::PathBuf;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use crate::config::Spec;
use crate::limits::{Limits, Meter};
use crate::process::ProcessError;
use crate::stream::{Direct, Filled, Input, Tail};
use crate::tree::{self, Mark};

/// How long a session whose standard input is closed is given to exit on
/// its own before it is killed, at shutdown.
const GRACE: Duration = Duration::from_secs(2);
/// How long the end of standard error is waited for after an `#error`
/// answer (the session goes on, so its standard error does not close).
const ERROR_TAIL_WAIT: Duration = Duration::from_millis(20);
/// How often a session without an exit watch ([`tree::exit_watch`]) is
/// asked whether it has exited while an answer is awaited.
const EXIT_POLL: Duration = Duration::from_millis(20);
/// How long a session that closed its standard output mid-answer is given
/// to exit on its own (so its own exit status is reported, not the kill's).
const EXIT_WAIT: Duration = Duration::from_millis(500);

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

/// How an answer must close: `#ok N` (a protocol 3 `start`) or `#end N`
/// (everything else); `#error N MESSAGE` closes any.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Close {
    /// `#ok N`, nothing before it.
    Ok,
    /// `#end N`, after the answer's rows.
    End,
}

impl Close {
    fn word(self) -> &'static str {
        match self {
            Close::Ok => "#ok",
            Close::End => "#end",
        }
    }
}

/// One answer of a session.
#[derive(Debug)]
pub(crate) struct Answer {
    /// The answer's lines (the CSV header and rows), without its closing
    /// line.
    pub stdout: Vec<u8>,
    /// From writing the document to the closing line.
    pub elapsed: Duration,
    /// The session's process id.
    pub pid: u32,
    /// The request number the document carried and the answer closed with.
    pub request: u64,
    /// How many documents this process had answered before this one.
    pub answered_before: u64,
    /// The session's standard error, whose end [`Answer::stderr`] reads
    /// (only when a message quotes it).
    pub(crate) err: Tail,
}

impl Answer {
    /// The end of the session's standard error (earlier answers' lines
    /// included).
    pub(crate) fn stderr(&self) -> Vec<u8> {
        self.err.get(Duration::ZERO)
    }
}

/// How an answer failed.
enum Fail {
    /// `#error N MESSAGE`: the session goes on.
    Refused(String),
    /// Died, passed its cap, broke the protocol: the session must end.
    Broken(String),
    /// Gave no closing line within its timeout: the session must end, and
    /// so must whatever orphans it left.
    TimedOut(String),
    /// Closed its standard output or exited mid-answer: the session must
    /// end, once its process has had a moment to exit on its own.
    Ended(String),
}

/// One adapter process serving problems.
struct Session {
    key: Key,
    child: Child,
    mark: Mark,
    /// Where documents are written (what the pipe cannot take at once, a
    /// thread writes, so a process that does not read cannot block a run
    /// past its timeout); None once closed.
    input: Option<Input>,
    /// Standard output, read by the thread waiting for an answer.
    out: Direct,
    /// Readable once the process has exited (None: asked at intervals).
    exit: Option<OwnedFd>,
    err: Tail,
    /// Bytes read after the last answer's closing line.
    carry: Vec<u8>,
    /// Documents answered (closed by `#end`, `#ok` or `#error`).
    answered: u64,
    /// The last request number written (0: none yet).
    request: u64,
    ended: bool,
}

/// How long the first document of a process may go unanswered before
/// pushval says what the likely cause is (it keeps waiting, to the
/// engine's timeout).
const FIRST_ANSWER_HINT: Duration = Duration::from_secs(5);

/// The likely cause of a session whose first document is never answered.
fn never_answered_hint(spec_name: &str) -> String {
    format!(
        "a process that never answers its first document is most likely a protocol 1 adapter (it reads one document to the end of its standard input, which a session never closes) declared with `session = true`: declare [engine.{spec_name}] session = false, or serve sessions (the adapter kit, the Python module `pushval.adapter`, does)"
    )
}

impl Session {
    fn start(spec: &Spec, key: Key) -> Result<Self, ProcessError> {
        let program = spec.program();
        let mut command = Command::new(&program);
        command
            .args(&spec.command[1..])
            .current_dir(&spec.dir)
            // How an adapter tells a session from a one-shot run (the kit,
            // `pushval.adapter`, reads it; pushval passes no argument):
            // documents one per line, each answer closed by `#end N`,
            // `#ok N` or `#error N MESSAGE`.
            .env("PUSHVAL_SESSION", "1")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        let mark = Mark::apply(&mut command);
        let mut child = tree::spawn(&mut command).map_err(|e| ProcessError {
            what: format!("could not start `{}`: {e}", program.display()),
            stderr: Vec::new(),
        })?;
        let input = Input::new(child.stdin.take().expect("piped"));
        let out = Direct::new(child.stdout.take().expect("piped"));
        let err = Tail::spawn(child.stderr.take().expect("piped"));
        let exit = tree::exit_watch(&child);
        Ok(Self {
            key,
            child,
            mark,
            input: Some(input),
            out,
            exit,
            err,
            carry: Vec::new(),
            answered: 0,
            request: 0,
            ended: false,
        })
    }

    fn alive(&mut self) -> bool {
        !self.ended && !tree::has_exited(&mut self.child)
    }

    /// Appends the process's output to `buf`, waiting until `until` at most
    /// for the first byte; [`Filled::Exited`] as soon as the process has
    /// exited with nothing left to read (a process it started may hold its
    /// standard output open, so no end of file would come).
    fn wait_output(&mut self, buf: &mut Vec<u8>, until: Instant) -> Filled {
        if let Some(exit) = &self.exit {
            return self.out.fill_or_exit(buf, until, Some(exit.as_fd()));
        }
        loop {
            let slice = until.min(Instant::now() + EXIT_POLL);
            match self.out.fill(buf, slice) {
                Filled::Nothing if tree::has_exited(&mut self.child) => {
                    // What it wrote before it exited comes first.
                    return match self.out.fill(buf, Instant::now()) {
                        Filled::Nothing => Filled::Exited,
                        got => got,
                    };
                }
                Filled::Nothing if Instant::now() < until => {}
                got => return got,
            }
        }
    }

    /// Waits until `until` at most for the process to exit; whether it has.
    fn exits_by(&mut self, until: Instant) -> bool {
        let mut pause = Duration::from_micros(100);
        while !tree::has_exited(&mut self.child) {
            let now = Instant::now();
            if now >= until {
                return false;
            }
            std::thread::sleep(pause.min(until - now));
            pause = (pause * 2).min(Duration::from_millis(5));
        }
        true
    }

    /// Writes `doc` (a JSON object) with the next request number; returns
    /// the number and when it was written. With no answer outstanding,
    /// whatever arrived since the last answer was closed is an error: it
    /// answers no request.
    fn send(
        &mut self,
        mut doc: serde_json::Map<String, serde_json::Value>,
        what: &str,
    ) -> Result<(u64, Instant), Fail> {
        if self.answered == self.request {
            while let Filled::Bytes = self.out.fill(&mut self.carry, Instant::now()) {}
            if !self.carry.iter().all(u8::is_ascii_whitespace) {
                let first = String::from_utf8_lossy(&self.carry);
                let first = first.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
                return Err(Fail::Broken(format!(
                    "wrote {} bytes after its answer to request {} was closed and before request {} was sent (a second answer, or output outside any answer), the first line `{}`",
                    self.carry.len(),
                    self.request,
                    self.request + 1,
                    clip(first)
                )));
            }
            self.carry.clear();
        }
        let number = self.request + 1;
        self.request = number;
        doc.insert("request".into(), serde_json::Value::from(number));
        let mut line = serde_json::to_vec(&doc).expect("a JSON object serialises");
        // One document per line (compact JSON holds no line break).
        line.push(b'\n');
        let written = Instant::now();
        let sent = self.input.as_ref().is_some_and(|input| input.send(line));
        if !sent {
            return Err(Fail::Broken(format!(
                "its standard input is closed (the session has ended) at request {number} ({what})"
            )));
        }
        Ok((number, written))
    }

    /// Writes `doc` and reads its answer.
    fn answer(
        &mut self,
        doc: serde_json::Map<String, serde_json::Value>,
        what: &str,
        close: Close,
        limits: Limits,
        timeout: Duration,
    ) -> Result<(u64, Vec<u8>), Fail> {
        let (number, written) = self.send(doc, what)?;
        self.receive(number, written, what, close, limits, timeout)
    }

    /// Reads the answer to request `number` (written at `written`) up to
    /// its closing line, which must carry that number, within `timeout` of
    /// `written`.
    fn receive(
        &mut self,
        number: u64,
        written: Instant,
        what: &str,
        close: Close,
        limits: Limits,
        timeout: Duration,
    ) -> Result<(u64, Vec<u8>), Fail> {
        let deadline = written + timeout;
        let mut meter = Meter::new(limits);
        // Pipelined answers may arrive back to back: the bytes after the
        // last closing line start this answer. Each line is counted
        // against the cap as it is scanned, so a later answer already read
        // counts against its own.
        let mut answer = std::mem::take(&mut self.carry);
        let mut scanned = 0;
        let mut hinted = self.answered > 0;
        loop {
            while let Some(i) = answer[scanned..].iter().position(|&b| b == b'\n') {
                let end = scanned + i;
                let line = answer[scanned..end]
                    .strip_suffix(b"\r")
                    .unwrap_or(&answer[scanned..end]);
                if let Some(closing) = closing_line(line) {
                    let text = String::from_utf8_lossy(line).trim().to_string();
                    let verdict = check_closing(&closing, &text, number, what, close);
                    self.carry = answer.split_off(end + 1);
                    answer.truncate(scanned);
                    self.answered += 1;
                    verdict?;
                    if close == Close::Ok && !answer.iter().all(u8::is_ascii_whitespace) {
                        return Err(Fail::Broken(format!(
                            "wrote {} bytes before `#ok {number}` in its answer to request {number} ({what}), which holds nothing but that line",
                            answer.len()
                        )));
                    }
                    return Ok((number, answer));
                }
                meter.add(&answer[scanned..=end]).map_err(Fail::Broken)?;
                scanned = end + 1;
            }
            // A line that never ends passes the cap too.
            if (answer.len() - scanned) as u64 > limits.max_bytes {
                return Err(Fail::Broken(format!(
                    "wrote a line of more than {} bytes, this answer's output cap (max_bytes): killed",
                    limits.max_bytes
                )));
            }
            let wait_until = if hinted {
                deadline
            } else {
                deadline.min(written + FIRST_ANSWER_HINT)
            };
            match self.wait_output(&mut answer, wait_until) {
                Filled::Bytes => {}
                Filled::End => {
                    return Err(Fail::Ended(format!(
                        "closed its standard output before the closing line of its answer to request {number} ({what}): the session ended mid-answer"
                    )))
                }
                Filled::Exited => {
                    return Err(Fail::Ended(format!(
                        "exited before the closing line (`{} {number}`) of its answer to request {number} ({what}), its standard output still held open by a process it started",
                        close.word()
                    )))
                }
                Filled::Nothing if Instant::now() < deadline => {
                    hinted = true;
                    eprintln!(
                        "warning: outside engine \"{}\" (command `{}`) has not answered request {number} ({what}), its first document, after {} s; {}. Waiting up to its timeout of {} s.",
                        self.key.name,
                        self.key.command.join(" "),
                        FIRST_ANSWER_HINT.as_secs(),
                        never_answered_hint(&self.key.name),
                        timeout.as_secs_f64()
                    );
                }
                Filled::Nothing => {
                    let hint = if self.answered == 0 && answer.is_empty() {
                        format!(" ({})", never_answered_hint(&self.key.name))
                    } else {
                        String::new()
                    };
                    return Err(Fail::TimedOut(format!(
                        "gave no closing line (`{} {number}`) for request {number} ({what}) within its timeout of {} s: killed{hint}",
                        close.word(),
                        timeout.as_secs_f64()
                    )));
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
        self.exits_by(until);
        self.end();
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        self.end();
    }
}

/// A closing line read: its word (`#end`, `#ok`, `#error`), its number
/// (None: missing or not a number) and the rest (an error's message).
struct Closing {
    word: &'static str,
    number: Option<u64>,
    message: String,
}

/// The closing line `line` is, if it is one: a line whose first word is
/// `#end`, `#ok` or `#error`.
fn closing_line(line: &[u8]) -> Option<Closing> {
    if line.first() != Some(&b'#') {
        return None;
    }
    let text = String::from_utf8_lossy(line);
    let mut words = text.trim().splitn(3, ' ');
    let word = match words.next()? {
        "#end" => "#end",
        "#ok" => "#ok",
        "#error" => "#error",
        _ => return None,
    };
    let number = words.next().and_then(|n| n.parse::<u64>().ok());
    let message = words.next().unwrap_or("").trim().to_string();
    Some(Closing {
        word,
        number,
        message,
    })
}

/// Whether `closing` (the line `text`) closes request `number` (`what`)
/// the way `close` asks: the same number, the right word, or `#error`.
fn check_closing(
    closing: &Closing,
    text: &str,
    number: u64,
    what: &str,
    close: Close,
) -> Result<(), Fail> {
    match closing.number {
        None => Err(Fail::Broken(format!(
            "closed its answer to request {number} ({what}) with `{}`, which carries no request number (in a session every answer closes with `#end N`, `#ok N` or `#error N MESSAGE`, N the document's \"request\"; the adapter kit, the Python module `pushval.adapter`, numbers its answers)",
            clip(text)
        ))),
        Some(n) if n < number => Err(Fail::Broken(format!(
            "answered request {n} again while request {number} ({what}) was asked (`{}`): a second answer to an earlier document",
            clip(text)
        ))),
        Some(n) if n != number => Err(Fail::Broken(format!(
            "closed its answer with request number {n} (`{}`) while request {number} ({what}) was asked",
            clip(text)
        ))),
        Some(_) if closing.word == "#error" => Err(Fail::Refused(closing.message.clone())),
        Some(_) if closing.word != close.word() => Err(Fail::Broken(format!(
            "closed its answer to request {number} ({what}) with `{}`; that request is closed by `{} {number}`",
            clip(text),
            close.word()
        ))),
        Some(_) => Ok(()),
    }
}

/// A line of an adapter's output for a message: at most 120 characters.
fn clip(line: &str) -> String {
    let line = line.trim();
    match line.char_indices().nth(120) {
        Some((i, _)) => format!("{}…", &line[..i]),
        None => line.to_string(),
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

/// A session of one engine held for one run (a protocol 2 answer) or one
/// stepping session (protocol 3: start, advances, finish): handed back to
/// the pool when dropped healthy, ended when broken.
pub(crate) struct Lease {
    session: Option<Session>,
}

impl Lease {
    /// A session of `spec`'s engine: an idle one, or a new process.
    pub(crate) fn take(spec: &Spec) -> Result<Self, ProcessError> {
        Ok(Self {
            session: Some(checkout(spec)?),
        })
    }

    /// The process id serving the lease.
    pub(crate) fn pid(&self) -> u32 {
        self.session.as_ref().map_or(0, |s| s.child.id())
    }

    /// Sends `doc` (a JSON object; the request number is added) and reads
    /// its answer, closed by `close` with that number, within `timeout` and
    /// `limits`. `what` names the request in messages (`start`, `advance`,
    /// `finish`, `problem`). An `#error` answer leaves the session usable; any
    /// other failure ends it (with every process it started).
    pub(crate) fn request(
        &mut self,
        doc: serde_json::Map<String, serde_json::Value>,
        what: &str,
        close: Close,
        limits: Limits,
        timeout: Duration,
    ) -> Result<Answer, ProcessError> {
        let Some(s) = self.session.as_mut() else {
            return Err(ProcessError {
                what: format!("request ({what}) on a session already ended"),
                stderr: Vec::new(),
            });
        };
        let start = Instant::now();
        let answered_before = s.answered;
        let pid = s.child.id();
        match s.answer(doc, what, close, limits, timeout) {
            Ok((request, stdout)) => Ok(Answer {
                stdout,
                elapsed: start.elapsed(),
                pid,
                request,
                answered_before,
                err: s.err.clone(),
            }),
            Err(Fail::Refused(message)) => Err(ProcessError {
                what: format!(
                    "answered request {} ({what}) with `#error {} {message}` (session process {pid})",
                    s.request, s.request
                ),
                stderr: s.err.get(ERROR_TAIL_WAIT),
            }),
            Err(fail) => Err(self.broken(fail, what)),
        }
    }
}

impl Lease {
    /// Sends every document of `requests` at once, then reads their
    /// answers in order (as [`Lease::request`] would one by one, without
    /// waiting for each answer before the next document): one result per
    /// request. An `#error` answer fails its request and the others are
    /// still read; a broken session fails the rest. Each answer has
    /// `timeout` from the moment its document was written.
    pub(crate) fn pipeline(
        &mut self,
        requests: Vec<(
            serde_json::Map<String, serde_json::Value>,
            &str,
            Close,
            Limits,
        )>,
        timeout: Duration,
    ) -> Vec<Result<Answer, ProcessError>> {
        let mut sent = Vec::with_capacity(requests.len());
        let mut results: Vec<Result<Answer, ProcessError>> = Vec::with_capacity(requests.len());
        let Some(s) = self.session.as_mut() else {
            return Vec::new();
        };
        let pid = s.child.id();
        for (doc, what, close, limits) in requests {
            match s.send(doc, what) {
                Ok((number, written)) => sent.push((number, written, what, close, limits)),
                Err(fail) => {
                    results.push(Err(self.broken(fail, what)));
                    return results;
                }
            }
        }
        for (number, written, what, close, limits) in sent {
            let Some(s) = self.session.as_mut() else {
                results.push(Err(ProcessError {
                    what: format!(
                        "request {number} ({what}): the session ended at an earlier request"
                    ),
                    stderr: Vec::new(),
                }));
                continue;
            };
            let answered_before = s.answered;
            let start = Instant::now();
            match s.receive(number, written, what, close, limits, timeout) {
                Ok((request, stdout)) => results.push(Ok(Answer {
                    stdout,
                    elapsed: start.elapsed(),
                    pid,
                    request,
                    answered_before,
                    err: s.err.clone(),
                })),
                Err(Fail::Refused(message)) => results.push(Err(ProcessError {
                    what: format!(
                        "answered request {number} ({what}) with `#error {number} {message}` (session process {pid})"
                    ),
                    stderr: s.err.get(ERROR_TAIL_WAIT),
                })),
                Err(fail) => results.push(Err(self.broken(fail, what))),
            }
        }
        results
    }

    /// Ends a broken session (and, after a timeout, the orphans), and says
    /// how.
    fn broken(&mut self, fail: Fail, what: &str) -> ProcessError {
        let (text, timed_out, ended) = match fail {
            Fail::TimedOut(t) => (t, true, false),
            Fail::Ended(t) => (t, false, true),
            Fail::Broken(t) | Fail::Refused(t) => (t, false, false),
        };
        let Some(mut s) = self.session.take() else {
            return ProcessError {
                what: format!("{text} ({what})"),
                stderr: Vec::new(),
            };
        };
        let pid = s.child.id();
        if ended {
            // Its own exit status, not the kill's, says what happened.
            s.exits_by(Instant::now() + EXIT_WAIT);
        }
        let status = s.end();
        let stderr = s.err.get(Duration::from_millis(200));
        release(s);
        if timed_out {
            tree::end_orphans();
        }
        let how = match status.map(|st| (st.code(), st)) {
            Some((Some(c), _)) => format!("; its process {pid} exited with status {c}"),
            Some((None, st)) => format!("; its process {pid} was ended by a signal ({st})"),
            None => String::new(),
        };
        ProcessError {
            what: format!("{text}{how}; the session is ended and the next run starts a new one"),
            stderr,
        }
    }
}

impl Drop for Lease {
    fn drop(&mut self) {
        if let Some(s) = self.session.take() {
            checkin(s);
        }
    }
}

/// Ends every idle session (pushval calls it before it exits): closes their
/// standard input, gives them a moment to exit on their own, then ends each
/// with every process it started; then ends every process re-parented to
/// pushval (an orphan an adapter left, whatever its process group or
/// environment; see the `tree` module). A session serving a run is left to
/// it.
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
    // Whatever an adapter left behind and pushval (a child subreaper)
    // inherited, in any process group and with any environment.
    tree::end_orphans();
}

/// How many session processes are running (idle or serving a run).
pub fn live_sessions() -> usize {
    pool().live
}
