//! Closed forms of what PhysX's friction types do to the steady ω (no PhysX
//! needed: they use only `pushval-model`).
//!
//! From the PhysX 5.1.3 source (physx-sys 0.11.5 vendors it, under
//! `physx/physx/source/lowleveldynamics/src/`):
//!
//! * **Welding** (`DyDynamics.cpp`, `PxsSolverConstraintPostProcessTask::
//!   mergeContacts`). All contact pairs between the same two bodies — here
//!   every foot against the static world — are merged into **one** solver
//!   constraint, unless a pair's contacts are modifiable; its points are then
//!   grouped into patches by normal and friction coefficient. Feet with one
//!   coefficient on a flat floor are one patch of n points
//!   ([`FootContacts::Welded`]); unwelded, each foot is
//!   a patch of one point ([`FootContacts::Separate`]).
//! * **Axes** (`DyContactPrep.cpp` for `ePATCH`, `DyContactPrepPF.cpp` for
//!   the others). Every patch takes `t0` from the relative *linear* velocity
//!   of the two bodies projected on the contact plane — for a body on static
//!   ground the direction of its **centre-of-mass** velocity, the same for
//!   every foot — and `t1 = n × t0` (`t0 × n` for the per-point types; the
//!   clamp is symmetric, the sign does not matter). Only below 1e-2 m/s
//!   (patch) or 3e-3 m/s (per point) does PhysX fall back on fixed axes.
//! * **Rows and caps** (`DySolverConstraints.cpp` `solveContact_BStatic`,
//!   `DySolverPFConstraints.cpp` `solveFriction_BStatic`). Each row is its own
//!   1-D constraint clamped to `±cap`: a box, not a disk.
//!   - `eTWO_DIRECTIONAL`: a `t0` and a `t1` row at every point, cap `μ λ_i`.
//!   - `eONE_DIRECTIONAL`: one row per point, `t0`, `t1`, `t0`, … in the
//!     order of the patch's points, cap `μ λ_i`; a one-point patch: `t0`.
//!   - `ePATCH`: a `t0` and a `t1` row at each of at most two anchors (the
//!     patch's first point, then greedily the farthest pair, `growPatches` in
//!     `DyFrictionCorrelation.cpp`), cap `μ Σλ` over the patch, halved with
//!     two anchors (`eIMPROVED_PATCH_FRICTION`, on by default).
//!
//! So in steady sliding a row at point `p` on axis `t` with cap `c` gives
//! `−c sgn(u_p·t) t`, with `u_p = v_c n_φ + ω D (p − p_c)` the point's
//! velocity, `t0 = v_cm/|v_cm|`, `v_cm = v_c n_φ − ω D p_c` (object frame,
//! origin at the centre of mass) and `t1 = D t0`; a row whose velocity is zero
//! sticks (any force in `[−c, c]`). The steady ω is a root of
//! `G(ω) = I_P ω̇ = Σ (p − p_c) × f + m v_c ω (p_c · n_φ)` ([`moment`],
//! [`steady_omega`]).
//!
//! At ω = 0 every point slides along `v_cm = v_c n_φ`, so every `t1` row
//! changes sign there and `G` jumps: the `t1` rows hold the orientation when
//! the jump straddles 0 ([`locks`], `|M₀| ≤ H`). The rows are set-valued one
//! by one, so a run that starts at ω = 0 can also stay there when the
//! sticking `t1` rows merely balance the `t0` rows ([`holds_at_rest`],
//! `|M₀| ≤ S`, S ≥ H); between the two, ω = 0 is semi-stable ([`at_rest`]).
//! On the paper plate patch and two-directional friction lock in either
//! scene; welded one-directional friction is semi-stable and PhysX holds it;
//! the one-directional law on separate feet ([`Law::Line`]), which has no
//! `t1` row, turns. On feet close to the centre of mass the lock fails and
//! every law has an ordinary root.

use pushval_model::{cross, perp, Body, Problem, Push, Support, Vec2};

use crate::{FrictionLaw, LawClass, LawSteady};

