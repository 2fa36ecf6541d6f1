//! Empty: the build script exists so that the build-dependencies (`cc`,
//! `libc`) take part in the host side's feature unification.
fn main() {}
