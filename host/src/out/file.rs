//! Files a command writes, whole or not at all: written to a temporary file beside the target and renamed over it
//! when complete (`tempfile`'s `NamedTempFile::persist`, a rename on the same file system), so that a full disk, an
//! error or a stop half-way leaves the target as it was (or absent), never a partial file under its name. A file
//! that is one of the command's inputs, or whose folder does not exist, is refused before anything runs. A link is
//! written through to its file; what is not a regular file (a device, a FIFO, a folder) is refused by name, never
//! replaced; a file written over keeps its permissions.

use std::io::Write;
use std::path::{Path, PathBuf};

/// A file being written: a temporary file in the target's folder, renamed to the target by [`Pending::commit`];
/// dropped without it, it is removed and the target is untouched.
pub struct Pending {
    temp: tempfile::NamedTempFile,
    target: PathBuf,
}

/// The folder a file is written in (the current one for a bare name).
fn folder(target: &Path) -> &Path {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// tempfile's error names the hidden temporary file (`... at path "/x/.out.json.XWGYjr.json"`), which the user
/// never asked for: the system's own message before it (the caller names the target).
fn without_temporary_name(e: std::io::Error) -> std::io::Error {
    let said = e.to_string();
    let own = said.split(" at path ").next().unwrap_or(&said).to_owned();
    std::io::Error::new(e.kind(), own)
}

impl Pending {
    /// Opens a temporary file beside `target` (named after it, with its extension: some writers choose the
    /// format by the extension).
    pub fn beside(target: &Path) -> std::io::Result<Self> {
        let resolved = through_link(target);
        let target = resolved.as_path();
        not_special(target)?;
        let name = target
            .file_name()
            .map_or("out".into(), |n| n.to_string_lossy().into_owned());
        let suffix = target
            .extension()
            .map_or(String::new(), |e| format!(".{}", e.to_string_lossy()));
        let temp = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(&suffix)
            .tempfile_in(folder(target))
            .map_err(without_temporary_name)?;
        Ok(Self {
            temp,
            target: target.to_path_buf(),
        })
    }

    /// The open temporary file.
    pub fn file(&mut self) -> &mut std::fs::File {
        self.temp.as_file_mut()
    }

    /// Flushes the file to the disk and renames it to the target, with the target's permissions (a new file's:
    /// read by all, written by its owner).
    pub fn commit(self) -> std::io::Result<()> {
        self.temp.as_file().sync_all()?;
        match std::fs::metadata(&self.target) {
            Ok(m) => self.temp.as_file().set_permissions(m.permissions())?,
            #[cfg(unix)]
            Err(_) => {
                use std::os::unix::fs::PermissionsExt;
                self.temp
                    .as_file()
                    .set_permissions(std::fs::Permissions::from_mode(0o644))?;
            }
            #[cfg(not(unix))]
            Err(_) => {}
        }
        self.temp.persist(&self.target).map_err(|e| e.error)?;
        Ok(())
    }
}

/// The file a link points to (a link's chain followed), or `target` itself.
fn through_link(target: &Path) -> PathBuf {
    match std::fs::symlink_metadata(target) {
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(target).unwrap_or_else(|_| target.to_path_buf()),
        _ => target.to_path_buf(),
    }
}

/// Refuses a target that exists and is not a regular file: renamed over, a device or a FIFO would be replaced.
fn not_special(target: &Path) -> std::io::Result<()> {
    match std::fs::metadata(target) {
        Ok(m) if !m.is_file() => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a device, a FIFO or a folder): name a file to write",
        )),
        _ => Ok(()),
    }
}

/// Writes `bytes` to `target` whole, or leaves it as it was.
pub fn write(target: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut pending = Pending::beside(target)?;
    pending.file().write_all(bytes)?;
    pending.commit()
}

