//! Runge–Kutta integrators for small fixed-size states.
//!
//! Written here rather than taken from an ODE crate because the trajectory
//! driver needs hooks no crate offers together: stopping exactly at every
//! switch, dense output at arbitrary sample times inside a step, and leaving
//! the integrator as soon as a segment has settled (the rest is a closed-form
//! arc). `benches/` compares it with `ode_solvers` on the same right-hand side.

/// State size of the pushing ODE: `[θ, ω, c_x, c_y]`.
pub const N: usize = 4;
/// An ODE state.
pub type State = [f64; N];

#[inline]
fn axpy(y: &State, h: f64, terms: &[(f64, &State)]) -> State {
    let mut out = *y;
    for (a, k) in terms {
        if *a != 0.0 {
            for i in 0..N {
                out[i] += h * a * k[i];
            }
        }
    }
    out
}

// Dormand–Prince 5(4) coefficients (Dormand & Prince 1980; Hairer, Nørsett &
// Wanner, Solving ODEs I, Table 5.2), with the 4th-order continuous extension
// of Shampine (1986) as used in Hairer's DOPRI5.
// The pushing ODE is autonomous, so the nodes c_i never enter a stage.
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Dense output over one accepted step: `y(t0 + s h)` for `s ∈ [0, 1]`, 4th order.
#[derive(Debug, Clone, Copy)]
pub struct Dense {
    /// Start of the step (s).
    pub t0: f64,
    /// Step size (s).
    pub h: f64,
    r: [State; 5],
}

impl Dense {
    /// The interpolated state at time `t` (within the step).
    #[inline]
    pub fn eval(&self, t: f64) -> State {
        let s = (t - self.t0) / self.h;
        let s1 = 1.0 - s;
        let mut out = [0.0; N];
        for (i, o) in out.iter_mut().enumerate() {
            let r = &self.r;
            *o = r[0][i] + s * (r[1][i] + s1 * (r[2][i] + s * (r[3][i] + s1 * r[4][i])));
        }
        out
    }
}

/// Result of one attempted Dormand–Prince step.
pub struct Attempt {
    /// The state at the step's end (5th order).
    pub y1: State,
    /// Derivative at the new point (first stage of the next step: FSAL).
    pub k7: State,
    /// Error norm; the step is acceptable when ≤ 1.
    pub err: f64,
    k: [State; 6],
}

/// One Dormand–Prince 5(4) step of size `h` from `y0` with derivative `k1`.
/// Error weights: `atol + rtol_i max(|y0_i|, |y1_i|)` per component (a
/// per-component relative tolerance, so that components whose size carries
/// no meaning, like a position that depends on the choice of origin, can be
/// held to the absolute one), RMS norm.
#[inline]
pub fn dp5_attempt<F: FnMut(&State) -> State>(
    f: &mut F,
    y0: &State,
    k1: &State,
    h: f64,
    atol: f64,
    rtol: &State,
) -> Attempt {
    let k2 = f(&axpy(y0, h, &[(A21, k1)]));
    let k3 = f(&axpy(y0, h, &[(A31, k1), (A32, &k2)]));
    let k4 = f(&axpy(y0, h, &[(A41, k1), (A42, &k2), (A43, &k3)]));
    let k5 = f(&axpy(
        y0,
        h,
        &[(A51, k1), (A52, &k2), (A53, &k3), (A54, &k4)],
    ));
    let k6 = f(&axpy(
        y0,
        h,
        &[(A61, k1), (A62, &k2), (A63, &k3), (A64, &k4), (A65, &k5)],
    ));
    let y1 = axpy(
        y0,
        h,
        &[(A71, k1), (A73, &k3), (A74, &k4), (A75, &k5), (A76, &k6)],
    );
    let k7 = f(&y1);
    let mut sum = 0.0;
    for i in 0..N {
        let e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        let sc = atol + rtol[i] * y0[i].abs().max(y1[i].abs());
        sum += (e / sc) * (e / sc);
    }
    let err = (sum / N as f64).sqrt();
    Attempt {
        y1,
        k7,
        err: if err.is_nan() { f64::INFINITY } else { err },
        k: [*k1, k2, k3, k4, k5, k6],
    }
}