/// PhysX's friction types (`PxFrictionType`, set per scene). PhysX 5.1.3
/// (physx-sys 0.11.5) has exactly these three; `eONE_DIRECTIONAL` and
/// `eTWO_DIRECTIONAL` were deprecated in later 5.x releases (5.4) and only
/// patch friction remains there.
///
/// Every friction patch takes the same two axes: `t0`, the direction of the
/// body's **centre-of-mass** velocity in the ground plane (the relative
/// linear velocity of the two bodies, not the contact point's), and
/// `t1 = n × t0`. Each row is a separate 1-D constraint clamped to `±cap`:
/// a box, not a disk. What a patch is depends on [`FootContacts`]; the laws
/// are in this module.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum FrictionType {
    /// `ePATCH` (PhysX's default): per contact patch, up to two friction
    /// anchors (contact points; the second the farthest from the first), each
    /// with a `t0` and a `t1` row capped by the patch's `μ_d Σλ_n` once
    /// `μ_s Σλ_n` is passed, halved when there are two anchors (the material
    /// flag `eIMPROVED_PATCH_FRICTION`, on by default). Solved with the
    /// normals in the last three position iterations and in the velocity
    /// iterations.
    #[default]
    Patch,
    /// `eTWO_DIRECTIONAL`: per contact point a `t0` and a `t1` row, each
    /// capped by the point's `μ_s λ_n`; solved after all normal iterations.
    TwoDirectional,
    /// `eONE_DIRECTIONAL`: per contact point **one** row, alternating `t0`,
    /// `t1`, `t0`, … from point to point within a patch, capped by the point's
    /// `μ_s λ_n`; a one-point patch always gets `t0`.
    OneDirectional,
}

impl FrictionType {
    /// `"patch"`, `"two_directional"` or `"one_directional"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            FrictionType::Patch => "patch",
            FrictionType::TwoDirectional => "two_directional",
            FrictionType::OneDirectional => "one_directional",
        }
    }

    /// PhysX's name: `"ePATCH"`, `"eTWO_DIRECTIONAL"`, `"eONE_DIRECTIONAL"`.
    pub fn physx_name(&self) -> &'static str {
        match self {
            FrictionType::Patch => "ePATCH",
            FrictionType::TwoDirectional => "eTWO_DIRECTIONAL",
            FrictionType::OneDirectional => "eONE_DIRECTIONAL",
        }
    }

    /// The engine model's name: `physx_patch`, `physx_two_directional`,
    /// `physx_one_directional`.
    pub fn model_name(&self) -> &'static str {
        match self {
            FrictionType::Patch => "physx_patch",
            FrictionType::TwoDirectional => "physx_two_directional",
            FrictionType::OneDirectional => "physx_one_directional",
        }
    }

    /// The friction law of this type on feet at `points` (m, object frame)
    /// whose contacts PhysX orders as `order` (support indices; the order
    /// matters only for welded feet, see the module docs; on the paper plate
    /// PhysX's order gives feet 0 and 2 the `t0` rows).
    pub fn law(&self, contacts: FootContacts, order: &[usize], points: &[[f64; 2]]) -> Law {
        match (contacts, self) {
            (_, FrictionType::TwoDirectional) | (FootContacts::Separate, FrictionType::Patch) => {
                Law::Box
            }
            (FootContacts::Separate, FrictionType::OneDirectional) => Law::Line,
            (FootContacts::Welded, FrictionType::OneDirectional) => {
                Law::Alternating(alternating_mask(order))
            }
            (FootContacts::Welded, FrictionType::Patch) => {
                let (a, b) = patch_anchors(points, order);
                Law::Anchors(a, b)
            }
        }
    }

    /// All three, patch first.
    pub const ALL: [FrictionType; 3] = [
        FrictionType::Patch,
        FrictionType::TwoDirectional,
        FrictionType::OneDirectional,
    ];
}

/// How the feet's contacts with the ground reach PhysX's solver.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum FootContacts {
    /// PhysX's default: every foot is its own shape and its own contact pair,
    /// but the solver **welds** all contact pairs between the same two bodies
    /// into one constraint (`DyDynamics.cpp`, "constraint welding", always
    /// on) and groups its points into patches by normal and friction
    /// coefficient: the feet on the floor become **one patch** of n points.
    #[default]
    Welded,
    /// Every foot's pair is marked `eMODIFY_CONTACTS` (no callback modifies
    /// anything), which PhysX never welds: **one patch per foot**, of one
    /// point.
    Separate,
}

