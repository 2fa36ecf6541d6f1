//! With the `mujoco` feature, writes the folder of libmujoco.so
//! (`MUJOCO_DYNAMIC_LINK_DIR`, set by `eval "$(scripts/setup-mujoco.sh)"`)
//! into the rpath of the `pushval` binary and this package's tests and
//! benches, so that they run without `LD_LIBRARY_PATH`.

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
