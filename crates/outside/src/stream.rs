//! An adapter's outputs read as they arrive, in bounded memory: standard
//! output in chunks through a bounded channel (the reader waits while the
//! consumer is behind), standard error as its last [`TAIL_BYTES`] bytes.
//! A session's pipes are read and written by the thread that asks
//! ([`Direct`], [`Input`]): a request and its answer cross no thread.

use std::io::{ErrorKind, Read, Write};
use std::os::fd::AsFd;
use std::process::{ChildStdin, ChildStdout};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{channel, sync_channel, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How much of standard error is kept (its end: the lines errors quote).
pub(crate) const TAIL_BYTES: usize = 64 * 1024;
/// The size of one read of standard output.
const CHUNK: usize = 64 * 1024;
/// Chunks waiting for the consumer at most.
const QUEUED: usize = 4;

/// What the standard output reader hands over.
pub(crate) enum Piece {
    /// The next bytes.
    Bytes(Vec<u8>),
    /// End of file (every writer closed it).
    End,
}

/// Standard output, chunk by chunk.
pub(crate) struct Chunks {
    rx: Receiver<Piece>,
    ended: bool,
}

impl Chunks {
    /// Starts a thread reading `r` to its end.
    pub(crate) fn spawn(mut r: impl Read + Send + 'static) -> Self {
        let (tx, rx) = sync_channel(QUEUED);
        std::thread::spawn(move || loop {
            let mut buf = vec![0; CHUNK];
            match r.read(&mut buf) {
                Ok(0) | Err(_) => {
                    let _ = tx.send(Piece::End);
                    return;
                }
                Ok(n) => {
                    buf.truncate(n);
                    if tx.send(Piece::Bytes(buf)).is_err() {
                        // Nobody reads any more: stop, the pipe closes.
                        return;
                    }
                }
            }
        });
        Self { rx, ended: false }
    }

    /// The next piece, waiting until `deadline` at most (None: nothing by
    /// then).
    pub(crate) fn next(&mut self, deadline: Instant) -> Option<Piece> {
        if self.ended {
            return Some(Piece::End);
        }
        let wait = deadline.saturating_duration_since(Instant::now());
        match self.rx.recv_timeout(wait) {
            Ok(Piece::End) | Err(RecvTimeoutError::Disconnected) => {
                self.ended = true;
                Some(Piece::End)
            }
            Ok(p) => Some(p),
            Err(RecvTimeoutError::Timeout) => None,
        }
    }
}

/// The end of standard error, shared with the thread reading it.
#[derive(Clone)]
pub(crate) struct Tail {
    inner: Arc<Mutex<(Vec<u8>, bool)>>,
}

impl std::fmt::Debug for Tail {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Tail")
    }
}

impl Tail {
    /// Starts a thread reading `r` to its end, keeping its last bytes.
    pub(crate) fn spawn(mut r: impl Read + Send + 'static) -> Self {
        let tail = Tail {
            inner: Arc::new(Mutex::new((Vec::new(), false))),
        };
        let t = tail.clone();
        std::thread::spawn(move || {
            let mut buf = vec![0; 8192];
            loop {
                let n = r.read(&mut buf).unwrap_or(0);
                let mut g = t.inner.lock().unwrap_or_else(|e| e.into_inner());
                if n == 0 {
                    g.1 = true;
                    return;
                }
                g.0.extend_from_slice(&buf[..n]);
                if g.0.len() > 2 * TAIL_BYTES {
                    let cut = g.0.len() - TAIL_BYTES;
                    g.0.drain(..cut);
                }
            }
        });
        tail
    }

