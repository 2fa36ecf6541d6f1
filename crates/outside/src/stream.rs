//! An adapter's outputs read as they arrive, in bounded memory: standard
//! output in chunks through a bounded channel (the reader waits while the
//! consumer is behind), standard error as its last [`TAIL_BYTES`] bytes.

use std::io::Read;
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError};
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