impl Attempt {
    /// Dense output for this (accepted) step.
    pub fn dense(&self, t0: f64, y0: &State, h: f64) -> Dense {
        let [k1, _k2, k3, k4, k5, k6] = &self.k;
        let k7 = &self.k7;
        let mut r = [[0.0; N]; 5];
        for i in 0..N {
            let dy = self.y1[i] - y0[i];
            let bspl = h * k1[i] - dy;
            r[0][i] = y0[i];
            r[1][i] = dy;
            r[2][i] = bspl;
            r[3][i] = dy - h * k7[i] - bspl;
            r[4][i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }
        Dense { t0, h, r }
    }
}

/// Next step size from an error norm (order-5 controller with a safety factor,
/// growth limited to [0.2, 5]).
#[inline]
pub fn next_step(h: f64, err: f64) -> f64 {
    let fac = if err == 0.0 {
        5.0
    } else {
        (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
    };
    h * fac
}

/// Next step size for the 8th-order pair: exponent 1/8, growth in [1/3, 6]
/// (Hairer's DOP853 defaults).
#[inline]
pub fn next_step8(h: f64, err: f64) -> f64 {
    let fac = if err == 0.0 {
        6.0
    } else {
        (0.9 * err.powf(-0.125)).clamp(1.0 / 3.0, 6.0)
    };
    h * fac
}

/// Initial step size (Hairer, Nørsett & Wanner, Sec. II.4): from the size of
/// the derivative, a trial Euler step and its second-derivative estimate.
///
/// `atol`/`rtol` are the error weights the integrator uses and `order` its
/// order; the state's own size is measured only over the components with a
/// relative tolerance (the step aims at a local error of 1% of the tolerance, which scales
/// as `h^(order + 1)`).
pub fn initial_step<F: FnMut(&State) -> State>(
    f: &mut F,
    y0: &State,
    k1: &State,
    atol: f64,
    rtol: &State,
    order: i32,
    hmax: f64,
) -> f64 {
    let norm = |v: &State, y: &State| {
        let mut s = 0.0;
        for i in 0..N {
            let sc = atol + rtol[i] * y[i].abs();
            s += (v[i] / sc).powi(2);
        }
        (s / N as f64).sqrt()
    };
    // The size of the state itself counts only where the tolerance is
    // relative: absolute components (angle, position) depend on the frame,
    // and so would the step.
    let relative: State = std::array::from_fn(|i| if rtol[i] > 0.0 { y0[i] } else { 0.0 });
    let d0 = norm(&relative, y0);
    let d1 = norm(k1, y0);
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    }
    .min(hmax);
    let y1 = axpy(y0, h0, &[(1.0, k1)]);
    let k2 = f(&y1);
    let diff: State = std::array::from_fn(|i| k2[i] - k1[i]);
    let d2 = norm(&diff, y0) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / (order as f64 + 1.0))
    };
    (100.0 * h0).min(h1).min(hmax)
}

/// One classical fourth-order Runge–Kutta step. Returns the new state.
#[inline]
pub fn rk4_step<F: FnMut(&State) -> State>(f: &mut F, y: &State, k1: &State, h: f64) -> State {
    let k2 = f(&axpy(y, 0.5 * h, &[(1.0, k1)]));
    let k3 = f(&axpy(y, 0.5 * h, &[(1.0, &k2)]));
    let k4 = f(&axpy(y, h, &[(1.0, &k3)]));
    axpy(y, h / 6.0, &[(1.0, k1), (2.0, &k2), (2.0, &k3), (1.0, &k4)])
}

