//! `fit.md`: the settings, the answer, where each set is unidentifiable
//! and the checks, every number from the rows.

use super::analysis::*;
use super::figure::sweep_x;

/// `fit.md`: the settings, the answer, where each set is unidentifiable and
/// the checks, every number from the rows.
pub(super) fn text(study: &Study, o: &Outcome, quick: bool) -> String {
    let sc = &study.base;
    let mut s = String::from(
        "# Fitting μ, I_cm, the contact and the centre of friction: identifiability\n\n",
    );
    s += "Written by `pushval fit-study`";
    if quick {
        s += " (`--quick`: reduced grids)";
    }
    s += " from the numbers in `identifiability.csv`; the figure is `identifiability.svg`.\n\n";
    s += &format!(
        "Scene: `{}` ({} kg, I_cm = {:.6} kg m², μ = {}, {} supports, contact at ({}, {}) m), started moving with the pusher at ω = 0. \
         Noise: {} mm on x and y, {} mrad on θ, every {} s sample. \
         Fisher std: the diagonal of (JᵀJ)⁻¹ of the whitened residuals at the truth (the file's values), \
         J by central differences (step {:e} of each parameter's scale), the model's DOP853 trajectory at tolerance {:e}. \
         Relative std: std / value for μ (scale 1) and I_cm.\n\n",
        sc.name,
        sc.mass,
        sc.inertia_cm,
        sc.supports[0].mu,
        sc.supports.len(),
        sc.contact.x,
        sc.contact.y,
        SIGMA_POSITION * 1e3,
        SIGMA_THETA * 1e3,
        sc.sample_dt,
        study.settings.fd_step,
        study.settings.tolerance
    );
    s += "## The shortest push\n\n";
    s += &format!(
        "Question: the shortest single push (from the paper's start) that gives μ within {} % and I_cm within {} % at {}σ (Fisher std at the stated noise, fitting mu_scale and inertia_cm together).\n\n",
        MU_TARGET * 100.0,
        INERTIA_TARGET * 100.0,
        SIGMAS
    );
    let answer = |(v, phi, d): (f64, f64, f64)| {
        let mut rel = String::new();
        for r in o
            .rows
            .iter()
            .filter(|r| r.point.sweep == "shortest" && r.point.speed == v && r.point.phi == phi)
        {
            rel += &format!(
                ", {} 2σ = {:.2} %",
                r.param.name(),
                100.0 * SIGMAS * r.relative_std()
            );
        }
        format!(
            "{d:.2} s at {v} m/s and φ = {phi:.4} rad (φ − π/4 = {:+.2} rad){rel}",
            phi - FRAC_PI_4
        )
    };
    match o.best(true) {
        Some(b) => {
            s += &format!(
                "**Answer: {}**, the shortest of the pushes on which the model's assumptions hold (pushing only, no contact slip at the file's contact μ, every support sliding); searched over the speeds and angles below in steps of one sample ({} s).\n\n",
                answer(b),
                sc.sample_dt
            );
        }
        None => s += "**Answer: none of the candidates on which the model's assumptions hold reaches both targets within the longest duration searched.**\n\n",
    }
    if let Some(b) = o.best(false).filter(|b| Some(*b) != o.best(true)) {
        s += &format!(
            "Ignoring the assumption checks, the shortest would be {} — but there the model itself is not to be trusted.\n\n",
            answer(b)
        );
    }
    s += "| speed (m/s) | φ (rad) | shortest duration (s) | failing assumption checks on it |\n|---|---|---|---|\n";
    for c in &o.shortest {
        let d = c
            .duration
            .map_or("> longest searched".to_string(), |d| format!("{d:.2}"));
        let v = if c.duration.is_none() {
            "".to_string()
        } else if c.violated.is_empty() {
            "none".to_string()
        } else {
            c.violated.join(", ")
        };
        s += &format!("| {} | {:.4} | {d} | {v} |\n", c.speed, c.phi);
    }
    s += "\n## Where a set is unidentifiable\n\n";
    s += "By the rules of `pushval fit` (information below 1e-10 of the largest, a direction with eigenvalue below 1e-10 of the largest, or a Fisher std above 1e3 × the scale):\n\n";
    for (set, params) in sets().iter().enumerate() {
        for sweep in ["speed", "duration", "segments"] {
            let mut xs: Vec<f64> = Vec::new();
            let mut names: Vec<&str> = Vec::new();
            for r in o
                .rows
                .iter()
                .filter(|r| r.point.sweep == sweep && r.set == set)
            {
                if !r.fisher_std.is_finite() {
                    let x = sweep_x(sweep, &r.point);
                    if !xs.contains(&x) {
                        xs.push(x);
                    }
                    if !names.contains(&r.param.name()) {
                        names.push(r.param.name());
                    }
                }
            }
            let what = if xs.is_empty() {
                "identifiable everywhere".to_string()
            } else {
                format!(
                    "{} unidentifiable at {sweep} = {}",
                    names.join(", "),
                    xs.iter()
                        .map(|x| format!("{x}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            };
            s += &format!("- {} against {sweep}: {what}\n", set_name(params));
        }
    }
    s += "\n## Fisher std against repeated noisy fits\n\n";
    s += &format!(
        "At each check point, {FITS} fits to the exact trajectory plus fresh noise (fixed seeds), started off the truth (μ × 0.9, I × 1.15, vector parameters + 5 mm in x and y). \
         The empirical std of the estimates (about their mean) must lie within a factor {AGREEMENT} of the Fisher std either way: with {FITS} fits a normal estimate's sample std falls outside that about 0.1 % of the time.\n\n"
    );
    s += "| push | parameters | component | Fisher std | empirical std | ratio | within |\n|---|---|---|---|---|---|---|\n";
    for c in &o.checks {
        let push = format!(
            "{} m/s, {} s, {} segment(s), φ₁ = {:.4}",
            c.point.speed, c.point.duration, c.point.segments, c.point.phi
        );
        let mut j = 0;
        for p in &c.set {
            for k in 0..p.dim() {
                let r = c.empirical[j] / c.fisher[j];
                s += &format!(
                    "| {push} | {} | {} | {:.3e} | {:.3e} | {:.2} | {} |\n",
                    set_name(&c.set),
                    component_name(*p, k),
                    c.fisher[j],
                    c.empirical[j],
                    r,
                    if (1.0 / AGREEMENT..=AGREEMENT).contains(&r) {
                        "yes"
                    } else {
                        "NO"
                    }
                );
                j += 1;
            }
        }
        if c.failed > 0 {
            s += &format!(
                "| {push} | {} | {} of {} fits did not converge | | | | NO |\n",
                set_name(&c.set),
                c.failed,
                c.fits
            );
        }
    }
    s += &format!(
        "\n{} of {} checks pass.\n",
        o.checks.iter().filter(|c| c.pass()).count(),
        o.checks.len()
    );
    s
}
