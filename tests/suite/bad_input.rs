//! Bad scenario files: each must be refused with a message that names the
//! key and the problem.

use std::path::Path;

use rstest::rstest;

/// A valid scenario; each case below replaces one line or appends one.
const GOOD: &str = r#"name = "t"
[object]
mass = 1.0
polygon = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]
[supports]
points = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]
mu = 0.5
load = "equal"
[contact]
point = [-0.125, -0.125]
[[push]]
duration = 1.0
speed = 0.5
phi = 0.8
"#;

fn edit(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "case does not apply: {from}");
    GOOD.replacen(from, to, 1)
}

#[test]
fn the_base_file_is_valid() {
    pushval::registry::from_toml(GOOD, Path::new("good.toml")).unwrap();
}

// Columns: the file text, the key the error must name, a fragment of its message.
#[rstest]
#[case::broken_toml(edit("mass = 1.0", "mass = = 1.0"), "object.mass", "")]
#[case::unknown_key(
    edit("mass = 1.0", "mass = 1.0\ncolour = 3"),
    "object.colour",
    "unknown field"
)]
#[case::unknown_table(format!("{GOOD}\n[extra]\na = 1\n"), "extra", "unknown field")]
#[case::wrong_type(edit("mass = 1.0", "mass = \"heavy\""), "object.mass", "invalid type")]
#[case::nan_mass(edit("mass = 1.0", "mass = nan"), "object.mass", "finite number > 0")]
#[case::inf_speed(edit("speed = 0.5", "speed = inf"), "push[0].speed", "finite")]
#[case::zero_mass(edit("mass = 1.0", "mass = 0.0"), "object.mass", "> 0")]
#[case::negative_mass(edit("mass = 1.0", "mass = -2.0"), "object.mass", "> 0")]
#[case::zero_mu(edit("mu = 0.5", "mu = 0.0"), "supports.mu", "> 0")]
#[case::negative_mu_list(
    edit("mu = 0.5", "mu = [0.5, 0.5, -0.1, 0.5]"),
    "supports.mu[2]",
    "> 0"
)]
#[case::mu_count(
    edit("mu = 0.5", "mu = [0.5, 0.5]"),
    "supports.mu",
    "2 values for 4 supports"
)]
#[case::degenerate_polygon(
    edit(
        "polygon = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]",
        "polygon = [[0,0],[1,0],[2,0]]"
    ),
    "object.polygon",
    "degenerate"
)]
#[case::two_vertices(
    edit(
        "polygon = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]",
        "polygon = [[0,0],[1,0]]"
    ),
    "object.polygon",
    "at least 3"
)]
#[case::self_intersecting(
    edit(
        "polygon = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]",
        "polygon = [[-0.125,-0.125],[0.125,0.125],[0.125,-0.125],[-0.125,0.125]]"
    ),
    "object.polygon",
    "self-intersecting"
)]
#[case::clockwise(
    edit(
        "polygon = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]",
        "polygon = [[-0.125,0.125],[0.125,0.125],[0.125,-0.125],[-0.125,-0.125]]"
    ),
    "object.polygon",
    "clockwise"
)]
#[case::contact_off_boundary(
    edit("point = [-0.125, -0.125]", "point = [0.0, 0.0]"),
    "contact.point",
    "not on the polygon's boundary"
)]
#[case::support_outside(
    edit(
        "points = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]",
        "points = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.3,0.125]]"
    ),
    "supports.points[3]",
    "outside the object"
)]
#[case::one_support_off_the_cm(
    GOOD.replace("points = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]", "points = [[0.05,0.0]]"),
    "supports",
    "would tip"
)]
#[case::tipping(edit("mass = 1.0", "mass = 1.0\ncenter_of_mass = [0.1, 0.1]").replace("points = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]", "points = [[-0.125,-0.125],[0.0,-0.125],[-0.125,0.0]]"), "supports", "would tip")]
#[case::loads_sum(
    edit("load = \"equal\"", "load = [1.0, 1.0, 1.0, 1.0]"),
    "supports.load",
    "sum to 4 N"
)]
#[case::load_rule(
    edit("load = \"equal\"", "load = \"magic\""),
    "supports.load",
    "unknown rule"
)]
#[case::uniform_without_grid(
    edit("load = \"equal\"", "load = \"uniform\""),
    "supports.load",
    "needs supports.uniform_grid"
)]
#[case::empty_schedule(GOOD.split("[[push]]").next().unwrap().to_string(), "push", "schedule is empty")]
#[case::zero_duration(edit("duration = 1.0", "duration = 0.0"), "push[0].duration", "> 0")]
#[case::negative_duration(edit("duration = 1.0", "duration = -1.0"), "push[0].duration", "> 0")]
#[case::negative_speed(edit("speed = 0.5", "speed = -0.5"), "push[0].speed", ">= 0")]
#[case::unknown_model(format!("{GOOD}[run]\nmodels = [\"dynamic\", \"bullet\"]\n"), "run.models[1]", "unknown model \"bullet\"")]
#[case::unknown_switching(format!("{GOOD}[run]\nswitching = \"sometimes\"\n"), "run.switching", "unknown value")]
#[case::zero_sample_dt(format!("{GOOD}[run]\nsample_dt = 0.0\n"), "run.sample_dt", "> 0")]
#[case::both_supports(
    edit("mu = 0.5", "mu = 0.5\nuniform_grid = 0.01"),
    "supports.uniform_grid",
    "not both"
)]
#[case::no_supports(
    edit(
        "points = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]",
        ""
    ),
    "supports",
    "needs points or uniform_grid"
)]
#[case::grid_too_fine(
    edit(
        "points = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]",
        "uniform_grid = 0.00001"
    ),
    "supports.uniform_grid",
    "the limit is 2e6"
)]
#[case::inertia_too_small(
    edit("mass = 1.0", "mass = 1.0\ninertia_contact = 0.01"),
    "object.inertia_contact",
    "no body has that inertia"
)]
#[case::both_inertias(
    edit("mass = 1.0", "mass = 1.0\ninertia_contact = 0.2\ninertia_cm = 0.01"),
    "object.inertia_contact",
    "not both"
)]
#[case::negative_gravity(
    edit("mu = 0.5", "mu = 0.5\ngravity = -9.81"),
    "supports.gravity",
    "> 0"
)]
#[case::contact_mu(
    edit("point = [-0.125, -0.125]", "point = [-0.125, -0.125]\nmu = -1"),
    "contact.mu",
    "> 0"
)]
#[case::cm_outside(
    edit("mass = 1.0", "mass = 1.0\ncenter_of_mass = [2.0, 0.0]"),
    "object.center_of_mass",
    "outside the polygon"
)]
#[case::missing_mass(edit("mass = 1.0", ""), "object.mass", "missing field")]
#[case::bad_precision(format!("{GOOD}[engine]\nprecision = \"f16\"\n"), "engine.precision", "unknown value")]
#[case::zero_engine_dt(format!("{GOOD}[engine]\ndt = 0.0\n"), "engine.dt", "> 0")]
#[case::nan_phi(edit("phi = 0.8", "phi = nan"), "push[0].phi", "finite")]
#[case::tolerance_negative(format!("{GOOD}[tolerance]\nposition_max = -1.0\n"), "tolerance.position_max", "> 0")]
fn bad_input_is_refused_with_key_and_reason(
    #[case] text: String,
    #[case] key: &str,
    #[case] fragment: &str,
) {
    let e =
        pushval::registry::from_toml(&text, Path::new("bad.toml")).expect_err("must be refused");
    let msg = e.to_string();
    assert!(msg.starts_with("bad.toml: "), "{msg}");
    assert_eq!(e.key, key, "{msg}");
    assert!(e.message.contains(fragment), "{msg}");
}
