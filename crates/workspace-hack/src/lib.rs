//! No code: this crate only unifies dependency features between CI's default
//! and engine-feature builds (see its `Cargo.toml`).
