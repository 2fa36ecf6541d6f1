//! The protocol's reading side: `pushval.toml`, the CSV rows and their
//! coverage, with errors naming the file and key, or the line and column.

use std::path::Path;

use pushval_outside::{csv, history_from_rows, Config};
use pushval_scenario::Scenario;

fn cfg(text: &str) -> Result<Config, String> {
    Config::from_toml(text, Path::new("/proj/pushval.toml")).map_err(|e| e.to_string())
}

#[test]
fn pushval_toml_defaults_and_folder() {
    let c = cfg("[engine.mysim]\ncommand = [\"python3\", \"a.py\"]\n").unwrap();
    let s = &c.engines[0];
    assert_eq!((s.order, s.dt, s.timeout_s), (1.0, 1e-3, 120.0));
    assert_eq!(s.dir, Path::new("/proj"));
    assert_eq!(s.version, None);
    let c = cfg("[engine.b]\ncommand = [\"./sim\"]\norder = 2\ndt = 5e-4\ntimeout_s = 3\nversion = \"b 1.0\"\n").unwrap();
    let s = &c.engines[0];
    assert_eq!((s.order, s.dt, s.timeout_s), (2.0, 5e-4, 3.0));
    assert_eq!(s.program(), Path::new("/proj/./sim"));
}

#[test]
fn pushval_toml_errors_name_file_and_key() {
    for (text, key) in [
        (
            "[engine.a]\ncommand = [\"x\"]\nshell = true\n",
            "engine.a.shell",
        ),
        ("[engine.a]\norder = 1\n", "engine.a.command"),
        (
            "[engine.a]\ncommand = \"python3 a.py\"\n",
            "engine.a.command",
        ),
        ("[engine.a]\ncommand = []\n", "engine.a.command"),
        ("[engine.a]\ncommand = [\"x\"]\ndt = -1\n", "engine.a.dt"),
        (
            "[engine.a]\ncommand = [\"x\"]\ntimeout_s = \"long\"\n",
            "engine.a.timeout_s",
        ),
        ("[engine.\"a b\"]\ncommand = [\"x\"]\n", "engine.a b"),
        ("[models]\nx = 1\n", "models"),
    ] {
        let e = cfg(text).unwrap_err();
        assert!(
            e.starts_with("/proj/pushval.toml: ") && e.contains(&format!("{key}:")),
            "{e}"
        );
    }
}

#[test]
fn malformed_rows_name_line_and_column() {
    let e = csv::read("t,x,y,theta,omega\n0,0,0,0,0\n0.1,abc,0,0,0\n", 0).unwrap_err();
    assert_eq!(e.to_string(), "line 3: column `x`: `abc` is not a number");
    let e = csv::read("t,x,theta,omega\n0,0,0,0\n", 0).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("line 1: the header lacks the column `y`"),
        "{e}"
    );
    // Without `omega`: ω from θ (θ = t², ω = 2t exactly).
    let r = csv::read("t,x,y,theta\n0,0,0,0\n1,0,0,1\n2,0,0,4\n", 0).unwrap();
    let w: Vec<f64> = r.iter().map(|r| r.numbers[4]).collect();
    assert_eq!(w, vec![0.0, 2.0, 4.0]);
    let e = csv::read("t,x,y,theta,omega\n0,0,0,0\n", 0).unwrap_err();
    assert_eq!(e.to_string(), "line 2: 4 fields, the header has 5");
    let e = csv::read("t,x,y,theta,omega\n0,0,0,inf,0\n", 0).unwrap_err();
    assert_eq!(e.to_string(), "line 2: column `theta`: inf is not finite");
    // Extra columns and their order do not matter.
    let r = csv::read("omega,t,extra,x,y,theta\n4,0,z,1,2,3\n", 0).unwrap();
    assert_eq!(r[0].numbers, [0.0, 1.0, 2.0, 3.0, 4.0]);
}

/// Rows per step: the segment of each step is the one holding its middle,
/// and the rows must run from 0 to the end, increasing.
#[test]
fn rows_become_steps_covering_the_run() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let sc = Scenario::from_path(root.join("scenarios/paper-square-v1.0.toml")).unwrap();
    let p = sc.problem();
    let rows_text = |ts: &[f64]| {
        let mut s = String::from("t,x,y,theta,omega\n");
        for t in ts {
            s.push_str(&format!("{t},{t},0,0,1\n"));
        }
        s
    };
    let ts: Vec<f64> = (0..=1000).map(|k| k as f64 * 0.01).collect();
    let text = rows_text(&ts);
    let rows = csv::read(&text, 0).unwrap();
    let h = history_from_rows(&p, &rows).unwrap();
    assert_eq!(h.len(), 1001);
    assert_eq!(h[200].segment, 0); // the step (1.99, 2.00]
    assert_eq!(h[201].segment, 1); // the step (2.00, 2.01]
    assert_eq!(h[1000].segment, 4);
    // Short of the end.
    let text = rows_text(&ts[..900]);
    let e = history_from_rows(&p, &csv::read(&text, 0).unwrap()).unwrap_err();
    assert!(
        e.contains("line 901") && e.contains("before the end"),
        "{e}"
    );
    // Not from 0, or not increasing.
    let text = rows_text(&ts[1..]);
    let e = history_from_rows(&p, &csv::read(&text, 0).unwrap()).unwrap_err();
    assert!(e.contains("line 2") && e.contains("not at 0"), "{e}");
    let mut back = ts.clone();
    back[5] = 0.02;
    let text = rows_text(&back);
    let e = history_from_rows(&p, &csv::read(&text, 0).unwrap()).unwrap_err();
    assert!(e.contains("line 7: column `t`"), "{e}");
}

/// Compact lines (protocol 3): little-endian binary64 in hexadecimal, 16
/// digits a number, whole rows. 1.5 is 0x3FF8000000000000, so its digits
/// little-endian are `000000000000f83f`; 0.0 is sixteen zeros.
#[test]
fn compact_rows_decode_exactly_and_name_what_is_wrong() {
    let zero = "0000000000000000";
    let one_and_half = "000000000000f83f";
    let columns = csv::Columns::of("t, x,y,theta,omega,steps", 1).unwrap();
    let line = format!("{zero}{one_and_half}{zero}{zero}{zero}{one_and_half}");
    let rows = csv::read_compact(&line, &columns, 7).unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0].numbers, [0.0, 1.5, 0.0, 0.0, 0.0]);
    assert_eq!((rows[0].steps, rows[0].line), (Some(1.5), 7));
    // NaN (0x7FF8000000000000) in `theta`.
    let nan = "000000000000f87f";
    let bad = format!("{zero}{zero}{zero}{nan}{zero}{zero}");
    let e = csv::read_compact(&bad, &columns, 3).unwrap_err();
    assert!(
        e.contains("line 3, row 1 of the compact line: column `theta`: NaN is not finite"),
        "{e}"
    );
    let e = csv::read_compact(&line[..line.len() - 16], &columns, 2).unwrap_err();
    assert!(e.contains("is not whole rows of 6 numbers"), "{e}");
    let e = csv::read_compact(&line.replace('f', "g"), &columns, 2).unwrap_err();
    assert!(e.contains("not hexadecimal"), "{e}");
    let e = csv::Columns::of("t,x,y,theta", 1).unwrap_err();
    assert!(e.contains("lacks the column `omega`"), "{e}");
}