impl FootContacts {
    /// `"welded"` or `"separate"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            FootContacts::Welded => "welded",
            FootContacts::Separate => "separate",
        }
    }

    /// Both, welded first.
    pub const ALL: [FootContacts; 2] = [FootContacts::Welded, FootContacts::Separate];
}

/// A support-friction law (see the module docs). The caps come from the
/// body's support friction magnitudes `F_i`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Law {
    /// Coulomb at every support, `−F_i u_i/|u_i|` (the analytic model).
    Coulomb,
    /// A `t0` and a `t1` row at every point, cap `F_i`
    /// (`eTWO_DIRECTIONAL`; `ePATCH` on one-point patches).
    Box,
    /// A `t0` row at every point, cap `F_i` (`eONE_DIRECTIONAL` on one-point
    /// patches).
    Line,
    /// One row per point, `t0` where bit i of the mask is set, `t1` where it
    /// is not, cap `F_i` (`eONE_DIRECTIONAL` on a welded patch;
    /// [`alternating_mask`]).
    Alternating(u64),
    /// A `t0` and a `t1` row at the two anchor points, each capped by half the
    /// patch's total `Σ F_i` (`ePATCH` on a welded patch; [`patch_anchors`]);
    /// one anchor (`a == b`): the whole total.
    Anchors(usize, usize),
}

/// The friction axes `(t0, t1)` (object frame) at ω: `t0` along the
/// centre-of-mass velocity `v_c n_φ − ω D p_c`, `t1 = D t0`. `None` when that
/// velocity is zero.
pub fn axes(body: &Body, push: &Push, omega: f64) -> Option<(Vec2, Vec2)> {
    let v = push.velocity() - perp(&body.contact()) * omega;
    let n = v.norm();
    (n > 0.0).then(|| {
        let t0 = v / n;
        (t0, perp(&t0))
    })
}

/// Which axis a friction row is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Along the centre-of-mass velocity.
    T0,
    /// Across it.
    T1,
}

/// One friction row: a point (m, object frame), its axis, its cap (N).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Where it acts (m, object frame).
    pub point: Vec2,
    /// Its axis.
    pub axis: Axis,
    /// Its clamp (N).
    pub cap: f64,
}

/// The friction rows of `law` on `body` (empty for [`Law::Coulomb`]).
pub fn rows(body: &Body, law: Law) -> Vec<Row> {
    let row = |i: usize, axis: Axis, cap: f64| Row {
        point: body.support(i).position,
        axis,
        cap,
    };
    let n = body.len();
    match law {
        Law::Coulomb => Vec::new(),
        Law::Box => (0..n)
            .flat_map(|i| {
                let c = body.support(i).friction;
                [row(i, Axis::T0, c), row(i, Axis::T1, c)]
            })
            .collect(),
        Law::Line => (0..n)
            .map(|i| row(i, Axis::T0, body.support(i).friction))
            .collect(),
        Law::Alternating(mask) => (0..n)
            .map(|i| {
                let axis = if mask >> i & 1 == 1 {
                    Axis::T0
                } else {
                    Axis::T1
                };
                row(i, axis, body.support(i).friction)
            })
            .collect(),
        Law::Anchors(a, b) if a == b => {
            let c = body.total_friction();
            vec![row(a, Axis::T0, c), row(a, Axis::T1, c)]
        }
        Law::Anchors(a, b) => {
            let half = 0.5 * body.total_friction();
            [a, b]
                .into_iter()
                .flat_map(|i| [row(i, Axis::T0, half), row(i, Axis::T1, half)])
                .collect()
        }
    }
}

/// The mask of [`Law::Alternating`] for points in the patch order `order`
/// (support indices): the 1st, 3rd, 5th, … get `t0`.
pub fn alternating_mask(order: &[usize]) -> u64 {
    order.iter().step_by(2).fold(0u64, |m, &i| m | 1u64 << i)
}

