//! The one way pushval writes a file: through a temporary file in the same
//! folder and a rename, so a reader never sees a half-written file.
//!
//! The file gets the mode any program's newly created file gets,
//! `0o666 & !umask` (0644 under the usual umask 022, 0664 under 002), so
//! results are readable by the group and others as the user's umask allows.
//! `tempfile` alone would leave them 0600: its temporary files are private
//! by default, and the rename keeps the temporary's mode. Here the temporary
//! file is created with the requested mode 0666, which the kernel masks by
//! the umask at creation (no umask is read or changed, so nothing races
//! with other threads).

use std::io::Write;
use std::path::Path;

use anyhow::Context;

/// The mode requested for every written file before the umask applies.
#[cfg(unix)]
pub const CREATE_MODE: u32 = 0o666;

/// Writes `bytes` to `path` through a temporary file in the same folder and a
/// rename, so a reader never sees a half-written file. The file's mode is
/// [`CREATE_MODE`] masked by the umask (Unix).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(CREATE_MODE));
    }
    let mut tmp = builder
        .tempfile_in(dir)
        .with_context(|| format!("creating a temporary file in {}", dir.display()))?;
    tmp.write_all(bytes)
        .with_context(|| format!("writing {}", path.display()))?;
    tmp.persist(path)
        .with_context(|| format!("renaming into {}", path.display()))?;
    Ok(())
}
