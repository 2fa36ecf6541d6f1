//! Ending an adapter and every process it started, `setsid()` or not.
//!
//! Each adapter starts in a process group of its own, with the variable
//! [`MARK`] set to a value unique to that process, which its descendants
//! inherit. On Linux pushval is also a child subreaper
//! (`prctl(PR_SET_CHILD_SUBREAPER)`), so an orphaned descendant is
//! re-parented to pushval, not to init, and pushval reaps it.
//!
//! [`end`] ends the tree of one adapter whose own process has not been
//! reaped yet (so its pid, and the id of its process group, cannot be reused
//! meanwhile): it stops the process group, then every process (read from
//! `/proc`) in that group, carrying the adapter's mark in its environment
//! or descending from the adapter by parent links, until a search finds no
//! new one; then kills them all, reaps the killed processes re-parented to
//! pushval, and reaps the adapter. It is
//! called at a timeout, at a cap, when a session ends, and after every
//! normal exit, so a daemon an adapter left behind does not outlive its run.
//!
//! A descendant that clears its environment, leaves the process group and
//! whose parent has already exited is not found by [`end`]; on Linux it has
//! been re-parented to pushval. [`end_orphans`] ends those: every child of
//! pushval that is not an adapter it started (a registry of the adapters
//! not yet reaped, filled by [`spawn`]) and not in pushval's own process
//! group (so a process another part of pushval started is left alone), and
//! their descendants. It runs at every timeout and when the sessions are
//! shut down before pushval exits. Its limit: an orphan of an adapter still
//! running (an intermediate process exited) is ended too if a timeout
//! happens meanwhile.

use std::process::{Child, Command, ExitStatus};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The adapters pushval started and has not reaped (their pids): the
/// children of pushval that are not orphans.
static ROOTS: Mutex<Vec<u32>> = Mutex::new(Vec::new());

fn roots() -> MutexGuard<'static, Vec<u32>> {
    ROOTS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Starts `command` (set up with [`Mark::apply`]) and registers it as an
/// adapter, at once: [`end_orphans`] never takes it for an orphan.
pub(crate) fn spawn(command: &mut Command) -> std::io::Result<Child> {
    let mut g = roots();
    let child = command.spawn()?;
    g.push(child.id());
    Ok(child)
}

/// The environment variable marking an adapter's processes.
pub(crate) const MARK: &str = "PUSHVAL_ADAPTER_RUN";

/// The mark of one adapter process: `MARK=VALUE`.
#[derive(Debug, Clone)]
pub(crate) struct Mark(String);