/// Cubic Hermite interpolation between `(y0, f0)` at `t0` and `(y1, f1)` at
/// `t0 + h`, evaluated at `t` (used for the fixed-step RK4's samples).
#[inline]
pub fn hermite(t0: f64, h: f64, y0: &State, f0: &State, y1: &State, f1: &State, t: f64) -> State {
    let s = (t - t0) / h;
    let h00 = (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s);
    let h10 = s * (1.0 - s) * (1.0 - s);
    let h01 = s * s * (3.0 - 2.0 * s);
    let h11 = s * s * (s - 1.0);
    std::array::from_fn(|i| h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y' = A y with a rotation plus decay, known in closed form.
    fn f(y: &State) -> State {
        [-0.5 * y[0] + y[1], -y[0] - 0.5 * y[1], -y[2], 2.0 * y[3]]
    }
    fn exact(t: f64) -> State {
        let e = (-0.5 * t).exp();
        [e * t.cos(), -e * t.sin(), (-t).exp(), (2.0 * t).exp()]
    }

    #[test]
    fn dp5_step_error_is_fifth_order_and_dense_output_fourth() {
        let y0 = exact(0.0);
        let mut g = |y: &State| f(y);
        let k1 = g(&y0);
        let mut errs = vec![];
        let mut derrs = vec![];
        for h in [0.05, 0.025] {
            let a = dp5_attempt(&mut g, &y0, &k1, h, 1.0, &[0.0; N]);
            let ex = exact(h);
            errs.push((0..N).map(|i| (a.y1[i] - ex[i]).abs()).fold(0.0, f64::max));
            let d = a.dense(0.0, &y0, h);
            let exm = exact(0.37 * h);
            let ym = d.eval(0.37 * h);
            derrs.push((0..N).map(|i| (ym[i] - exm[i]).abs()).fold(0.0, f64::max));
        }
        // Local error of a 5th-order step is O(h^6); of the 4th-order interpolant O(h^5).
        let p = (errs[0] / errs[1]).log2();
        let pd = (derrs[0] / derrs[1]).log2();
        assert!((5.6..6.6).contains(&p), "local order {p}");
        assert!((4.6..5.8).contains(&pd), "dense local order {pd}");
    }

    #[test]
    fn rk4_global_order_is_four() {
        let run = |n: usize| {
            let h = 1.0 / n as f64;
            let mut y = exact(0.0);
            let mut g = |y: &State| f(y);
            for _ in 0..n {
                let k1 = g(&y);
                y = rk4_step(&mut g, &y, &k1, h);
            }
            let ex = exact(1.0);
            (0..N).map(|i| (y[i] - ex[i]).abs()).fold(0.0, f64::max)
        };
        let p = (run(20) / run(40)).log2();
        assert!((3.8..4.2).contains(&p), "order {p}");
    }

    /// Local error O(h⁹) for the 8th-order step, O(h⁸) for the 7th-order interpolant.
    #[test]
    fn dop853_orders() {
        let y0 = exact(0.0);
        let mut g = |y: &State| f(y);
        let k1 = g(&y0);
        let (mut e, mut d) = (vec![], vec![]);
        for h in [0.4, 0.2] {
            let a = dop853::attempt(&mut g, &y0, &k1, h, 1.0, &[0.0; N]);
            let ex = exact(h);
            e.push((0..N).map(|i| (a.y1[i] - ex[i]).abs()).fold(0.0, f64::max));
            let dn = a.dense(&mut g, 0.0, &y0, h);
            let ym = dn.eval(0.37 * h);
            let exm = exact(0.37 * h);
            d.push((0..N).map(|i| (ym[i] - exm[i]).abs()).fold(0.0, f64::max));
        }
        let p = (e[0] / e[1]).log2();
        let pd = (d[0] / d[1]).log2();
        assert!((8.4..9.8).contains(&p), "local order {p} {e:?}");
        assert!((7.4..8.8).contains(&pd), "dense local order {pd} {d:?}");
    }
}

/// Dormand & Prince's 8(5,3) pair (DOP853; Hairer, Nørsett & Wanner, Solving
/// ODEs I, Sec. II.10) with its 7th-order continuous extension. Twelve stages
/// per step (the thirteenth, f at the new point, is the next step's first);
/// the dense output costs three more, taken only for steps that hold a sample.
///
/// Generic over the state size `M` (default [`N`], the pushing ODE's): the
/// free slide (`crate::slide`) integrates a larger state with the same pair.
pub mod dop853 {
    use super::N;
    use crate::dop853_tables::{A, D, E3_SUB, E5};

    /// One attempted step.
    pub struct Attempt<const M: usize = N> {
        /// The state at the step's end (8th order).
        pub y1: [f64; M],
        /// f(y1): the next step's first stage.
        pub k13: [f64; M],
        /// Error norm; acceptable when ≤ 1.
        pub err: f64,
        k: [[f64; M]; 13],
    }

    #[inline]
    fn stage<const M: usize>(
        y0: &[f64; M],
        h: f64,
        k: &[[f64; M]],
        row: &[f64; 16],
        upto: usize,
    ) -> [f64; M] {
        let mut out = *y0;
        for (j, kj) in k.iter().enumerate().take(upto) {
            let a = row[j];
            if a != 0.0 {
                for i in 0..M {
                    out[i] += h * a * kj[i];
                }
            }
        }
        out
    }

    /// One DOP853 step of size `h` from `y0` with derivative `k1`; error
    /// weights `atol + rtol_i max(|y0_i|, |y1_i|)`, the combined 5th/3rd-order
    /// estimate of Hairer's code.
    pub fn attempt<const M: usize, F: FnMut(&[f64; M]) -> [f64; M]>(
        f: &mut F,
        y0: &[f64; M],
        k1: &[f64; M],
        h: f64,
        atol: f64,
        rtol: &[f64; M],
    ) -> Attempt<M> {
        attempt_with(f, y0, k1, h, |i, a: f64, b: f64| {
            atol + rtol[i] * a.abs().max(b.abs())
        })
    }

    /// [`attempt`] with the error weight of component `i` chosen by the
    /// caller, `weight(i, y0_i, y1_i)` (for components whose error is
    /// measured against another component's size).
    pub fn attempt_with<const M: usize, F, W>(
        f: &mut F,
        y0: &[f64; M],
        k1: &[f64; M],
        h: f64,
        weight: W,
    ) -> Attempt<M>
    where
        F: FnMut(&[f64; M]) -> [f64; M],
        W: Fn(usize, f64, f64) -> f64,
    {
        let mut k = [[0.0; M]; 13];
        k[0] = *k1;
        for s in 1..12 {
            k[s] = f(&stage(y0, h, &k, &A[s], s));
        }
        let y1 = stage(y0, h, &k, &A[12], 12);
        k[12] = f(&y1);
        let (mut e5, mut e3) = (0.0, 0.0);
        for i in 0..M {
            let sc = weight(i, y0[i], y1[i]);
            let mut d5 = 0.0;
            let mut d3 = 0.0;
            for s in 0..13 {
                d5 += E5[s] * k[s][i];
                let b = if s < 12 { A[12][s] } else { 0.0 };
                d3 += b * k[s][i];
            }
            for (s, sub) in E3_SUB {
                d3 -= sub * k[s][i];
            }
            e5 += (d5 / sc).powi(2);
            e3 += (d3 / sc).powi(2);
        }
        let deno = e5 + 0.01 * e3;
        let err = if deno > 0.0 {
            h.abs() * e5 / (deno * M as f64).sqrt()
        } else {
            0.0
        };
        Attempt {
            y1,
            k13: k[12],
            err: if err.is_nan() { f64::INFINITY } else { err },
            k,
        }
    }

    /// The 7th-order dense output over an accepted step.
    #[derive(Debug, Clone, Copy)]
    pub struct Dense<const M: usize = N> {
        /// Start of the step (s).
        pub t0: f64,
        /// Step size (s).
        pub h: f64,
        y0: [f64; M],
        r: [[f64; M]; 7],
    }

    impl<const M: usize> Attempt<M> {
        /// Builds the dense output (three more evaluations of `f`).
        pub fn dense<F: FnMut(&[f64; M]) -> [f64; M]>(
            &self,
            f: &mut F,
            t0: f64,
            y0: &[f64; M],
            h: f64,
        ) -> Dense<M> {
            let mut k = [[0.0; M]; 16];
            k[..13].copy_from_slice(&self.k);
            for s in 13..16 {
                k[s] = f(&stage(y0, h, &k, &A[s], s));
            }
            let mut r = [[0.0; M]; 7];
            for i in 0..M {
                let dy = self.y1[i] - y0[i];
                r[0][i] = dy;
                r[1][i] = h * k[0][i] - dy;
                r[2][i] = 2.0 * dy - h * (k[12][i] + k[0][i]);
                for (row, d) in D.iter().enumerate() {
                    let mut acc = 0.0;
                    for s in 0..16 {
                        acc += d[s] * k[s][i];
                    }
                    r[3 + row][i] = h * acc;
                }
            }
            Dense { t0, h, y0: *y0, r }
        }
    }

    impl<const M: usize> Dense<M> {
        /// The state at time `t` within the step.
        pub fn eval(&self, t: f64) -> [f64; M] {
            let s = (t - self.t0) / self.h;
            let s1 = 1.0 - s;
            let mut out = [0.0; M];
            for (i, o) in out.iter_mut().enumerate() {
                let r = &self.r;
                // y0 + s(r0 + s1(r1 + s(r2 + s1(r3 + s(r4 + s1(r5 + s r6))))))
                let mut acc = r[6][i];
                acc = r[5][i] + s * acc;
                acc = r[4][i] + s1 * acc;
                acc = r[3][i] + s * acc;
                acc = r[2][i] + s1 * acc;
                acc = r[1][i] + s * acc;
                acc = r[0][i] + s1 * acc;
                *o = self.y0[i] + s * acc;
            }
            out
        }
    }
}