/// The two anchors `ePATCH` picks from points in the order `order` (support
/// indices into `points`): the first point, the next one more than 1e-4 m
/// away, then each further point replaces the anchor it is farther from when
/// that lengthens the pair (`growPatches`). For a rectangle of four corners:
/// a diagonal.
pub fn patch_anchors(points: &[[f64; 2]], order: &[usize]) -> (usize, usize) {
    let d2 = |a: usize, b: usize| {
        let (p, q) = (points[a], points[b]);
        (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)
    };
    let mut anchors: Vec<usize> = Vec::with_capacity(2);
    let mut best = 0.0;
    for &j in order {
        match anchors.len() {
            0 => anchors.push(j),
            1 => {
                let d = d2(j, anchors[0]);
                if d > 1e-8 {
                    anchors.push(j);
                    best = d;
                }
            }
            _ => {
                let (d0, d1) = (d2(j, anchors[0]), d2(j, anchors[1]));
                if d0 > d1 {
                    if d0 > best {
                        anchors[1] = j;
                        best = d0;
                    }
                } else if d1 > best {
                    anchors[0] = j;
                    best = d1;
                }
            }
        }
    }
    match anchors[..] {
        [a, b] => (a, b),
        [a] => (a, a),
        _ => (0, 0),
    }
}

/// The normal loads (N) PhysX's PGS gives rigid feet at rest, in support
/// order: the limit of Gauss–Seidel sweeps, visiting the contacts in the
/// order `order` (support indices) and starting from zero impulses, on the
/// normal rows' effective-mass system `K λ = b 1` (the same gravity velocity
/// to cancel at every foot), scaled to carry `weight` (N). `K_ij = 1/m +
/// (x_i x_j + y_i y_j)/I_t` for feet at `points` (m, relative to the centre
/// of mass) of a body of mass `mass` (kg) and tilt inertia `tilt_inertia`
/// (kg m², both horizontal axes). With three feet this is statics; with more
/// the system is singular (statically indeterminate) and the sweeps' start
/// and order pick the split: on the paper plate about 2/7 and 3/14 of m g on the
/// diagonals (2.803 / 2.102 N), which warm starting then keeps. A foot whose
/// impulse would turn negative is clamped at 0, as PGS does.
pub fn pgs_rest_loads(
    points: &[[f64; 2]],
    mass: f64,
    tilt_inertia: f64,
    weight: f64,
    order: &[usize],
) -> Vec<f64> {
    let n = points.len();
    let k = |i: usize, j: usize| {
        1.0 / mass + (points[i][0] * points[j][0] + points[i][1] * points[j][1]) / tilt_inertia
    };
    let mut lambda = vec![0.0; n];
    for _ in 0..100_000 {
        let mut change = 0.0f64;
        for &i in order {
            let residual = 1.0 - (0..n).map(|j| k(i, j) * lambda[j]).sum::<f64>();
            let next = (lambda[i] + residual / k(i, i)).max(0.0);
            change = change.max((next - lambda[i]).abs());
            lambda[i] = next;
        }
        if change <= 1e-15 * mass {
            break;
        }
    }
    let total: f64 = lambda.iter().sum();
    lambda.iter().map(|l| l * weight / total).collect()
}

