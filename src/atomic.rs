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

/// An output folder written whole: files go into a fresh temporary folder
/// beside `dest`, and [`FreshDir::commit`] renames it into place (the folder
/// that was there before is removed). A command that fails before it
/// commits leaves no half-written folder and no stale result from an
/// earlier run under `dest` (dropping an uncommitted `FreshDir` removes
/// its temporary folder).
pub struct FreshDir {
    tmp: Option<tempfile::TempDir>,
    dest: std::path::PathBuf,
}

impl FreshDir {
    /// A fresh, empty folder that will become `dest`.
    pub fn new(dest: &Path) -> anyhow::Result<Self> {
        let parent = dest
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
        let name = dest
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".into());
        let tmp = tempfile::Builder::new()
            .prefix(&format!(".{name}.partial-"))
            .tempdir_in(parent)
            .with_context(|| format!("creating a temporary folder in {}", parent.display()))?;
        Ok(Self {
            tmp: Some(tmp),
            dest: dest.to_path_buf(),
        })
    }

    /// Where the files go until the commit.
    pub fn path(&self) -> &Path {
        self.tmp.as_ref().expect("not committed").path()
    }

    /// Writes `name` into the folder (atomically, like every file).
    pub fn write(&self, name: &str, bytes: &[u8]) -> anyhow::Result<()> {
        write_atomic(&self.path().join(name), bytes)
    }

    /// Renames the folder into place, replacing what `dest` held.
    pub fn commit(mut self) -> anyhow::Result<()> {
        let tmp = self.tmp.take().expect("committed once").keep();
        #[cfg(unix)]
        {
            // TempDir makes its folder private (0700); an output folder is
            // readable like the files in it (0755, the usual umask's).
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&tmp, std::fs::Permissions::from_mode(0o755))
                .with_context(|| format!("setting the mode of {}", tmp.display()))?;
        }
        if self.dest.exists() {
            let old = tmp.with_extension("old");
            std::fs::rename(&self.dest, &old)
                .with_context(|| format!("moving the old {} aside", self.dest.display()))?;
            std::fs::rename(&tmp, &self.dest)
                .with_context(|| format!("renaming into {}", self.dest.display()))?;
            if old.is_dir() {
                std::fs::remove_dir_all(&old)
                    .with_context(|| format!("removing {}", old.display()))?;
            } else {
                std::fs::remove_file(&old)
                    .with_context(|| format!("removing {}", old.display()))?;
            }
        } else {
            std::fs::rename(&tmp, &self.dest)
                .with_context(|| format!("renaming into {}", self.dest.display()))?;
        }
        Ok(())
    }
}