impl Mark {
    /// Sets `command` up as an adapter: its own process group and a fresh
    /// mark; on Linux makes pushval a child subreaper (once).
    pub(crate) fn apply(command: &mut Command) -> Self {
        use std::os::unix::process::CommandExt;
        static NEXT: AtomicU64 = AtomicU64::new(0);
        #[cfg(target_os = "linux")]
        {
            static SUBREAPER: std::sync::Once = std::sync::Once::new();
            // Without it (an old kernel) orphans go to init: still found
            // by their mark and killed, only reaped by init.
            SUBREAPER.call_once(|| {
                let _ = rustix::process::set_child_subreaper(Some(rustix::process::getpid()));
            });
        }
        let value = format!(
            "{}-{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        );
        command.process_group(0).env(MARK, &value);
        Mark(format!("{MARK}={value}"))
    }
}

/// Ends `child` (an adapter started with [`Mark::apply`], not yet reaped)
/// and every process it started; returns its exit status.
pub(crate) fn end(child: &mut Child, mark: &Mark) -> std::io::Result<ExitStatus> {
    let root = rustix::process::Pid::from_child(child);
    #[cfg(target_os = "linux")]
    linux::end_descendants(root, mark);
    #[cfg(not(target_os = "linux"))]
    let _ = mark;
    // The group's id is the unreaped child's pid: it cannot name another
    // group.
    let _ = rustix::process::kill_process_group(root, rustix::process::Signal::KILL);
    // The adapter too, should it have left its group.
    let _ = child.kill();
    let status = child.wait();
    let id = child.id();
    roots().retain(|&p| p != id);
    status
}

/// Ends every process re-parented to pushval (see the module docs) and
/// their descendants, and reaps them. Nothing to do off Linux (orphans go
/// to init there).
pub(crate) fn end_orphans() {
    #[cfg(target_os = "linux")]
    {
        let g = roots();
        linux::end_orphans(&g);
    }
}

/// A file descriptor that becomes readable once `child` has exited (a
/// pidfd, Linux 5.3 and later), so a wait on its output can also wait on its
/// exit in one `poll(2)`; None where there is none (then [`has_exited`] is
/// asked at intervals).
pub(crate) fn exit_watch(child: &Child) -> Option<std::os::fd::OwnedFd> {
    #[cfg(target_os = "linux")]
    {
        use rustix::process::{pidfd_open, Pid, PidfdFlags};
        pidfd_open(Pid::from_child(child), PidfdFlags::empty()).ok()
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = child;
        None
    }
}

/// Whether `child` has exited, without reaping it (its pid stays its own).
pub(crate) fn has_exited(child: &mut Child) -> bool {
    #[cfg(target_os = "linux")]
    {
        use rustix::process::{waitid, WaitId, WaitIdOptions};
        let pid = rustix::process::Pid::from_child(child);
        matches!(
            waitid(
                WaitId::Pid(pid),
                WaitIdOptions::EXITED | WaitIdOptions::NOWAIT | WaitIdOptions::NOHANG,
            ),
            Ok(Some(_)) | Err(_)
        )
    }
    #[cfg(not(target_os = "linux"))]
    {
        // Reaping here is harmless: `end` then kills a group that is gone.
        matches!(child.try_wait(), Ok(Some(_)) | Err(_))
    }
}

#[cfg(target_os = "linux")]
mod linux {
    use std::collections::{HashMap, HashSet};
    use std::time::{Duration, Instant};

    use rustix::process::{kill_process, kill_process_group, waitpid, Pid, Signal, WaitOptions};

    use super::Mark;

    /// How long the killed processes are waited for (to reap the ones
    /// re-parented to pushval) before they are left to their parents.
    const REAP_WAIT: Duration = Duration::from_secs(1);
    /// How many rounds of finding and killing (a process may fork while
    /// the previous round kills its parent).
    const ROUNDS: usize = 20;

    /// One process of `/proc`: its parent, its process group, its state.
    struct Proc {
        ppid: i32,
        pgrp: i32,
        zombie: bool,
    }

    /// `/proc/PID/stat` read: None when the process is gone.
    fn stat(pid: i32) -> Option<Proc> {
        let text = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
        // The command name is in parentheses and may hold anything.
        let rest = &text[text.rfind(')')? + 1..];
        let mut f = rest.split_ascii_whitespace();
        let state = f.next()?;
        let ppid = f.next()?.parse().ok()?;
        let pgrp = f.next()?.parse().ok()?;
        Some(Proc {
            ppid,
            pgrp,
            zombie: state == "Z" || state == "X",
        })
    }

    /// Whether process `pid`'s environment holds `mark` (false when it
    /// cannot be read: another user's process, or gone).
    fn marked(pid: i32, mark: &Mark) -> bool {
        std::fs::read(format!("/proc/{pid}/environ"))
            .is_ok_and(|env| env.split(|&b| b == 0).any(|v| v == mark.0.as_bytes()))
    }

    fn all() -> HashMap<i32, Proc> {
        let Ok(dir) = std::fs::read_dir("/proc") else {
            return HashMap::new();
        };
        dir.filter_map(|e| e.ok()?.file_name().to_str()?.parse::<i32>().ok())
            .filter_map(|pid| Some((pid, stat(pid)?)))
            .collect()
    }

    /// The live processes of `root`'s tree: `root`'s process group, its
    /// descendants by parent links, and every process carrying `mark`.
    fn tree(root: i32, mark: &Mark, me: i32) -> Vec<i32> {
        let procs = all();
        let descends = |mut pid: i32| {
            for _ in 0..256 {
                if pid == root {
                    return true;
                }
                match procs.get(&pid) {
                    Some(p) if p.ppid > 1 && p.ppid != me => pid = p.ppid,
                    _ => return false,
                }
            }
            false
        };
        procs
            .iter()
            .filter(|(&pid, p)| pid != root && pid != me && !p.zombie)
            .filter(|(&pid, p)| p.pgrp == root || descends(pid) || marked(pid, mark))
            .map(|(&pid, _)| pid)
            .collect()
    }