    /// Its last bytes, after waiting up to `grace` for the end of file (a
    /// process just ended may still have bytes in the pipe).
    pub(crate) fn get(&self, grace: Duration) -> Vec<u8> {
        let until = Instant::now() + grace;
        loop {
            {
                let g = self.inner.lock().unwrap_or_else(|e| e.into_inner());
                if g.1 || Instant::now() >= until {
                    let from = g.0.len().saturating_sub(TAIL_BYTES);
                    return g.0[from..].to_vec();
                }
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

/// Waits until `fd` is ready for `flags` or `deadline` passes (None: no
/// deadline); false at the deadline. Blocks in `poll(2)`: no spinning.
fn wait_ready(fd: impl AsFd, flags: rustix::event::PollFlags, deadline: Option<Instant>) -> bool {
    loop {
        let timeout = match deadline {
            None => None,
            Some(d) => {
                let left = d.saturating_duration_since(Instant::now());
                Some(rustix::time::Timespec {
                    tv_sec: left.as_secs() as _,
                    tv_nsec: left.subsec_nanos() as _,
                })
            }
        };
        let mut fds = [rustix::event::PollFd::new(&fd, flags)];
        match rustix::event::poll(&mut fds, timeout.as_ref()) {
            // Ready, or an error or hang-up the next read or write reports.
            Ok(n) if n > 0 => return true,
            Ok(_) => {
                if deadline.is_some_and(|d| Instant::now() >= d) {
                    return false;
                }
            }
            Err(rustix::io::Errno::INTR) => {}
            // poll itself failed (not expected): let the read or write say.
            Err(_) => return true,
        }
    }
}

/// What [`wait_readable_or_exit`] saw first.
#[cfg(target_os = "linux")]
enum Ready {
    /// The pipe has bytes, an end of file or an error to read.
    Readable,
    /// The pipe has nothing and the process has exited.
    Exited,
    /// Neither by the deadline.
    Deadline,
}

/// Waits until `fd` is readable or `exit` (a process's pidfd) says the
/// process exited, or `deadline` passes. Blocks in `poll(2)`: no spinning.
/// A readable pipe wins over an exit: bytes written before the exit are
/// read before it is reported.
#[cfg(target_os = "linux")]
fn wait_readable_or_exit(
    fd: impl AsFd,
    exit: std::os::fd::BorrowedFd<'_>,
    deadline: Instant,
) -> Ready {
    use rustix::event::{poll, PollFd, PollFlags};
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let timeout = rustix::time::Timespec {
            tv_sec: left.as_secs() as _,
            tv_nsec: left.subsec_nanos() as _,
        };
        let mut fds = [
            PollFd::new(&fd, PollFlags::IN),
            PollFd::new(&exit, PollFlags::IN),
        ];
        match poll(&mut fds, Some(&timeout)) {
            Ok(n) if n > 0 => {
                return if fds[0].revents().is_empty() {
                    Ready::Exited
                } else {
                    Ready::Readable
                };
            }
            Ok(_) => {
                if Instant::now() >= deadline {
                    return Ready::Deadline;
                }
            }
            Err(rustix::io::Errno::INTR) => {}
            // poll itself failed (not expected): let the read say.
            Err(_) => return Ready::Readable,
        }
    }
}

/// What [`Direct::fill`] got.
pub(crate) enum Filled {
    /// Some bytes, appended.
    Bytes,
    /// End of file (every writer closed it).
    End,
    /// Nothing by the deadline.
    Nothing,
    /// Nothing to read, and the process has exited (a process it started
    /// may still hold the pipe open, so no end of file comes).
    Exited,
}

/// A session's standard output, read by the thread that waits for an
/// answer (non-blocking reads, `poll(2)` until a deadline), into the
/// caller's buffer.
pub(crate) struct Direct {
    out: ChildStdout,
    ended: bool,
    scratch: Box<[u8]>,
}

impl Direct {
    pub(crate) fn new(out: ChildStdout) -> Self {
        // Without non-blocking reads a deadline could not be kept; should
        // it fail (it does not on a pipe), reads only block until data.
        let _ = rustix::io::ioctl_fionbio(&out, true);
        Self {
            out,
            ended: false,
            scratch: vec![0; CHUNK].into_boxed_slice(),
        }
    }

    /// Appends to `buf` what is there, waiting until `deadline` at most for
    /// the first byte.
    pub(crate) fn fill(&mut self, buf: &mut Vec<u8>, deadline: Instant) -> Filled {
        self.fill_or_exit(buf, deadline, None)
    }

    /// As [`Direct::fill`], and [`Filled::Exited`] as soon as `exit` (the
    /// writer's pidfd, readable once it has exited) says the process is gone
    /// while the pipe has nothing to read. What the process wrote before it
    /// exited is read first.
    pub(crate) fn fill_or_exit(
        &mut self,
        buf: &mut Vec<u8>,
        deadline: Instant,
        exit: Option<std::os::fd::BorrowedFd<'_>>,
    ) -> Filled {
        loop {
            if self.ended {
                return Filled::End;
            }
            match self.out.read(&mut self.scratch) {
                Ok(0) => {
                    self.ended = true;
                    return Filled::End;
                }
                Ok(n) => {
                    buf.extend_from_slice(&self.scratch[..n]);
                    return Filled::Bytes;
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) if e.kind() == ErrorKind::WouldBlock => {
                    let ready = match exit {
                        #[cfg(target_os = "linux")]
                        Some(exit) => match wait_readable_or_exit(&self.out, exit, deadline) {
                            Ready::Readable => true,
                            Ready::Exited => return Filled::Exited,
                            Ready::Deadline => false,
                        },
                        _ => wait_ready(&self.out, rustix::event::PollFlags::IN, Some(deadline)),
                    };
                    if !ready {
                        return Filled::Nothing;
                    }
                }
                Err(_) => {
                    self.ended = true;
                    return Filled::End;
                }
            }
        }
    }
}

/// A session's standard input: a document is written at once by the
/// thread that sends it (non-blocking); what the pipe cannot take yet goes
/// to a thread that writes it as the process reads (so a process that does
/// not read never blocks a run past its timeout), and every later document
/// queues behind it, in order. Dropping it closes standard input once the
/// queue is written.
pub(crate) struct Input {
    pipe: Arc<ChildStdin>,
    queue: Sender<Vec<u8>>,
    /// Documents handed to the thread and not yet written.
    queued: Arc<AtomicUsize>,
    /// The pipe is broken (the process closed it).
    broken: Arc<AtomicUsize>,
}

impl Input {
    pub(crate) fn new(stdin: ChildStdin) -> Self {
        let _ = rustix::io::ioctl_fionbio(&stdin, true);
        let pipe = Arc::new(stdin);
        let (queue, rx) = channel::<Vec<u8>>();
        let queued = Arc::new(AtomicUsize::new(0));
        let broken = Arc::new(AtomicUsize::new(0));
        let (p, q, b) = (pipe.clone(), queued.clone(), broken.clone());
        std::thread::spawn(move || {
            for doc in rx {
                if write_all(&p, &doc).is_err() {
                    b.store(1, Ordering::SeqCst);
                    return;
                }
                q.fetch_sub(1, Ordering::SeqCst);
            }
            // The sender is gone: this clone of standard input closes here.
        });
        Self {
            pipe,
            queue,
            queued,
            broken,
        }
    }

    /// Writes `doc`, or queues what the pipe cannot take now; false when
    /// standard input is closed or broken.
    pub(crate) fn send(&self, doc: Vec<u8>) -> bool {
        if self.broken.load(Ordering::SeqCst) != 0 {
            return false;
        }
        let mut done = 0;
        if self.queued.load(Ordering::SeqCst) == 0 {
            while done < doc.len() {
                match (&*self.pipe).write(&doc[done..]) {
                    Ok(0) => return false,
                    Ok(n) => done += n,
                    Err(e) if e.kind() == ErrorKind::Interrupted => {}
                    Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                    Err(_) => return false,
                }
            }
            if done == doc.len() {
                return true;
            }
        }
        self.queued.fetch_add(1, Ordering::SeqCst);
        let rest = if done == 0 { doc } else { doc[done..].to_vec() };
        if self.queue.send(rest).is_err() {
            self.queued.fetch_sub(1, Ordering::SeqCst);
            return false;
        }
        true
    }
}

/// Writes all of `doc` to the non-blocking `pipe`, waiting for room.
fn write_all(mut pipe: &ChildStdin, doc: &[u8]) -> std::io::Result<()> {
    let mut done = 0;
    while done < doc.len() {
        match pipe.write(&doc[done..]) {
            Ok(0) => return Err(ErrorKind::WriteZero.into()),
            Ok(n) => done += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) if e.kind() == ErrorKind::WouldBlock => {
                wait_ready(pipe, rustix::event::PollFlags::OUT, None);
            }
            Err(e) => return Err(e),
        }
    }
    Ok(())
}