fn sgn(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// `G(ω) = I_P ω̇` (N m) under `law`: the friction moment about the contact
/// point plus the inertial term `m v_c ω (p_c · n_φ)`. A sticking row (zero
/// velocity along its axis) contributes nothing here; [`steady_omega`] finds
/// the set-valued roots.
pub fn moment(body: &Body, push: &Push, omega: f64, law: Law) -> f64 {
    let pc = body.contact();
    let v = push.velocity();
    let mut m = body.mass() * push.speed * omega * pc.dot(&push.direction());
    let vel = |p: Vec2| v + perp(&(p - pc)) * omega;
    if law == Law::Coulomb {
        for s in body.supports() {
            let u = vel(s.position);
            let n = u.norm();
            if n > 0.0 {
                m += cross(&(s.position - pc), &(-u * (s.friction / n)));
            }
        }
        return m;
    }
    let Some((t0, t1)) = axes(body, push, omega) else {
        return m;
    };
    for r in rows(body, law) {
        let t = match r.axis {
            Axis::T0 => t0,
            Axis::T1 => t1,
        };
        let f = -t * (r.cap * sgn(vel(r.point).dot(&t)));
        m += cross(&(r.point - pc), &f);
    }
    m
}

/// Whether `law` holds ω = 0 (see the module docs). Near ω = 0 every point
/// slides along `t0 ≈ n_φ`, so a `t0` row at `p` gives the moment
/// `−c (p − p_c) × n_φ` about the contact point, and a `t1` row slides with
/// `u·t1 = ω p·t0` (its speed across the centre-of-mass velocity, measured
/// from the centre of mass) and gives `−c sgn(ω p·n_φ) (p − p_c)·n_φ`. So
/// `G(0±) = M₀ ∓ H` with `M₀ = −Σ_{t0} c (p − p_c) × n_φ` and
/// `H = Σ_{t1} c sgn(p·n_φ) (p − p_c)·n_φ`, and ω = 0 attracts (the rows hold
/// it, Filippov's sliding mode) iff `|M₀| ≤ H`. False for [`Law::Coulomb`].
///
/// That the `t1` rows, sticking, can balance `M₀` at ω = 0 is the weaker
/// condition [`holds_at_rest`]: a row whose point lies behind the centre of
/// mass (`p·n_φ < 0`) counts against `H` but for `S`, and between the two ω
/// = 0 is semi-stable ([`AtRest`]).
pub fn locks(body: &Body, push: &Push, law: Law) -> bool {
    if law == Law::Coulomb {
        return false;
    }
    let (m0, h) = lock_moments(body, push, law);
    m0.abs() <= h
}

/// `(M₀, H)` of [`locks`] (N m).
pub fn lock_moments(body: &Body, push: &Push, law: Law) -> (f64, f64) {
    let pc = body.contact();
    let n = push.direction();
    let (mut m0, mut h) = (0.0, 0.0);
    for r in rows(body, law) {
        let d = r.point - pc;
        match r.axis {
            Axis::T0 => m0 -= r.cap * cross(&d, &n),
            Axis::T1 => h += r.cap * sgn(r.point.dot(&n)) * d.dot(&n),
        }
    }
    (m0, h)
}

/// Whether the `t1` rows, sticking, can balance the `t0` rows' moment at
/// ω = 0: `|M₀| ≤ S` with `S = Σ_{t1} c |(p − p_c)·n_φ|` ([`rest_moments`]).
/// This is the balance of a velocity-level (Moreau) step that ends at ω = 0
/// from ω = 0: every `t1` row then has zero velocity and may take any force
/// in `[−c, c]`, every `t0` row slides at its cap. It asks nothing of the
/// sign of `p·n_φ`, so it holds wherever [`locks`] does and also where a
/// `t1` row behind the centre of mass would, in continuous time, push ω away
/// from 0 (Filippov's condition fails, the static balance does not). False
/// for [`Law::Coulomb`].
pub fn holds_at_rest(body: &Body, push: &Push, law: Law) -> bool {
    if law == Law::Coulomb {
        return false;
    }
    let (m0, s) = rest_moments(body, push, law);
    m0.abs() <= s
}

/// `(M₀, S)` of [`holds_at_rest`] (N m): the `t0` rows' moment about the
/// contact point at ω = 0 and the largest moment the `t1` rows can hold.
pub fn rest_moments(body: &Body, push: &Push, law: Law) -> (f64, f64) {
    let pc = body.contact();
    let n = push.direction();
    let (mut m0, mut s) = (0.0, 0.0);
    for r in rows(body, law) {
        let d = r.point - pc;
        match r.axis {
            Axis::T0 => m0 -= r.cap * cross(&d, &n),
            Axis::T1 => s += r.cap * d.dot(&n).abs(),
        }
    }
    (m0, s)
}

/// What ω = 0 is for a run started there, from the two criteria.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AtRest {
    /// `|M₀| ≤ H` ([`locks`]): ω = 0 attracts from both sides.
    Locked,
    /// `H < |M₀| ≤ S` ([`holds_at_rest`] but not [`locks`]): the sticking
    /// `t1` rows hold ω = 0, and ω returns to 0 from the side opposite to
    /// `M₀`; a disturbance to the side of `M₀` leaves for the root
    /// [`steady_omega`] finds from 0. Which of the two a run shows depends on
    /// the solver's disturbances, not on the law.
    SemiStable,
    /// `|M₀| > S`: ω leaves 0 for the root [`steady_omega`] finds from 0.
    Turns,
}

/// The class of ω = 0 under `law` ([`AtRest`]).
pub fn at_rest(body: &Body, push: &Push, law: Law) -> AtRest {
    if locks(body, push, law) {
        AtRest::Locked
    } else if holds_at_rest(body, push, law) {
        AtRest::SemiStable
    } else {
        AtRest::Turns
    }
}

