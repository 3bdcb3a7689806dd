//! The files the workbench touches for a page: pose files it reads only from the directory `ringpod ui --files`
//! names (a file the user picks in the page comes as its text instead), and the live cueing file, in a directory
//! of its own that only this user can enter, replaced whole on every write.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The file `name` under `dir`, or why the page may not read it: no directory was named, or the name leads out of
/// it (an absolute path, `..`, a symbolic link that points elsewhere). The reason never holds the file's content.
pub fn under(dir: Option<&Path>, name: &str) -> Result<PathBuf, String> {
    let Some(dir) = dir else {
        return Err(format!(
            "{name}: the workbench reads no file by name: pick it in the page, or start `ringpod ui --files DIR` \
             to stream files under DIR"
        ));
    };
    let dir = dir
        .canonicalize()
        .map_err(|e| format!("--files {}: {e}", dir.display()))?;
    let outside = || {
        format!(
            "{name}: not a file under {} (the directory `ringpod ui --files` names)",
            dir.display()
        )
    };
    // A name that does not resolve is refused as one outside: whether a path exists elsewhere is not told.
    let path = dir.join(name).canonicalize().map_err(|_| outside())?;
    if path.starts_with(&dir) && path.is_file() {
        Ok(path)
    } else {
        Err(outside())
    }
}

/// The text of the file `name` under `dir` (at most `limit` bytes), or why the page may not read it, as
/// [`under`] says, naming the file. The name is checked, the file opened, and the name checked again against the file that was
/// opened: someone who can write in the directory and swaps a component for a link between the check and the
/// open gets the open file refused, whatever it is (the same file by a hard link is the same file).
pub fn read_under(dir: Option<&Path>, name: &str, limit: u64) -> Result<String, String> {
    // Every reason names the file once, as [`under`]'s do.
    let named = |reason: String| format!("{name}: {reason}");
    let path = under(dir, name)?;
    let file = crate::input::files::open(&path).map_err(named)?;
    still_under(&file, dir, name)?;
    crate::input::files::as_text(crate::input::files::read_open(file, limit).map_err(named)?).map_err(named)
}

/// Whether the open `file` is the one `name` under `dir` resolves to now.
fn still_under(file: &std::fs::File, dir: Option<&Path>, name: &str) -> Result<(), String> {
    let now = under(dir, name)?;
    let same = file
        .try_clone()
        .and_then(same_file::Handle::from_file)
        .and_then(|opened| Ok(opened == same_file::Handle::from_path(&now)?))
        .unwrap_or(false);
    if same {
        Ok(())
    } else {
        Err(format!("{name}: changed while it was opened: not read"))
    }
}

/// Why a pose file was refused, without what it holds: the table reader quotes a header it does not understand,
/// which for a file the page named could be any file's first line.
pub fn reason_without_content(reason: &str) -> &str {
    reason.split(", found `").next().unwrap_or(reason)
}

/// A directory only this user can enter (created 0700 on Unix, not changed after), removed when dropped.
pub fn private_dir() -> std::io::Result<tempfile::TempDir> {
    let mut builder = tempfile::Builder::new();
    builder.prefix("ringpod-ui-");
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o700));
    builder.tempdir()
}

/// Replaces `path` with `text` whole: written to a new file beside it, then renamed over it. A reader sees the old
/// file or the new one, never a part; a symbolic link planted at `path` is replaced, never followed.
pub fn write_whole(path: &Path, text: &str) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut file = tempfile::NamedTempFile::new_in(dir)?;
    file.write_all(text.as_bytes())?;
    file.as_file().sync_all()?;
    // An existing file keeps its mode (a temporary file is made 0600); a link's is not taken (never followed).
    if let Ok(m) = std::fs::symlink_metadata(path) {
        if m.is_file() {
            file.as_file().set_permissions(m.permissions())?;
        }
    }
    file.persist(path).map_err(|e| e.error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn a_file_written_whole_keeps_its_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = private_dir().unwrap();
        let path = dir.path().join("cueing.toml");
        std::fs::write(&path, "old").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644)).unwrap();
        write_whole(&path, "new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(std::fs::metadata(&path).unwrap().permissions().mode() & 0o777, 0o644);
    }

    #[cfg(unix)]
    #[test]
    fn only_files_under_the_named_directory_are_read() {
        let root = private_dir().unwrap();
        let dir = root.path().join("files");
        std::fs::create_dir(&dir).unwrap();
        std::fs::write(dir.join("poses.csv"), "t,x,y,z,alpha,beta,gamma\n").unwrap();
        std::fs::write(root.path().join("secret.txt"), "hunter2\n").unwrap();
        std::os::unix::fs::symlink(root.path().join("secret.txt"), dir.join("link.csv")).unwrap();
        let ok = under(Some(&dir), "poses.csv").unwrap();
        assert!(ok.ends_with("files/poses.csv"), "{}", ok.display());
        for name in ["../secret.txt", "/etc/passwd", "link.csv", "missing.csv", ".", ""] {
            let e = under(Some(&dir), name).unwrap_err();
            assert!(e.contains("not a file under"), "{name}: {e}");
        }
        assert!(under(None, "poses.csv").unwrap_err().contains("--files"));
    }

    /// A link swapped in after the name was checked and swapped back after the open: the open file is not the
    /// one the name leads to, and it is refused.
    #[cfg(unix)]
    #[test]
    fn a_file_swapped_between_the_check_and_the_open_is_refused() {
        let root = private_dir().unwrap();
        let dir = root.path().join("files");
        std::fs::create_dir(&dir).unwrap();
        std::fs::write(root.path().join("secret.txt"), "hunter2\n").unwrap();
        let name = dir.join("poses.csv");
        std::os::unix::fs::symlink(root.path().join("secret.txt"), &name).unwrap();
        let opened = std::fs::File::open(&name).unwrap();
        std::fs::remove_file(&name).unwrap();
        std::fs::write(&name, "t,x,y,z,alpha,beta,gamma\n").unwrap();
        let e = still_under(&opened, Some(&dir), "poses.csv").unwrap_err();
        assert!(e.contains("changed while it was opened"), "{e}");
        // Left alone, the file is read.
        let text = read_under(Some(&dir), "poses.csv", 1 << 20).unwrap();
        assert!(text.starts_with("t,x"), "{text}");
        assert!(read_under(Some(&dir), "../secret.txt", 1 << 20)
            .unwrap_err()
            .contains("not a file under"));
    }

    #[test]
    fn a_header_is_not_quoted_back() {
        let r = "line 1: the header must name the columns t,x (in any order), found `root:x:0:0`";
        assert_eq!(
            reason_without_content(r),
            "line 1: the header must name the columns t,x (in any order)"
        );
        assert_eq!(reason_without_content("no header line"), "no header line");
    }

    #[cfg(unix)]
    #[test]
    fn a_write_replaces_a_planted_link_and_leaves_its_target_alone() {
        use std::os::unix::fs::PermissionsExt;
        let dir = private_dir().unwrap();
        let mode = std::fs::metadata(dir.path()).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o700, "only this user enters");
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "keep").unwrap();
        let path = dir.path().join("cueing.toml");
        std::os::unix::fs::symlink(&victim, &path).unwrap();
        write_whole(&path, "a = 1\n").unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
        assert!(!std::fs::symlink_metadata(&path).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a = 1\n");
    }
}
