//! The README and the book (`docs/book`) hold together: every relative link and image resolves to a file of the
//! repository, a link with `#anchor` names a heading of the Markdown file it points to, a link of the book stays
//! inside the book's `src/` (mdBook publishes nothing else), and `SUMMARY.md` lists every chapter file.
//!
//! The Markdown is parsed with `pulldown-cmark` (CommonMark with tables, as GitHub and mdBook read it), so a link in
//! a code block or a table cell is seen exactly as a reader sees it. A heading's anchor is its text, lower-cased,
//! with spaces as `-` and everything but letters, digits, `-` and `_` left out, and `-1`, `-2` added to repeats: the
//! rule mdBook and GitHub share for the headings this project writes.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Component, Path, PathBuf};

use pulldown_cmark::{Event, Options, Parser, Tag, TagEnd};

const README: &str = "README.md";
const BOOK_SRC: &str = "docs/book/src";
const SUMMARY: &str = "docs/book/src/SUMMARY.md";

/// Where the checks read files: the repository on disk, or a made-up tree in memory.
trait Files {
    /// The text of a file, `None` when there is none (or it is a folder).
    fn read(&self, path: &Path) -> Option<String>;
    /// Whether a file or folder is there.
    fn exists(&self, path: &Path) -> bool;
}

struct Disk(PathBuf);

impl Files for Disk {
    fn read(&self, path: &Path) -> Option<String> {
        std::fs::read_to_string(self.0.join(path)).ok()
    }

    fn exists(&self, path: &Path) -> bool {
        self.0.join(path).exists()
    }
}

/// A made-up tree: each path with its text (pictures with any text).
struct Memory(BTreeMap<PathBuf, String>);

impl Files for Memory {
    fn read(&self, path: &Path) -> Option<String> {
        self.0.get(path).cloned()
    }

    fn exists(&self, path: &Path) -> bool {
        self.0.keys().any(|p| p.starts_with(path))
    }
}

fn options() -> Options {
    Options::ENABLE_TABLES | Options::ENABLE_FOOTNOTES | Options::ENABLE_STRIKETHROUGH
}

/// A link or image of a Markdown file: its target as written and the line it is on.
struct Link {
    target: String,
    line: usize,
}

fn links(text: &str) -> Vec<Link> {
    let mut out = Vec::new();
    for (event, range) in Parser::new_ext(text, options()).into_offset_iter() {
        if let Event::Start(Tag::Link { dest_url, .. } | Tag::Image { dest_url, .. }) = event {
            let line = text[..range.start].matches('\n').count() + 1;
            out.push(Link {
                target: dest_url.to_string(),
                line,
            });
        }
    }
    out
}

/// The anchors of a Markdown file's headings, in order.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut heading: Option<String> = None;
    for event in Parser::new_ext(text, options()) {
        match event {
            Event::Start(Tag::Heading { .. }) => heading = Some(String::new()),
            Event::Text(t) | Event::Code(t) => {
                if let Some(h) = heading.as_mut() {
                    h.push_str(&t);
                }
            }
            Event::End(TagEnd::Heading(_)) => {
                let id = anchor(&heading.take().unwrap_or_default());
                let n = seen.entry(id.clone()).or_insert(0);
                out.insert(if *n == 0 { id.clone() } else { format!("{id}-{n}") });
                *n += 1;
            }
            _ => {}
        }
    }
    out
}

fn anchor(heading: &str) -> String {
    heading
        .trim()
        .chars()
        .filter_map(|c| match c {
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c.to_ascii_lowercase()),
            c if c.is_whitespace() => Some('-'),
            _ => None,
        })
        .collect()
}

/// `a/b/../c` as `a/c`, without asking the file system; `None` when it climbs out of the repository.
fn normalise(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::Normal(p) => out.push(p),
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(out)
}

fn is_external(target: &str) -> bool {
    target.contains("://") || target.starts_with("mailto:")
}