    /// The children of pushval that are orphans: not in `roots`, not in
    /// pushval's own process group.
    fn orphans(procs: &HashMap<i32, Proc>, roots: &[u32], me: i32, group: i32) -> Vec<i32> {
        procs
            .iter()
            .filter(|(&pid, p)| p.ppid == me && p.pgrp != group && !roots.contains(&(pid as u32)))
            .map(|(&pid, _)| pid)
            .collect()
    }

    pub(super) fn end_orphans(roots: &[u32]) {
        let me = rustix::process::getpid().as_raw_nonzero().get();
        let group = rustix::process::getpgrp().as_raw_nonzero().get();
        let mut killed: HashSet<i32> = HashSet::new();
        for _ in 0..ROUNDS {
            let procs = all();
            let mut found: Vec<i32> = orphans(&procs, roots, me, group)
                .into_iter()
                .filter(|pid| !killed.contains(pid))
                .collect();
            // And their descendants, by parent links (stopped first: a
            // stopped process neither forks nor dies).
            let mut frontier: HashSet<i32> = found
                .iter()
                .copied()
                .chain(killed.iter().copied())
                .collect();
            loop {
                let next: Vec<i32> = procs
                    .iter()
                    .filter(|(pid, p)| frontier.contains(&p.ppid) && !frontier.contains(pid))
                    .map(|(&pid, _)| pid)
                    .collect();
                if next.is_empty() {
                    break;
                }
                frontier.extend(&next);
                found.extend(next.into_iter().filter(|pid| !killed.contains(pid)));
            }
            if found.is_empty() {
                break;
            }
            for pid in found {
                if let Some(p) = Pid::from_raw(pid) {
                    let _ = kill_process(p, Signal::STOP);
                    killed.insert(pid);
                }
            }
        }
        for &pid in &killed {
            if let Some(p) = Pid::from_raw(pid) {
                let _ = kill_process(p, Signal::KILL);
            }
        }
        reap(killed, me);
    }

    /// Reaps the killed processes that are (or become, as their parents
    /// die) pushval's children; the others are their parents' to reap.
    fn reap(mut killed: HashSet<i32>, me: i32) {
        let deadline = Instant::now() + REAP_WAIT;
        let mut pause = Duration::from_micros(100);
        while !killed.is_empty() && Instant::now() < deadline {
            killed.retain(|&pid| match stat(pid) {
                None => false,
                Some(p) if p.zombie && p.ppid == me => {
                    if let Some(p) = Pid::from_raw(pid) {
                        let _ = waitpid(Some(p), WaitOptions::NOHANG);
                    }
                    false
                }
                Some(_) => true,
            });
            if !killed.is_empty() {
                std::thread::sleep(pause);
                pause = (pause * 2).min(Duration::from_millis(10));
            }
        }
    }

    pub(super) fn end_descendants(root: Pid, mark: &Mark) {
        let me = rustix::process::getpid().as_raw_nonzero().get();
        // Stop first, kill after: a stopped process neither forks nor dies,
        // so the parent links that find an unmarked descendant hold while
        // the tree is searched.
        let _ = rustix::process::kill_process_group(root, Signal::STOP);
        let _ = kill_process(root, Signal::STOP);
        let root = root.as_raw_nonzero().get();
        let mut killed = HashSet::new();
        for _ in 0..ROUNDS {
            let found: Vec<i32> = tree(root, mark, me)
                .into_iter()
                .filter(|pid| !killed.contains(pid))
                .collect();
            if found.is_empty() {
                break;
            }
            for pid in found {
                if let Some(p) = Pid::from_raw(pid) {
                    let _ = kill_process(p, Signal::STOP);
                    killed.insert(pid);
                }
            }
        }
        let _ = kill_process_group(Pid::from_raw(root).expect("a pid"), Signal::KILL);
        for &pid in &killed {
            if let Some(p) = Pid::from_raw(pid) {
                let _ = kill_process(p, Signal::KILL);
            }
        }
        reap(killed, me);
    }
}
