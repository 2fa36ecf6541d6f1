//! What the dynamic model's analysis of a push keeps between runs
//! ([`PushCache`]): a planner predicts schedules that share most of their
//! pushes (a finite-difference Jacobian changes one direction at a time; a
//! warm-started re-plan starts from the last plan's directions), and per
//! segment most of a run's work depends on the push alone.

use crate::dynamic::{SegmentDynamics, SteadyState};
use crate::tail::ends::EndSeries;
use crate::{Body, InertialTerm, Push};

/// Pushes remembered at most; the oldest is replaced beyond that.
const CAPACITY: usize = 32;

/// Per push (speed and direction, to the bit) on one body: the steady state
/// a segment tends to, when that does not depend on where ω starts (the
/// inertial slope `k < 0`: `G` decreases and has one root), and the series
/// in `δ` about it (`r_n` and `H_n = F_n/(n − iμ)`, which scale with the start's
/// `δ₀^n`: a warm segment only sums them). [`DynamicModel::final_state_cached`] with
/// a cache returns what [`DynamicModel::final_state`] returns, bit for bit;
/// the cache only spares the work. It forgets everything when the body or
/// the reading of the inertial term changes.
///
/// [`DynamicModel::final_state_cached`]: crate::DynamicModel::final_state_cached
/// [`DynamicModel::final_state`]: crate::DynamicModel::final_state
#[derive(Debug, Clone, Default)]
pub struct PushCache {
    /// The body and inertial term the entries belong to.
    owner: Option<(Body, InertialTerm)>,
    entries: Vec<Entry>,
    /// The entry replaced next once full.
    next: usize,
    hits: usize,
    misses: usize,
}

#[derive(Debug, Clone)]
struct Entry {
    /// `speed` and `phi` of the push, as bits.
    key: (u64, u64),
    /// The root its segments tend to (k < 0 only; None until found).
    root: Option<Option<SteadyState>>,
    /// ω* (bits) the memo is about.
    memo_root: u64,
    /// The series in `δ` about that root (None until made; `Some(None)`:
    /// it has none).
    memo: Option<Option<EndSeries>>,
}

impl PushCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Pushes looked up and found, and not found, so far.
    pub fn hits_misses(&self) -> (usize, usize) {
        (self.hits, self.misses)
    }

    /// Empties the cache unless it belongs to `body` and `term`.
    pub(super) fn bind(&mut self, body: &Body, term: InertialTerm) {
        let same = self
            .owner
            .as_ref()
            .is_some_and(|(b, t)| *t == term && b == body);
        if !same {
            self.owner = Some((body.clone(), term));
            self.entries.clear();
            self.next = 0;
        }
    }

    /// The entry of `push`, made if new.
    pub(super) fn entry(&mut self, push: &Push) -> usize {
        let key = (push.speed.to_bits(), push.phi.to_bits());
        if let Some(i) = self.entries.iter().position(|e| e.key == key) {
            self.hits += 1;
            return i;
        }
        self.misses += 1;
        let e = Entry {
            key,
            root: None,
            memo_root: 0,
            memo: None,
        };
        if self.entries.len() < CAPACITY {
            self.entries.push(e);
            self.entries.len() - 1
        } else {
            let i = self.next;
            self.entries[i] = e;
            self.next = (i + 1) % CAPACITY;
            i
        }
    }

    /// [`SegmentDynamics::attractor_from`] for entry `i`'s push.
    pub(super) fn attractor(
        &mut self,
        i: usize,
        dynamics: &SegmentDynamics,
        omega: f64,
    ) -> Option<SteadyState> {
        // The cases in which `attractor_from` returns the root of the push
        // alone; every other goes to it.
        if dynamics.inertial_slope() < 0.0
            && dynamics.speed() > 0.0
            && dynamics.moment(omega) != 0.0
        {
            *self.entries[i]
                .root
                .get_or_insert_with(|| dynamics.monotone_root())
        } else {
            dynamics.attractor_from(omega)
        }
    }

    /// The series in `δ` of entry `i` about the root `omega`, cut as
    /// `fresh()` would cut it (`cut`, an [`EndSeries::cut`] with `fresh`'s
    /// reach, speed, span and tolerance): from the terms kept, or `fresh()` kept instead
    /// when they do not reach that far (the terms are the same, only the
    /// number computed differs). So a call gets the same series, to the
    /// bit, whatever the cache held.
    pub(super) fn memo(
        &mut self,
        i: usize,
        omega: f64,
        cut: impl FnOnce(&EndSeries) -> Option<EndSeries>,
        fresh: impl FnOnce() -> Option<EndSeries>,
    ) -> Option<EndSeries> {
        let e = &mut self.entries[i];
        if e.memo_root == omega.to_bits() {
            match e.memo {
                Some(None) => return None,
                Some(Some(s)) => {
                    if let Some(s) = cut(&s) {
                        return Some(s);
                    }
                }
                None => {}
            }
        }
        e.memo_root = omega.to_bits();
        e.memo = Some(fresh());
        e.memo.flatten()
    }
}
