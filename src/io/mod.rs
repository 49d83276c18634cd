//! Reading and writing the files LIGGGHTS and LAMMPS read and write: text
//! dumps (plain or gzip), data files, VTK, and printf-style number formats.
pub mod cfmt;
pub mod data;
pub mod dump;
pub mod vtk;

use crate::error::{Error, Result};

/// Write a results file so that a reader (or a killed run) never sees it half
/// written: the bytes go to a temporary file in the same folder, which is then
/// renamed over `path`.
pub fn write_atomic(path: impl AsRef<std::path::Path>, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let path = path.as_ref();
    let fail = |e: std::io::Error| Error::usage(format!("cannot write {}: {e}", path.display()));
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(fail)?;
    tmp.write_all(bytes).map_err(fail)?;
    persist_public(tmp, path).map_err(fail)
}

/// Rename a finished temporary file to `path`. The temporary file is private
/// (0600); the result gets the usual mode, or keeps the one of the file it
/// replaces.
pub fn persist_public(tmp: tempfile::NamedTempFile, path: &std::path::Path) -> std::io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(path).map(|m| m.permissions()).unwrap_or_else(|_| std::fs::Permissions::from_mode(0o644));
        tmp.as_file().set_permissions(mode)?;
    }
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}