/// The steady ω a run started at ω = 0 reaches when the sticking `t1` rows
/// hold whatever they can balance and nothing disturbs it: 0 where
/// [`holds_at_rest`], else [`steady_omega`] from 0.
pub fn steady_from_rest(body: &Body, push: &Push, law: Law) -> Steady {
    if holds_at_rest(body, push, law) {
        Steady {
            omega: 0.0,
            sticks: true,
        }
    } else {
        steady_omega(body, push, law, 0.0)
    }
}

/// A steady state of a friction law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steady {
    /// The steady ω (rad/s).
    pub omega: f64,
    /// True when `G` jumps across zero there (a friction row sticks and holds
    /// ω: a set-valued root, e.g. the lock at 0), false at an ordinary root.
    pub sticks: bool,
}

/// The steady ω that `I_P ω̇ = G(ω)` reaches from `omega0` (rad/s) under
/// `law`: marching from `omega0` in the direction `G` drives ω to the first
/// sign change of `G`, then bisecting; a sign change by a jump is a sticking
/// root. From `omega0 = 0` the side is read off `G(0±)`: 0 itself when the
/// jump straddles 0 ([`locks`]), otherwise the side both point to (or, when
/// they point away from each other, the side of `G(0+) + G(0−)`).
pub fn steady_omega(body: &Body, push: &Push, law: Law, omega0: f64) -> Steady {
    let g = |w: f64| moment(body, push, w, law);
    let (start, g0) = if omega0 == 0.0 {
        let eps = 1e-12;
        let (gp, gm) = (g(eps), g(-eps));
        if gp <= 0.0 && gm >= 0.0 {
            return Steady {
                omega: 0.0,
                sticks: gp < 0.0 || gm > 0.0,
            };
        }
        let side = if gp > 0.0 && gm > 0.0 {
            1.0
        } else if gp < 0.0 && gm < 0.0 {
            -1.0
        } else {
            (gp + gm).signum()
        };
        (side * eps, g(side * eps))
    } else {
        (omega0, g(omega0))
    };
    if g0 == 0.0 {
        return Steady {
            omega: start,
            sticks: false,
        };
    }
    let dir = g0.signum();
    let mut lo = start;
    let mut step = 1e-3 * (push.speed + 1e-3);
    let mut hi = start + dir * step;
    let mut n = 0;
    while g(hi) * dir > 0.0 && n < 200 {
        lo = hi;
        step *= 1.5;
        hi += dir * step;
        n += 1;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid == lo || mid == hi {
            break;
        }
        if g(mid) * dir > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let scale = body.total_friction()
        * body
            .supports()
            .map(|s| (s.position - body.contact()).norm())
            .fold(0.0, f64::max);
    let jump = g(lo).abs().min(g(hi).abs());
    Steady {
        omega: 0.5 * (lo + hi),
        sticks: jump > 1e-9 * scale,
    }
}

/// PhysX's friction rows in closed form, capped by the friction PhysX gives
/// the feet at rest (`μ̄ N_i`, N_i the PGS split of [`pgs_rest_loads`]): the
/// law of the friction type on welded or separate feet, the class of ω = 0
/// from the lock (`|M₀| ≤ H`) and hold (`|M₀| ≤ S`) criteria, and the steady
/// ω a run from rest reaches. PhysX's contact order is taken as the
/// supports' order (on the paper plate it gives feet 0 and 2 the `t0` rows,
/// as PhysX does).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysxClamp {
    /// The scene's friction type.
    pub friction: FrictionType,
    /// How the feet's contacts reach the solver; default welded.
    pub contacts: FootContacts,
    /// Plate thickness (m) for the tilt inertia of the rest loads; default
    /// `0.005`.
    pub plate_thickness: f64,
    /// Gravity (m/s²); default 9.81.
    pub gravity: f64,
}

impl PhysxClamp {
    /// The law of `friction` with the PhysX adapter's defaults (welded feet,
    /// 5 mm plate, g = 9.81 m/s²).
    pub fn new(friction: FrictionType) -> Self {
        Self {
            friction,
            contacts: FootContacts::Welded,
            plate_thickness: 0.005,
            gravity: 9.81,
        }
    }

