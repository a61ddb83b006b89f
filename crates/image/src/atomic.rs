//! Files that are replaced whole or not at all.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Writes a file through `write`, atomically: the data goes to a temporary
/// file beside `path` (a fresh name from [`tempfile::NamedTempFile`], so
/// that writers in several threads or processes never share one), which is
/// synced and then renamed over `path` only once `write` has succeeded, so
/// a failure never leaves a partial file or destroys an earlier one. Of
/// writers racing to the same path, the last rename wins: the file is
/// always one of their complete contents.
///
/// A path that exists and is neither a regular file nor a folder (a FIFO,
/// `/dev/null`, `/dev/stdout`) is written directly: renaming a file over it
/// would replace the pipe or the device with a plain file.
pub fn write_atomically_with(path: &Path, write: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    if fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        let mut out = BufWriter::new(File::create(path)?);
        write(&mut out)?;
        return out.flush();
    }
    let folder = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    // Dropped on an error, the temporary file is removed.
    let mut out = BufWriter::new(temporary_file().tempfile_in(folder)?);
    write(&mut out)?;
    let temporary = out.into_inner().map_err(|e| e.into_error())?;
    temporary.as_file().sync_all()?;
    temporary.persist(path).map(drop).map_err(|e| e.error)
}

/// A builder of temporary files that get the permissions `File::create`
/// gives (0o666 less the umask, as a plain write would) instead of
/// tempfile's private 0o600: they become the output.
fn temporary_file() -> tempfile::Builder<'static, 'static> {
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    builder
}

/// Why the folder of `path` cannot take a new file, when it does not exist
/// or is not a folder ("…/dir does not exist"): checked before a long
/// render, so the message names the folder rather than the file.
pub fn unusable_folder(path: &Path) -> Option<String> {
    let folder = path.parent().filter(|folder| !folder.as_os_str().is_empty() && !folder.is_dir())?;
    let what = if folder.exists() { "is not a folder" } else { "does not exist" };
    Some(format!("{} {what}", folder.display()))
}

/// [`write_atomically_with`] for bytes already in memory.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomically_with(path, |out| out.write_all(bytes))
}

/// A name beside `path` for a probe of whether its folder is writable.
pub(crate) fn temporary_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.probe", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_no_temporary() {
        let temporary = tempfile::tempdir().unwrap();
        let dir = temporary.path();
        let path = dir.join("kept.txt");
        write_atomically(&path, b"old").unwrap();
        let failed = write_atomically_with(&path, |out| {
            out.write_all(b"half")?;
            Err(io::Error::other("encoder failed"))
        });
        assert!(failed.is_err());
        assert_eq!(fs::read(&path).unwrap(), b"old");
        let names: Vec<_> = fs::read_dir(dir).unwrap().map(|entry| entry.unwrap().file_name()).collect();
        assert!(names.iter().all(|name| !name.to_string_lossy().starts_with(".tmp")), "{names:?}");
        write_atomically(&path, b"new").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"new");
    }

    #[cfg(unix)]
    #[test]
    fn outputs_get_the_permissions_of_a_plain_write() {
        use std::os::unix::fs::PermissionsExt;
        let temporary = tempfile::tempdir().unwrap();
        let dir = temporary.path();
        let (atomic, plain) = (dir.join("atomic"), dir.join("plain"));
        write_atomically(&atomic, b"x").unwrap();
        fs::write(&plain, b"x").unwrap();
        let mode = |path: &Path| fs::metadata(path).unwrap().permissions().mode();
        assert_eq!(mode(&atomic), mode(&plain));
    }

    #[cfg(unix)]
    #[test]
    fn devices_are_written_in_place_not_replaced() {
        use std::os::unix::fs::FileTypeExt;
        write_atomically(Path::new("/dev/null"), b"nothing").unwrap();
        assert!(fs::metadata("/dev/null").unwrap().file_type().is_char_device());
    }

    #[test]
    fn writers_racing_to_one_path_all_succeed_and_one_complete_file_is_left() {
        let temporary = tempfile::tempdir().unwrap();
        let dir = temporary.path();
        let path = dir.join("raced.bin");
        let contents: Vec<Vec<u8>> = (0..2u8).map(|writer| vec![writer; 1 << 20]).collect();
        for _ in 0..10 {
            std::thread::scope(|scope| {
                let writers: Vec<_> =
                    contents.iter().map(|bytes| scope.spawn(|| write_atomically(&path, bytes))).collect();
                for writer in writers {
                    writer.join().unwrap().expect("every writer succeeds");
                }
            });
            let written = fs::read(&path).unwrap();
            assert!(contents.contains(&written), "a mix of the writers' contents");
        }
        assert_eq!(fs::read_dir(dir).unwrap().count(), 1, "temporary files left behind");
    }
}