/// Every broken link of `file` (a path relative to the repository), one line each.
fn broken_links(files: &dyn Files, file: &Path) -> Vec<String> {
    let Some(text) = files.read(file) else {
        return vec![format!("{}: missing", file.display())];
    };
    let in_book = file.starts_with(BOOK_SRC);
    let mut out = Vec::new();
    for link in links(&text) {
        if is_external(&link.target) {
            continue;
        }
        let at = format!("{}:{}: `{}`", file.display(), link.line, link.target);
        let (path, fragment) = match link.target.split_once('#') {
            Some((p, f)) => (p, Some(f)),
            None => (link.target.as_str(), None),
        };
        let target = if path.is_empty() {
            Some(file.to_path_buf())
        } else {
            normalise(&file.parent().unwrap_or(Path::new("")).join(path))
        };
        let Some(target) = target else {
            out.push(format!("{at} leaves the repository"));
            continue;
        };
        if !files.exists(&target) {
            out.push(format!("{at}: no file {}", target.display()));
            continue;
        }
        if in_book && !target.starts_with(BOOK_SRC) {
            out.push(format!("{at}: outside the book's src/, which is all mdBook publishes"));
        }
        if let Some(fragment) = fragment {
            match files
                .read(&target)
                .filter(|_| target.extension().is_some_and(|e| e == "md"))
            {
                Some(t) if anchors(&t).contains(fragment) => {}
                Some(_) => out.push(format!("{at}: no heading #{fragment} in {}", target.display())),
                None => out.push(format!(
                    "{at}: an anchor into {}, which is not Markdown",
                    target.display()
                )),
            }
        }
    }
    out
}

/// The chapter files `SUMMARY.md` links to, relative to the repository.
fn summary_chapters(files: &dyn Files) -> BTreeSet<PathBuf> {
    let text = files.read(Path::new(SUMMARY)).unwrap_or_default();
    links(&text)
        .into_iter()
        .filter(|l| !is_external(&l.target))
        .filter_map(|l| normalise(&Path::new(BOOK_SRC).join(l.target.split('#').next().unwrap_or_default())))
        .collect()
}

/// The chapter files that `SUMMARY.md` leaves out, of `chapters` (every `.md` under the book's `src/`).
fn unlisted(files: &dyn Files, chapters: &BTreeSet<PathBuf>) -> Vec<String> {
    let listed = summary_chapters(files);
    chapters
        .iter()
        .filter(|c| c.as_path() != Path::new(SUMMARY) && !listed.contains(*c))
        .map(|c| format!("{} is not in {SUMMARY}", c.display()))
        .collect()
}

/// Every `.md` under `dir` (relative to `root`), sorted.
fn markdown_under(root: &Path, dir: &Path, out: &mut BTreeSet<PathBuf>) {
    for entry in std::fs::read_dir(root.join(dir)).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let name = entry.expect("a directory entry").file_name();
        let path = dir.join(name);
        if root.join(&path).is_dir() {
            markdown_under(root, &path, out);
        } else if path.extension().is_some_and(|e| e == "md") {
            out.insert(path);
        }
    }
}

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the repository")
        .to_path_buf()
}

fn book_chapters(root: &Path) -> BTreeSet<PathBuf> {
    let mut chapters = BTreeSet::new();
    markdown_under(root, Path::new(BOOK_SRC), &mut chapters);
    chapters
}

#[test]
fn every_link_and_image_of_the_readme_and_the_book_resolves() {
    let root = repository();
    let disk = Disk(root.clone());
    let mut files = book_chapters(&root);
    files.insert(PathBuf::from(README));
    let broken: Vec<String> = files.iter().flat_map(|f| broken_links(&disk, f)).collect();
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
    // The check reads what it should: the README's pictures and links into the book are among them.
    let readme = links(&disk.read(Path::new(README)).expect("the README"));
    assert!(
        readme.iter().any(|l| l.target.ends_with(".png")),
        "the README shows no picture"
    );
    assert!(
        readme.iter().any(|l| l.target.starts_with("docs/book/src/")),
        "the README links into no chapter"
    );
}

