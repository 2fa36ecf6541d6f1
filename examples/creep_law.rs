//! MuJoCo's creep ladder: writes results/friction_models/mujoco/creep_law.csv
//! (one row per run, the closed form of `pushval_mujoco::creep` beside each
//! measurement) and creep_law.md (generated from that CSV).
//!
//! ```text
//! eval "$(scripts/setup-mujoco.sh)"
//! cargo run --release --features mujoco --example creep_law [-- OUT_DIR]
//! ```
//!
//! OUT_DIR defaults to results/friction_models/mujoco. Files are written to a
//! temporary name and renamed, so a failed run leaves the old ones. Exit
//! code 2 on an error.

use std::f64::consts::FRAC_PI_4;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use pushval::report::creep_law::{markdown, CSV_COLUMNS};
use pushval_mujoco::creep::{
    hold_time, measure, CreepCase, CreepRegime, CreepScene, SLIDING_SPEED,
};
use pushval_mujoco::{Cone, MujocoSettings};

/// One run of the ladder.
struct Cell {
    group: &'static str,
    scene: CreepScene,
    direction: f64,
    load: f64,
    case: CreepCase,
}

fn scene(cone: Cone, impratio: f64, dt: f64) -> CreepScene {
    CreepScene {
        settings: MujocoSettings {
            cone,
            impratio,
            timestep: dt,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// A change of the default scene.
type Variant = Box<dyn Fn(&mut CreepScene)>;

const IMPRATIOS: [f64; 3] = [1.0, 10.0, 100.0];
const CASES: [CreepCase; 2] = [CreepCase::Held, CreepCase::Sliding(SLIDING_SPEED)];

fn ladder() -> Vec<Cell> {
    let mut cells = Vec::new();
    let mut push = |group, scene, direction, load, case| {
        cells.push(Cell {
            group,
            scene,
            direction,
            load,
            case,
        })
    };
    // impratio × cone × load × dt × case.
    for cone in Cone::ALL {
        for imp in IMPRATIOS {
            for dt in [5e-4, 1e-3, 5e-3, 2e-2] {
                for load in [0.25, 0.5, 0.75, 0.9] {
                    for case in CASES {
                        push("ladder", scene(cone, imp, dt), 0.0, load, case);
                    }
                }
            }
        }
    }
    // solref, solimp, feet at dt = 1e-3.
    let variants: [(&str, Variant); 8] = [
        (
            "solref",
            Box::new(|s| s.settings.contact_solref = [0.005, 1.0]),
        ),
        (
            "solref",
            Box::new(|s| s.settings.contact_solref = [0.05, 1.0]),
        ),
        (
            "solref",
            Box::new(|s| s.settings.contact_solref = [0.02, 0.7]),
        ),
        (
            "solref",
            Box::new(|s| s.settings.contact_solref = [0.02, 0.5]),
        ),
        (
            "solref",
            Box::new(|s| s.settings.contact_solref = [0.02, 0.3]),
        ),
        (
            "solimp",
            Box::new(|s| s.settings.contact_solimp = [0.99, 0.99, 0.001, 0.5, 2.0]),
        ),
        (
            "solimp",
            Box::new(|s| s.settings.contact_solimp = [0.5, 0.95, 0.004, 0.5, 2.0]),
        ),
        ("feet", Box::new(|s| s.feet = 8)),
    ];
    for (group, apply) in &variants {
        for cone in Cone::ALL {
            for imp in IMPRATIOS {
                for load in [0.5, 0.9] {
                    for case in CASES {
                        let mut s = scene(cone, imp, 1e-3);
                        apply(&mut s);
                        push(group, s, 0.0, load, case);
                    }
                }
            }
        }
    }
    // No load: does the plate settle on its feet at all?
    for cone in Cone::ALL {
        for zeta in [1.0, 0.7, 0.5, 0.3] {
            for imp in [1.0, 100.0] {
                let mut s = scene(cone, imp, 1e-3);
                s.settings.contact_solref = [0.02, zeta];
                push("unloaded", s, 0.0, 0.0, CreepCase::Held);
            }
        }
    }
    // Load direction: the pyramid's anisotropy (the ellipse for contrast).
    for (cone, dirs) in [
        (Cone::Pyramidal, vec![FRAC_PI_4 / 3.0, FRAC_PI_4]),
        (Cone::Elliptic, vec![FRAC_PI_4]),
    ] {
        for imp in [1.0, 100.0] {
            for &dir in &dirs {
                for load in [0.5, 0.6, 0.75, 0.9] {
                    for case in CASES {
                        push("direction", scene(cone, imp, 1e-3), dir, load, case);
                    }
                }
            }
        }
    }
    // Limits: at and past the friction limit; MuJoCo's noslip pass.
    for cone in Cone::ALL {
        for imp in [1.0, 100.0] {
            for load in [0.99, 1.05] {
                for case in CASES {
                    push("limit", scene(cone, imp, 1e-3), 0.0, load, case);
                }
            }
            for load in [0.5, 0.9] {
                let mut s = scene(cone, imp, 1e-3);
                s.settings.noslip_iterations = 10;
                push("noslip", s, 0.0, load, CreepCase::Held);
            }
        }
    }
    cells
}

fn row(c: &Cell) -> Result<[String; 25], String> {
    let s = &c.scene.settings;
    let hold = hold_time(c.case, c.load, c.scene.mu, s.gravity);
    let m = measure(&c.scene, c.case, c.load, c.direction, hold).map_err(|e| {
        format!(
            "{} run (cone {}, impratio {}, dt {}, λ {}, {}): {e}",
            c.group,
            s.cone.as_str(),
            s.impratio,
            s.timestep,
            c.load,
            c.case.as_str()
        )
    })?;
    let ([along, across], p) = c.scene.predicted(c.load, c.direction, m.tangents);
    let rel = if p.regime == CreepRegime::Slides || c.load == 0.0 {
        f64::NAN
    } else {
        (m.creep - along).hypot(m.lateral - across) / along.hypot(across)
    };
    let input = c.scene.creep_input(c.load, c.direction, m.tangents);
    let e = |v: f64, d: usize| {
        if v.is_finite() {
            format!("{v:.d$e}")
        } else {
            String::new()
        }
    };
    let [r0, r1] = s.contact_solref;
    let si = s.contact_solimp;
    Ok([
        c.group.to_string(),
        format!("{}", s.impratio),
        s.cone.as_str().to_string(),
        format!("{r0} {r1}"),
        format!("{} {} {} {} {}", si[0], si[1], si[2], si[3], si[4]),
        format!("{}", s.timestep),
        format!("{}", c.scene.feet_positions().len()),
        format!("{}", s.noslip_iterations),
        format!("{:.6}", c.direction),
        format!("{}", c.load),
        c.case.as_str().to_string(),
        p.regime.as_str().to_string(),
        e(m.creep, 6),
        e(along, 6),
        e(rel, 3),
        e(m.steadiness(), 2),
        e(m.lateral, 6),
        e(across, 6),
        format!("{hold:.3}"),
        format!("{}", m.contacts),
        e(m.height_std, 2),
        e(m.penetration, 4),
        e(p.penetration, 4),
        format!("{:.6}", p.impedance),
        e(pushval_mujoco::creep::slip_scale(&input), 6),
    ])
}

fn write_atomic(path: &Path, text: &str) -> Result<(), String> {
    pushval::atomic::write_atomic(path, text.as_bytes()).map_err(|e| format!("{e:#}"))
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() > 1 {
        return Err(format!(
            "expected at most one argument (OUT_DIR), got {args:?}"
        ));
    }
    let out: PathBuf = match args.first() {
        Some(a) => PathBuf::from(a),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("results/friction_models/mujoco"),
    };
    let out = out
        .canonicalize()
        .map_err(|e| format!("OUT_DIR {}: {e}", out.display()))?;
    if !out.is_dir() {
        return Err(format!("OUT_DIR {} is not a directory", out.display()));
    }
    let cells = ladder();
    let start = std::time::Instant::now();
    let mut csv = pushval::outdir::Csv::new(&CSV_COLUMNS);
    for (i, c) in cells.iter().enumerate() {
        csv.row(&row(c)?);
        if (i + 1) % 50 == 0 {
            eprintln!("creep_law: {}/{} runs", i + 1, cells.len());
        }
    }
    let md = markdown(csv.text())?;
    write_atomic(&out.join("creep_law.csv"), csv.text())?;
    write_atomic(&out.join("creep_law.md"), &md)?;
    eprintln!(
        "creep_law: {} runs in {:.1} s; wrote {}/creep_law.csv and creep_law.md",
        cells.len(),
        start.elapsed().as_secs_f64(),
        out.display()
    );
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("creep_law: error: {e}");
            ExitCode::from(2)
        }
    }
}
