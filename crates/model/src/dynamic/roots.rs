//! The steady states of ω̇ (its roots), their stability and relaxation
//! time, and the one a transient tends to.

use super::{RootKind, SegmentDynamics, SteadyState};

/// Intervals of the uniform grid that [`SegmentDynamics::steady_states`]
/// scans for sign changes of `G` over ±(the bound on |ω*|).
const ROOT_GRID: usize = 512;

impl SegmentDynamics {
    /// Speed scale for "has this support stopped?" tests (m/s).
    fn speed_scale(&self, omega: f64) -> f64 {
        let rmax = self.b.iter().fold(0.0f64, |a, &b| a.max(b)).sqrt();
        self.speed + omega.abs() * rmax
    }

    /// Every steady state, sorted by ω, with its stability. Empty when ω̇ never
    /// vanishes (possible only when all supports lie on the push line).
    pub fn steady_states(&self) -> Vec<SteadyState> {
        let g = |w: f64| self.moment(w);
        let mut roots = Vec::new();
        if self.speed == 0.0 {
            // The contact point is held still: the object can only pivot about it,
            // and friction stops it. ω* = 0, reached in finite time.
            return vec![SteadyState {
                omega: 0.0,
                kind: RootKind::Stable,
                tau: None,
            }];
        }
        let bound = self.root_bound();
        if self.k <= 0.0 {
            // Monotone: one sign change in [−bound, bound] at most.
            let (lo, hi) = (-bound, bound);
            if g(lo) > 0.0 && g(hi) < 0.0 {
                roots.push(self.refine((lo, g(lo)), (hi, g(hi))));
            } else if g(lo) == 0.0 || g(hi) == 0.0 {
                roots.push(if g(lo) == 0.0 { lo } else { hi });
            }
        } else {
            // Several roots possible: scan a grid clustered where each support's
            // term is steepest (ω = −v s_i / b_i, where |u_i| is smallest).
            let mut grid: Vec<f64> = (0..=ROOT_GRID)
                .map(|j| -bound + 2.0 * bound * j as f64 / ROOT_GRID as f64)
                .collect();
            self.cluster_points(bound, &mut grid);
            grid.sort_by(f64::total_cmp);
            grid.dedup();
            let vals: Vec<f64> = grid.iter().map(|&w| g(w)).collect();
            for j in 0..grid.len() - 1 {
                let (a, b) = (vals[j], vals[j + 1]);
                if a == 0.0 {
                    roots.push(grid[j]);
                } else if a * b < 0.0 {
                    roots.push(self.refine((grid[j], a), (grid[j + 1], b)));
                }
            }
            if vals[grid.len() - 1] == 0.0 {
                roots.push(grid[grid.len() - 1]);
            }
        }
        roots.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * (1.0 + b.abs()));
        roots.into_iter().map(|w| self.classify(w)).collect()
    }

    /// The distance from the contact point to the nearest support not under
    /// it, `min √b_i` over `b_i = |r_i|² > 0` (m; infinite when there is
    /// none).
    fn r_min(&self) -> f64 {
        self.b
            .iter()
            .fold(f64::INFINITY, |a, &b| if b > 0.0 { a.min(b) } else { a })
            .sqrt()
    }

    /// A bound on |ω| of every steady state (rad/s). With `k > 0` the friction
    /// moment is at most M, so |k ω*| ≤ M; with k ≤ 0 the root sits where the
    /// friction moment changes sign, within a few v/r.
    fn root_bound(&self) -> f64 {
        let g = |w: f64| self.moment(w);
        if self.k > 0.0 {
            return self.max_moment / self.k * (1.0 + 1e-9) + 1e-300;
        }
        // Expand until the sign changes (G decreasing: G(+∞) < 0 < G(−∞)).
        let mut w = self.speed / self.r_min().max(1e-300);
        for _ in 0..200 {
            if g(w) < 0.0 && g(-w) > 0.0 {
                break;
            }
            w *= 2.0;
        }
        w
    }

    /// Appends to `grid` the scan points clustered about each support's
    /// steepest place (ω = −v s_i / b_i) that lie inside ±`bound`.
    fn cluster_points(&self, bound: f64, grid: &mut Vec<f64>) {
        for i in 0..self.f.len() {
            if self.b[i] > 0.0 {
                let w0 = -self.speed * self.s[i] / self.b[i];
                let width = self.speed / self.b[i].sqrt();
                for d in [
                    -1.0, -0.3, -0.1, -0.03, -0.01, 0.0, 0.01, 0.03, 0.1, 0.3, 1.0,
                ] {
                    let w = w0 + d * width;
                    if w.abs() < bound {
                        grid.push(w);
                    }
                }
            }
            if grid.len() > 20_000 {
                break;
            }
        }
    }

    /// The steady state a transient starting at `omega` converges to, as
    /// [`Self::attractor`] of [`Self::steady_states`] but scanning only the
    /// stretch of the grid from `omega` in the direction ω̇ drives it, up to
    /// its first sign change (a trajectory needs no other root). None when ω
    /// runs away.
    pub fn attractor_from(&self, omega: f64) -> Option<SteadyState> {
        if self.speed == 0.0 {
            return self.attractor(&self.steady_states(), omega);
        }
        let g0 = self.moment(omega);
        if g0 == 0.0 {
            return Some(self.classify(omega));
        }
        let up = g0 > 0.0;
        if self.k > 0.0 {
            // A root within rounding of ω is the state itself (as in
            // `attractor`). (With k ≤ 0, G decreases: its one root lies
            // ahead, and the first bracket below holds it even within
            // rounding.)
            let h = 1e-12 * (1.0 + omega.abs());
            let (gl, gh) = (self.moment(omega - h), self.moment(omega + h));
            if (gl > 0.0) != (gh > 0.0) && gl != 0.0 && gh != 0.0 {
                return Some(self.classify(self.refine((omega - h, gl), (omega + h, gh))));
            }
        } else if self.k < 0.0 {
            // G decreases strictly: its one root is the attractor from
            // every start. It is found from ω = 0, not from `omega`, so the
            // same push gives the same root to the last bit whatever the
            // start (what lets a caller keep it per push: `PushCache`).
            return self.monotone_root();
        } else {
            return self.root_ahead(omega, g0);
        }
        let bound = self.root_bound();
        // The clustered points ahead, nearest first.
        let mut extra = Vec::new();
        self.cluster_points(bound, &mut extra);
        extra.retain(|&w| if up { w > omega } else { w < omega });
        extra.sort_by(|a, b| if up { a.total_cmp(b) } else { b.total_cmp(a) });
        // The uniform points ahead, nearest first.
        let step = 2.0 * bound / ROOT_GRID as f64;
        let first = ((omega + bound) / step).floor();
        let mut j = if up {
            (first + 1.0).max(0.0)
        } else {
            first.min(ROOT_GRID as f64)
        };
        let uniform_done = |j: f64| !(0.0..=ROOT_GRID as f64).contains(&j);
        let mut e = 0;
        let (mut prev, mut gprev) = (omega, g0);
        loop {
            let wu = (!uniform_done(j)).then(|| -bound + step * j);
            let we = extra.get(e).copied();
            let w = match (wu, we) {
                (Some(a), Some(b)) if (a < b) == up => a,
                (Some(_), Some(b)) | (None, Some(b)) => b,
                (Some(a), None) => a,
                (None, None) => return None,
            };
            if wu == Some(w) {
                j += if up { 1.0 } else { -1.0 };
            } else {
                e += 1;
            }
            if (w > prev) != up || w == prev {
                continue;
            }
            let gw = self.moment(w);
            if gw == 0.0 {
                return Some(self.classify(w));
            }
            if (gw > 0.0) != (gprev > 0.0) {
                return Some(self.classify(self.refine((prev, gprev), (w, gw))));
            }
            (prev, gprev) = (w, gw);
        }
    }

    /// The one root of a strictly decreasing `G` (`k < 0`), bracketed from
    /// ω = 0: a function of the push alone.
    pub(crate) fn monotone_root(&self) -> Option<SteadyState> {
        let g0 = self.moment(0.0);
        if g0 == 0.0 {
            return Some(self.classify(0.0));
        }
        self.root_ahead(0.0, g0)
    }

    /// The first root of a non-increasing `G` from `omega` (where `G` is
    /// `g0 ≠ 0`) in the direction it drives ω: steps from ω growing by
    /// doubling from a tenth of v/r_min bracket it; past 2⁶⁰ times that
    /// scale there is none (the full scan's bound stops sooner).
    fn root_ahead(&self, omega: f64, g0: f64) -> Option<SteadyState> {
        let up = g0 > 0.0;
        let mut h = 0.1 * self.speed / self.r_min().max(1e-300);
        let dir = if up { 1.0 } else { -1.0 };
        let (mut prev, mut gprev) = (omega, g0);
        for _ in 0..64 {
            let w = omega + dir * h;
            let gw = self.moment(w);
            if gw == 0.0 {
                return Some(self.classify(w));
            }
            if (gw > 0.0) != up {
                return Some(self.classify(self.refine((prev, gprev), (w, gw))));
            }
            (prev, gprev) = (w, gw);
            h *= 2.0;
        }
        None
    }

    fn classify(&self, w: f64) -> SteadyState {
        let (umin, idx) = self.min_support_speed(w);
        let scale = self.speed_scale(w);
        let h = 1e-7 * scale.max(1e-300)
            / self
                .b
                .iter()
                .fold(0.0f64, |a, &b| a.max(b))
                .sqrt()
                .max(1e-300);
        if umin <= 1e-6 * scale {
            // A jump in G: decide stability from the sign on each side.
            let stable = self.moment(w - h) > 0.0 && self.moment(w + h) < 0.0;
            return SteadyState {
                omega: w,
                kind: RootKind::Pivot {
                    support: idx,
                    stable,
                },
                tau: None,
            };
        }
        let slope = self.moment_slope(w);
        if slope < 0.0 {
            SteadyState {
                omega: w,
                kind: RootKind::Stable,
                tau: Some(-self.inertia_contact / slope),
            }
        } else {
            SteadyState {
                omega: w,
                kind: RootKind::Unstable,
                tau: None,
            }
        }
    }

    /// Bracketed root refinement to machine precision: regula falsi with the
    /// Anderson–Björck scaling of the retained end (superlinear), and a
    /// bisection whenever three steps in a row have not halved the bracket.
    /// Stops when the bracket is a few ulps wide or `|G|` is down to its
    /// rounding floor (a few ε times the moments summed): near ω* = 0 the
    /// bracket's relative width never gets there. `g(lo)` and `g(hi)` have
    /// opposite signs; the caller passes them with the ends, `(ω, G(ω))`
    /// (either end first).
    fn refine(&self, (mut lo, mut glo): (f64, f64), (mut hi, mut ghi): (f64, f64)) -> f64 {
        let g = |w: f64| self.moment(w);
        let mut side = 0i8;
        let mut width = (hi - lo).abs();
        let mut slow = 0;
        for _ in 0..200 {
            let mut w = if slow >= 3 {
                slow = 0;
                0.5 * (lo + hi)
            } else {
                (lo * ghi - hi * glo) / (ghi - glo)
            };
            if !(w > lo.min(hi) && w < lo.max(hi)) {
                w = 0.5 * (lo + hi);
            }
            let gw = g(w);
            // |G| at its rounding floor: no point in the bracket is closer.
            if gw.abs() <= 4.0 * f64::EPSILON * (self.max_moment + (self.k * w).abs()) {
                return w;
            }
            if gw.signum() == glo.signum() {
                // The hi end is kept: scale its value (Anderson–Björck).
                if side == -1 {
                    let m = 1.0 - gw / glo;
                    ghi *= if m > 0.0 { m } else { 0.5 };
                }
                lo = w;
                glo = gw;
                side = -1;
            } else {
                if side == 1 {
                    let m = 1.0 - gw / ghi;
                    glo *= if m > 0.0 { m } else { 0.5 };
                }
                hi = w;
                ghi = gw;
                side = 1;
            }
            let new_width = (hi - lo).abs();
            if new_width <= 4.0 * f64::EPSILON * lo.abs().max(hi.abs()) + 1e-300 {
                break;
            }
            if new_width > 0.5 * width {
                slow += 1;
            } else {
                slow = 0;
            }
            width = new_width;
        }
        if glo.abs() < ghi.abs() {
            lo
        } else {
            hi
        }
    }

    /// The steady state a transient starting at `omega` converges to: the
    /// nearest root in the direction ω̇ drives it. None when ω runs away.
    pub fn attractor(&self, roots: &[SteadyState], omega: f64) -> Option<SteadyState> {
        let gw = self.moment(omega);
        if let Some(r) = roots
            .iter()
            .find(|r| (r.omega - omega).abs() <= 1e-12 * (1.0 + omega.abs()))
        {
            return Some(*r);
        }
        if gw > 0.0 {
            roots.iter().find(|r| r.omega > omega).copied()
        } else if gw < 0.0 {
            roots.iter().rev().find(|r| r.omega < omega).copied()
        } else {
            roots
                .iter()
                .min_by(|a, b| (a.omega - omega).abs().total_cmp(&(b.omega - omega).abs()))
                .copied()
        }
    }
}
