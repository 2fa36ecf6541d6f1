//! With the `mujoco` feature, writes the folder of libmujoco.so
//! (`MUJOCO_DYNAMIC_LINK_DIR`, see scripts/setup-mujoco.sh) into the rpath of
//! this package's tests, examples and benches, so that they run without
//! `LD_LIBRARY_PATH`. (`rustc-link-arg` reaches this package's own linked
//! targets only; binaries of other packages need `LD_LIBRARY_PATH`.)

fn main() {
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