#[test]
fn the_summary_lists_every_chapter() {
    let root = repository();
    let chapters = book_chapters(&root);
    assert!(chapters.len() > 10, "the book has {} chapters", chapters.len());
    let missing = unlisted(&Disk(root), &chapters);
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

/// A made-up book in memory: the README, a summary, two chapters and a picture.
fn made_up(chapter: &str) -> Memory {
    let files = [
        (
            README,
            "# R\n\n![p](docs/book/src/images/p.png)\n[c](docs/book/src/a.md#first-part)\n",
        ),
        (SUMMARY, "# Summary\n\n- [A](a.md)\n- [B](b.md)\n"),
        (
            "docs/book/src/a.md",
            "# A\n\n## First part\n\n## Gram: `det G` and more\n\n## Twice\n\n## Twice\n",
        ),
        ("docs/book/src/b.md", chapter),
        ("docs/book/src/images/p.png", "png"),
        ("host/src/main.rs", "fn main() {}"),
    ];
    Memory(files.iter().map(|(p, t)| (PathBuf::from(p), t.to_string())).collect())
}

fn broken_in_b(chapter: &str) -> Vec<String> {
    broken_links(&made_up(chapter), Path::new("docs/book/src/b.md"))
}

#[test]
fn links_that_resolve_pass() {
    let book =
        made_up("# B\n\n[a](a.md) [g](a.md#gram-det-g-and-more) [t](a.md#twice-1) [me](#b) ![p](images/p.png)\n");
    assert_eq!(broken_links(&book, Path::new(README)), Vec::<String>::new());
    assert_eq!(
        broken_links(&book, Path::new("docs/book/src/b.md")),
        Vec::<String>::new()
    );
    // A link in a code block is no link.
    assert_eq!(broken_in_b("# B\n\n```\n[x](nothing.md)\n```\n"), Vec::<String>::new());
    assert_eq!(
        broken_in_b("# B\n\n[web](https://example.invalid/x.md)\n"),
        Vec::<String>::new()
    );
}

#[test]
fn a_missing_file_or_picture_is_named_with_its_line() {
    let broken = broken_in_b("# B\n\ntext\n[c](c.md)\n![q](images/q.png)\n");
    assert_eq!(broken.len(), 2, "{broken:?}");
    assert!(
        broken[0].starts_with("docs/book/src/b.md:4: `c.md`: no file"),
        "{broken:?}"
    );
    assert!(
        broken[1].starts_with("docs/book/src/b.md:5: `images/q.png`: no file"),
        "{broken:?}"
    );
    // In a table cell too.
    assert_eq!(broken_in_b("# B\n\n| a | b |\n|---|---|\n| [c](c.md) | x |\n").len(), 1);
}

#[test]
fn an_anchor_without_its_heading_is_broken() {
    let broken =
        broken_in_b("# B\n\n[a](a.md#second-part) [t](a.md#twice-2) [me](#nothing) [m](../../../host/src/main.rs#x)\n");
    // The last one is also outside the book's src/: two lines.
    assert_eq!(broken.len(), 5, "{broken:?}");
    assert!(
        broken[0].ends_with("no heading #second-part in docs/book/src/a.md"),
        "{broken:?}"
    );
    assert!(
        broken[1].ends_with("no heading #twice-2 in docs/book/src/a.md"),
        "{broken:?}"
    );
    assert!(
        broken[2].ends_with("no heading #nothing in docs/book/src/b.md"),
        "{broken:?}"
    );
    assert!(
        broken[4].ends_with("an anchor into host/src/main.rs, which is not Markdown"),
        "{broken:?}"
    );
}

#[test]
fn a_book_link_out_of_its_src_or_the_repository_is_broken() {
    let broken = broken_in_b("# B\n\n[main](../../../host/src/main.rs) [up](../../../../x.md)\n");
    assert_eq!(broken.len(), 2, "{broken:?}");
    assert!(
        broken[0].ends_with("outside the book's src/, which is all mdBook publishes"),
        "{broken:?}"
    );
    assert!(broken[1].ends_with("leaves the repository"), "{broken:?}");
}

#[test]
fn a_chapter_the_summary_leaves_out_is_named() {
    let book = made_up("# B\n");
    let mut chapters: BTreeSet<PathBuf> = book.0.keys().filter(|p| p.starts_with(BOOK_SRC)).cloned().collect();
    chapters.retain(|p| p.extension().is_some_and(|e| e == "md"));
    assert_eq!(unlisted(&book, &chapters), Vec::<String>::new());
    chapters.insert(PathBuf::from("docs/book/src/c.md"));
    assert_eq!(
        unlisted(&book, &chapters),
        vec![format!("docs/book/src/c.md is not in {SUMMARY}")]
    );
}

#[test]
fn anchors_follow_the_heading_text() {
    let ids = anchors("# Two commands\n\n## `--motion sine`: fixed-frequency\n\n# Two commands\n\n## A, B & C (x)\n");
    let want = [
        "--motion-sine-fixed-frequency",
        "a-b--c-x",
        "two-commands",
        "two-commands-1",
    ];
    assert_eq!(ids, want.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>());
    // Headings in code blocks are no headings.
    assert!(anchors("```sh\n# not a heading\n```\n").is_empty());
}
