//! `pushval control-study`: plans and MPC in every engine.

use std::path::Path;
use std::process::ExitCode;

/// `pushval control-study`.
pub fn cli(
    _out: &Path,
    _quick: bool,
    _shard: Option<crate::shard::Shard>,
    _merge: bool,
    _only: Option<&str>,
) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not yet")
}