/// Whether `output` is the same file as `input` (by the file's identity where both exist: a hard link or another
/// spelling of the path is the same file; by the canonical path otherwise).
pub fn same_file(output: &Path, input: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(a), Ok(b)) = (std::fs::metadata(output), std::fs::metadata(input)) {
            return a.dev() == b.dev() && a.ino() == b.ino();
        }
    }
    match (output.canonicalize(), input.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Refuses, before anything runs, an output that cannot be written where it is named (its folder is not a
/// folder: found only at the end of a long run, it would lose the run) or that is one of the inputs (writing it
/// would destroy what is being read).
pub fn check_output(output: &Path, inputs: &[&Path]) -> Result<(), String> {
    // The metadata of a link is its file's: a link to a device is refused as the device is.
    not_special(output).map_err(|e| format!("{}: {e}", output.display()))?;
    let dir = folder(output);
    if !dir.is_dir() {
        return Err(format!("{} is not a folder to write in", dir.display()));
    }
    match inputs.iter().find(|i| same_file(output, i)) {
        Some(i) => Err(format!(
            "{} is also an input ({}): writing it would destroy what is read; name another file",
            output.display(),
            i.display()
        )),
        None => Ok(()),
    }
}

/// [`check_output`] for each of a command's outputs, and no two of them one file (both reported written, one
/// would be lost).
pub fn check_outputs<'a>(outputs: &[&'a Path], inputs: &[&Path]) -> Result<(), (&'a Path, String)> {
    for (k, out) in outputs.iter().enumerate() {
        check_output(out, inputs).map_err(|e| (*out, e))?;
        if let Some(other) = outputs[..k].iter().find(|o| *o == out || same_file(out, o)) {
            return Err((
                *out,
                format!(
                    "{} is also another output ({}): one would replace the other; name two files",
                    out.display(),
                    other.display()
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device, a FIFO or a folder is refused by name and left as it is; a link is written through to its file,
    /// and stays a link; a file written over keeps its permissions, a new one is read by all.
    #[test]
    #[cfg(unix)]
    fn what_is_not_a_regular_file_is_refused_and_a_file_keeps_its_permissions() {
        use std::os::unix::fs::{FileTypeExt, PermissionsExt};
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("fifo");
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        for special in [Path::new("/dev/null"), fifo.as_path(), dir.path()] {
            assert!(check_output(special, &[]).is_err(), "{}", special.display());
            assert!(write(special, b"x").is_err(), "{}", special.display());
        }
        assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
        let file = dir.path().join("run.csv");
        std::fs::write(&file, "old").unwrap();
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        write(&link, b"through").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "through");
        for mode in [0o644, 0o600, 0o664] {
            std::fs::set_permissions(&file, std::fs::Permissions::from_mode(mode)).unwrap();
            write(&file, b"again").unwrap();
            assert_eq!(std::fs::metadata(&file).unwrap().permissions().mode() & 0o777, mode);
        }
        let new = dir.path().join("new.csv");
        write(&new, b"new").unwrap();
        assert_eq!(std::fs::metadata(&new).unwrap().permissions().mode() & 0o777, 0o644);
    }

    #[test]
    fn two_outputs_on_one_path_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
        assert!(check_outputs(&[&a, &b], &[]).is_ok());
        let (out, said) = check_outputs(&[&a, &b, &a], &[]).unwrap_err();
        assert_eq!(out, a.as_path());
        assert!(said.contains("also another output"), "{said}");
        // Another spelling of the same file, once it exists.
        std::fs::write(&a, "x").unwrap();
        let spelled = dir.path().join(".").join("a.csv");
        assert!(check_outputs(&[&a, &spelled], &[]).is_err());
    }

    #[test]
    fn a_write_replaces_the_target_whole_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("x.txt");
        std::fs::write(&target, "old").unwrap();
        write(&target, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        let pending = Pending::beside(&target).unwrap();
        drop(pending);
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "an abandoned write leaves nothing"
        );
        assert_eq!(
            std::fs::read_to_string(&target).unwrap(),
            "new",
            "and the target as it was"
        );
    }

    #[test]
    fn the_same_file_is_found_under_another_name() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        std::fs::write(&a, "x").unwrap();
        let spelled = dir.path().join(".").join("a.csv");
        assert!(check_output(&spelled, &[&a]).is_err());
        // A file's identity (device and inode) is known on Unix only: elsewhere a hard link is another name.
        #[cfg(unix)]
        {
            let linked = dir.path().join("b.csv");
            std::fs::hard_link(&a, &linked).unwrap();
            assert!(same_file(&linked, &a), "a hard link is the same file");
        }
        assert!(
            check_output(&dir.path().join("c.csv"), &[&a]).is_ok(),
            "a new file is no input"
        );
    }

    #[test]
    fn an_output_in_no_folder_is_refused_before_anything_runs_and_a_write_there_names_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let nowhere = dir.path().join("missing").join("out.json");
        let said = check_output(&nowhere, &[]).unwrap_err();
        assert!(said.contains("missing") && said.contains("not a folder"), "{said}");
        // A file where the folder should be is no folder either.
        let file = dir.path().join("file");
        std::fs::write(&file, "x").unwrap();
        assert!(check_output(&file.join("out.json"), &[]).is_err());
        assert!(check_output(&dir.path().join("out.json"), &[]).is_ok());
        assert!(
            check_output(Path::new("bare-name.json"), &[]).is_ok(),
            "the current folder"
        );
        let e = write(&nowhere, b"x").unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::NotFound);
        assert!(!e.to_string().contains(".out.json."), "{e}");
        assert!(e.to_string().contains("(os error"), "the system's own message: {e}");
    }
}