    /// The closed form of PhysX's rest loads for `problem` (N, support
    /// order; [`pgs_rest_loads`] with the scene's mass, tilt inertia and
    /// gravity, contacts visited in the supports' order).
    pub fn rest_loads(&self, problem: &Problem) -> Vec<f64> {
        let body = &problem.body;
        let points: Vec<[f64; 2]> = body
            .supports()
            .map(|p| [p.position.x, p.position.y])
            .collect();
        let order: Vec<usize> = (0..points.len()).collect();
        let t = self.plate_thickness;
        let tilt = 0.5 * body.inertia_cm() + body.mass() * t * t / 12.0;
        pgs_rest_loads(
            &points,
            body.mass(),
            tilt,
            body.mass() * self.gravity,
            &order,
        )
    }

    /// The body the law's rows see: every foot's cap `μ̄ N_i` with PhysX's
    /// one coefficient `μ̄ = Σ F_i / (m g)` and its rest loads
    /// ([`Self::rest_loads`]), as the engine has them.
    fn engine_body(&self, problem: &Problem) -> Option<Body> {
        let body = &problem.body;
        let mu = body.total_friction() / (body.mass() * self.gravity);
        let supports: Vec<Support> = body
            .supports()
            .zip(self.rest_loads(problem))
            .map(|(s, n)| Support {
                position: s.position,
                friction: mu * n,
            })
            .collect();
        Body::new(body.mass(), body.inertia_cm(), body.contact(), &supports).ok()
    }
}

impl FrictionLaw for PhysxClamp {
    fn law_name(&self) -> &'static str {
        match (self.contacts, self.friction) {
            (FootContacts::Welded, FrictionType::Patch) => {
                "one welded patch: t0/t1 rows at two anchors, each capped at half of μΣN (pushval_physx::predict)"
            }
            (FootContacts::Welded, FrictionType::OneDirectional) => {
                "one welded patch: one row per foot, t0 and t1 alternating, cap μN (pushval_physx::predict)"
            }
            (FootContacts::Separate, FrictionType::OneDirectional) => {
                "a t0 row per foot along the centre of mass's velocity, cap μN (pushval_physx::predict)"
            }
            _ => "a t0 and a t1 row per foot, each capped at μN: a box (pushval_physx::predict)",
        }
    }
    fn steady(&self, problem: &Problem, segment: usize, _dt: f64) -> Option<LawSteady> {
        let push = problem.pushes.get(segment)?;
        self.steady_of(&self.engine_body(problem)?, push)
    }
    /// PhysX's loads at rest ([`pgs_rest_loads`]: the PGS split of `m g`
    /// over the feet, in the supports' order). The centre of mass and the
    /// pusher are on the floor's plane, so the push moves no load.
    fn loads(&self, problem: &Problem, _segment: usize, _dt: f64) -> Option<Vec<f64>> {
        Some(self.rest_loads(problem))
    }
    /// The rows and caps at the run's loads: every foot's cap `μ̄ N_i` with
    /// the given `N_i` in place of the rest loads.
    fn steady_on_loads(
        &self,
        problem: &Problem,
        segment: usize,
        _dt: f64,
        loads: &[f64],
    ) -> Option<LawSteady> {
        let push = problem.pushes.get(segment)?;
        let body = &problem.body;
        if !crate::law::usable_loads(loads, body.len()) {
            return None;
        }
        let mu = body.total_friction() / (body.mass() * self.gravity);
        let supports: Vec<Support> = body
            .supports()
            .zip(loads)
            .map(|(s, n)| Support {
                position: s.position,
                friction: mu * n,
            })
            .collect();
        let body = Body::new(body.mass(), body.inertia_cm(), body.contact(), &supports).ok()?;
        self.steady_of(&body, push)
    }
}

impl PhysxClamp {
    /// The law's steady state for `body` (its caps the supports' friction).
    fn steady_of(&self, body: &Body, push: &Push) -> Option<LawSteady> {
        let points: Vec<[f64; 2]> = body
            .supports()
            .map(|s| [s.position.x, s.position.y])
            .collect();
        let order: Vec<usize> = (0..points.len()).collect();
        let law = self.friction.law(self.contacts, &order, &points);
        let class = match at_rest(body, push, law) {
            AtRest::Locked => LawClass::Locked,
            AtRest::Turns => LawClass::Turns,
            AtRest::SemiStable => {
                let (moment, lock) = lock_moments(body, push, law);
                LawClass::SemiStable {
                    moment,
                    lock,
                    hold: rest_moments(body, push, law).1,
                }
            }
        };
        Some(LawSteady {
            omega: steady_from_rest(body, push, law).omega,
            class,
        })
    }
}
