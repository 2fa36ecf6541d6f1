//! `[release]` and `[initial] velocity` (issue 46): the slide to rest in
//! the scenario format. A thrown plate (no pushes) slides from `[initial]`;
//! a velocity beside pushes is refused, naming the key.

use std::path::Path;

use pushval_model::Vec2;
use pushval_scenario::Scenario;

const PLATE: &str = r#"
name = "thrown"
[object]
mass = 1.0
polygon = [[-0.125, -0.125], [0.125, -0.125], [0.125, 0.125], [-0.125, 0.125]]
[supports]
points = [[-0.125, -0.125], [0.125, -0.125], [0.125, 0.125], [-0.125, 0.125]]
mu = 0.5
[contact]
point = [-0.125, -0.125]
"#;

fn load(extra: &str) -> Result<Scenario, pushval_scenario::ScenarioError> {
    Scenario::from_toml(&format!("{PLATE}{extra}"), Path::new("t.toml"))
}

const PUSH: &str = "[[push]]\nduration = 1.0\nspeed = 0.5\nphi = 0.7\n";

#[test]
fn a_thrown_plate_parses_with_its_velocity_and_release() {
    let sc = load("[initial]\ntheta = 0.2\nomega = 3.0\nvelocity = [1.0, -0.5]\n[release]\nmax_duration = 4.0\n")
        .unwrap();
    assert!(sc.pushes.is_empty());
    assert_eq!(sc.initial.velocity, Vec2::new(1.0, -0.5));
    assert_eq!(sc.initial.omega, 3.0);
    assert_eq!(sc.release.map(|r| r.max_duration), Some(4.0));
    let p = sc.problem();
    assert_eq!(p.release, sc.release);
    p.check().unwrap();
    // max_duration defaults to 10 s.
    let sc = load("[initial]\nvelocity = [1.0, 0.0]\n[release]\n").unwrap();
    assert_eq!(sc.release.map(|r| r.max_duration), Some(10.0));
    // After pushes: the release, no velocity.
    let sc = load(&format!("{PUSH}[release]\n")).unwrap();
    assert_eq!(sc.pushes.len(), 1);
    assert_eq!(sc.initial.velocity, Vec2::zeros());
    assert!(sc.release.is_some());
    // Without a release nothing changes.
    assert_eq!(load(PUSH).unwrap().release, None);
}

#[test]
fn bad_release_input_names_the_key() {
    let e = load(&format!("{PUSH}[initial]\nvelocity = [1.0, 0.0]\n")).unwrap_err();
    assert_eq!(e.key, "initial.velocity", "{e}");
    assert!(e.message.contains("without [[push]]"), "{e}");
    let e = load(&format!(
        "{PUSH}[initial]\nvelocity = [1.0, 0.0]\n[release]\n"
    ))
    .unwrap_err();
    assert_eq!(e.key, "initial.velocity", "{e}");
    let e = load("[release]\nmax_duration = -1.0\n").unwrap_err();
    assert_eq!(e.key, "release.max_duration", "{e}");
    let e = load("[release]\nmax_duraton = 1.0\n").unwrap_err();
    assert!(e.key.starts_with("release"), "{e}");
    let e = load("[initial]\nvelocity = [1.0]\n[release]\n").unwrap_err();
    assert_eq!(e.key, "initial.velocity", "{e}");
    // No pushes and no release: still an empty schedule.
    let e = load("[initial]\nomega = 1.0\n").unwrap_err();
    assert_eq!(e.key, "push", "{e}");
}
