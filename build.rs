//! Embeds what pushval ships (the scenarios, the study files and the
//! protocol's JSON schemas) into the binary: `OUT_DIR/shipped.rs` lists each
//! file's name and its text (`include_str!`), so no path of the build tree is
//! read at run time (`src/shipped.rs`).
//!
//! With the `mujoco` feature, writes the folder of libmujoco.so
//! (`MUJOCO_DYNAMIC_LINK_DIR`, set by `eval "$(scripts/setup-mujoco.sh)"`)
//! into the rpath of the `pushval` binary and this package's tests and
//! benches, so that they run without `LD_LIBRARY_PATH`.

use std::path::Path;

/// `(name, include_str!(path))` rows for every file of `dir` ending in `ext`,
/// sorted by name.
fn rows(dir: &str, ext: &str) -> String {
    println!("cargo::rerun-if-changed={dir}");
    let root = Path::new(&std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo")).join(dir);
    let mut files: Vec<_> = std::fs::read_dir(&root)
        .unwrap_or_else(|e| panic!("{}: {e}", root.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.to_string_lossy().ends_with(ext))
        .collect();
    files.sort();
    let mut out = String::from("&[\n");
    for f in files {
        println!("cargo::rerun-if-changed={}", f.display());
        let name = f
            .file_name()
            .expect("a file")
            .to_string_lossy()
            .into_owned();
        out.push_str(&format!(
            "    ({name:?}, include_str!({:?})),\n",
            f.display().to_string()
        ));
    }
    out.push(']');
    out
}

fn main() {
    let out = Path::new(&std::env::var("OUT_DIR").expect("set by cargo")).join("shipped.rs");
    let text = format!(
        "/// The shipped scenarios (`scenarios/*.toml`): file name and text.\n\
         pub const SCENARIOS: &[(&str, &str)] = {};\n\
         /// The shipped study files (`studies/*.toml`): file name and text.\n\
         pub const STUDIES: &[(&str, &str)] = {};\n\
         /// The protocol's JSON schemas (`adapters/*.schema.json`): file name and text.\n\
         pub const SCHEMAS: &[(&str, &str)] = {};\n",
        rows("scenarios", ".toml"),
        rows("studies", ".toml"),
        rows("adapters", ".schema.json"),
    );
    std::fs::write(&out, text).unwrap_or_else(|e| panic!("{}: {e}", out.display()));
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    let feature = std::env::var_os("CARGO_FEATURE_MUJOCO").is_some();
    let unix_elf = matches!(
        std::env::var("CARGO_CFG_TARGET_OS").as_deref(),
        Ok("linux") | Ok("freebsd")
    );
    if feature && unix_elf {
        if let Ok(dir) = std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
            println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
        }
    }
}
