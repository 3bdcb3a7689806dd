//! The layout rules, kept true for every source tree: the core (`shared/src`), the host (`host/src`), the firmware
//! (`firmware/src`), the test runners (`tests/src`) and the QEMU programs (`tests/qemu/src`): no file over 500 lines
//! outside its tests, no function over 100 lines outside tests, and no import cycle between the files of one module
//! folder: between the top-level modules of a crate (a file or folder directly under `src/`), and between the sibling
//! files and folders of every folder below (`analysis/branches.rs` and `analysis/kinematics.rs` importing each other
//! is a cycle of `analysis`). A module that imports its parent or its child makes no cycle: it is not a sibling.
//!
//! The sources are parsed with `syn` (line numbers from proc-macro2's `span-locations`), so braces in strings and
//! comments cannot fool a count. Test code counts nowhere: items under `#[cfg(test)]` (the `mod tests` at the end of
//! a file), `#[test]` functions, and files named `tests.rs` or under a `tests/` folder.
//!
//! An import is any path that starts with `crate::`, `super::` or `self::`, in a `use`, in code or inside a macro's
//! arguments, resolved to the file it lands in; `m::X` where module `m` re-exports `X` (`pub use x::X;`) lands in the
//! file it is re-exported from. A crate root (`lib.rs`, `main.rs`) declares its modules and is no node of a cycle.
//! Each binary under `src/bin/` (`bin/x.rs`, or `bin/x/main.rs` with its modules beside it) is a crate of its own, as
//! cargo builds it: its `crate::` is its own root.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::Path;

use proc_macro2::{Span, TokenStream, TokenTree};
use syn::spanned::Spanned;
use syn::visit::{self, Visit};
use syn::{Attribute, ImplItemFn, Item, ItemFn, ItemMod, ItemUse, Signature, TraitItemFn, UseTree};

const MAX_FILE_LINES: usize = 500;
const MAX_FN_LINES: usize = 100;
const TREES: [&str; 5] = ["shared/src", "host/src", "firmware/src", "tests/src", "tests/qemu/src"];

/// A source file: its path under `src/` (with `/`) and its text.
struct Source {
    path: String,
    text: String,
}

impl Source {
    fn new(path: &str, text: &str) -> Self {
        Self {
            path: path.into(),
            text: text.into(),
        }
    }
}

/// Every `.rs` file under `dir`, sorted, with its path relative to `root`.
fn read_tree(root: &Path, dir: &Path, out: &mut Vec<Source>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("a directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            read_tree(root, &path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let rel = path
                .strip_prefix(root)
                .expect("under the root")
                .to_string_lossy()
                .replace('\\', "/");
            out.push(Source { path: rel, text });
        }
    }
}

fn is_test_file(path: &str) -> bool {
    let mut parts: Vec<&str> = path.split('/').collect();
    let file = parts.pop().unwrap_or_default();
    file == "tests.rs" || parts.contains(&"tests")
}

/// `#[cfg(test)]` (also inside `all(...)`), or `#[test]` and the like (`#[tokio::test]`).
fn is_test(attrs: &[Attribute]) -> bool {
    attrs.iter().any(|a| {
        let path = a.path();
        if path.is_ident("cfg") {
            let cfg: String = a.meta.require_list().map(|l| l.tokens.to_string()).unwrap_or_default();
            let cfg = cfg.replace(' ', "");
            cfg == "test" || (cfg.starts_with("all(") && cfg[4..cfg.len() - 1].split(',').any(|c| c == "test"))
        } else {
            path.segments.last().is_some_and(|s| s.ident == "test")
        }
    })
}

fn item_attrs(item: &Item) -> &[Attribute] {
    match item {
        Item::Const(i) => &i.attrs,
        Item::Enum(i) => &i.attrs,
        Item::Fn(i) => &i.attrs,
        Item::Impl(i) => &i.attrs,
        Item::Macro(i) => &i.attrs,
        Item::Mod(i) => &i.attrs,
        Item::Static(i) => &i.attrs,
        Item::Struct(i) => &i.attrs,
        Item::Trait(i) => &i.attrs,
        Item::Type(i) => &i.attrs,
        Item::Use(i) => &i.attrs,
        _ => &[],
    }
}

fn lines(span: Span) -> usize {
    span.end().line + 1 - span.start().line
}

/// The file's lines less those of its top-level test items.
fn lines_outside_tests(file: &syn::File, text: &str) -> usize {
    let tests: usize = file
        .items
        .iter()
        .filter(|i| is_test(item_attrs(i)))
        .map(|i| lines(i.span()))
        .sum();
    text.lines().count().saturating_sub(tests)
}

/// The module a file is: `a/b.rs` and `a/b/mod.rs` are `[a, b]`, `lib.rs` and `main.rs` the root `[]`.
fn module_of(path: &str) -> Vec<String> {
    let mut parts: Vec<String> = path.trim_end_matches(".rs").split('/').map(String::from).collect();
    if parts.len() == 1 && (parts[0] == "lib" || parts[0] == "main") || parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

/// A module: the path of names from its crate root (`[]` for the root).
type Module = Vec<String>;

/// Import edges between sibling modules, by the folder (module) they sit in: `(parent, from, to)` with the first
/// place that makes the edge.
type Edges = BTreeMap<(Module, String, String), String>;

/// The crate a file belongs to and its path inside that crate: `bin/x.rs` is the root (`main.rs`) of the crate
/// `bin/x`, a file under `bin/x/` belongs to that crate, and any other file to the library (`lib.rs`, `main.rs`).
fn crate_of(path: &str) -> (String, String) {
    let parts: Vec<&str> = path.split('/').collect();
    match parts.as_slice() {
        ["bin", file] => (format!("bin/{}", file.trim_end_matches(".rs")), "main.rs".into()),
        ["bin", name, rest @ ..] => (format!("bin/{name}"), rest.join("/")),
        _ => (String::new(), path.into()),
    }
}

/// The longest prefix of `path` that is a module of the crate (a file); the root at least.
fn known_prefix<'p>(path: &'p [String], known: &BTreeSet<Module>) -> &'p [String] {
    (0..=path.len())
        .rev()
        .map(|k| &path[..k])
        .find(|p| known.contains(*p))
        .unwrap_or_default()
}

/// Where a `use` path in `module` points, as the full path of names: `None` for another crate.
fn use_path(module: &[String], segments: &[String], known: &BTreeSet<Module>) -> Option<Module> {
    let (first, rest) = segments.split_first()?;
    let mut path: Module = match first.as_str() {
        "crate" => Vec::new(),
        "self" => module.to_vec(),
        "super" => module[..module.len().checked_sub(1)?].to_vec(),
        name => {
            // Uniform paths: a child module's name starts a path relative to this module.
            let child: Module = module.iter().cloned().chain([name.to_string()]).collect();
            if !known.contains(&child) {
                return None;
            }
            child
        }
    };
    let mut rest = rest;
    while rest.first().is_some_and(|s| s == "super") {
        path.pop();
        rest = &rest[1..];
    }
    path.extend(rest.iter().cloned());
    Some(path)
}

/// The names a module file brings in with `use` (`pub use x::X;`), by the module they come from.
fn reexports(file: &syn::File, module: &[String], known: &BTreeSet<Module>, out: &mut Reexports) {
    fn walk(tree: &UseTree, prefix: &mut Vec<String>, leaves: &mut Vec<(Vec<String>, String)>) {
        match tree {
            UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                walk(&p.tree, prefix, leaves);
                prefix.pop();
            }
            UseTree::Name(n) => {
                let mut path = prefix.clone();
                path.push(n.ident.to_string());
                leaves.push((path, n.ident.to_string()));
            }
            UseTree::Rename(r) => {
                let mut path = prefix.clone();
                path.push(r.ident.to_string());
                leaves.push((path, r.rename.to_string()));
            }
            UseTree::Group(g) => g.items.iter().for_each(|t| walk(t, prefix, leaves)),
            UseTree::Glob(_) => {}
        }
    }
    for item in &file.items {
        if let Item::Use(u) = item {
            let mut leaves = Vec::new();
            walk(&u.tree, &mut Vec::new(), &mut leaves);
            for (segments, name) in leaves {
                let Some(path) = use_path(module, &segments, known) else {
                    continue;
                };
                let from = known_prefix(&path, known);
                if from != module {
                    out.insert((module.to_vec(), name), from.to_vec());
                }
            }
        }
    }
}

/// `(module, name)` to the module the name is re-exported from.
type Reexports = BTreeMap<(Module, String), Module>;

/// One file's walk: its long functions, and the imports that leave its top-level module.
struct Scan<'a> {
    path: &'a str,
    /// The module being walked: the file's, and any inline `mod` inside it.
    module: Module,
    known: &'a BTreeSet<Module>,
    reexports: &'a Reexports,
    edges: &'a mut Edges,
    found: &'a mut Vec<String>,
}

impl Scan<'_> {
    /// The module (file) a `crate::`/`super::`/`self::` path lands in (`None`: another crate).
    fn target(&self, segments: &[String]) -> Option<Module> {
        if !["crate", "super", "self"].contains(&segments.first()?.as_str()) {
            return None;
        }
        let path = use_path(&self.module, segments, self.known)?;
        let at = known_prefix(&path, self.known);
        let through = path
            .get(at.len())
            .and_then(|name| self.reexports.get(&(at.to_vec(), name.clone())));
        Some(through.cloned().unwrap_or_else(|| at.to_vec()))
    }

    fn import(&mut self, segments: &[String], span: Span) {
        let Some(to) = self.target(segments) else {
            return;
        };
        let from = known_prefix(&self.module, self.known);
        // The edge is between the children of the deepest module both lie in.
        let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
        if let (Some(a), Some(b)) = (from.get(common), to.get(common)) {
            let at = format!("{}:{} `{}`", self.path, span.start().line, segments.join("::"));
            let key = (from[..common].to_vec(), a.clone(), b.clone());
            self.edges.entry(key).or_insert(at);
        }
    }

    fn use_tree(&mut self, prefix: &mut Vec<String>, tree: &UseTree) {
        match tree {
            UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(prefix, &p.tree);
                prefix.pop();
            }
            UseTree::Name(n) => {
                prefix.push(n.ident.to_string());
                self.import(prefix, n.ident.span());
                prefix.pop();
            }
            UseTree::Rename(r) => {
                prefix.push(r.ident.to_string());
                self.import(prefix, r.ident.span());
                prefix.pop();
            }
            UseTree::Glob(g) => self.import(prefix, g.star_token.spans[0]),
            UseTree::Group(g) => g.items.iter().for_each(|t| self.use_tree(prefix, t)),
        }
    }

    /// `crate::a::b` sequences in a macro's tokens, which `syn` leaves unparsed.
    fn tokens(&mut self, tokens: TokenStream) {
        let tokens: Vec<TokenTree> = tokens.into_iter().collect();
        let is_sep = |i: usize| {
            matches!((tokens.get(i), tokens.get(i + 1)), (Some(TokenTree::Punct(a)), Some(TokenTree::Punct(b)))
                if a.as_char() == ':' && b.as_char() == ':')
        };
        for (i, tt) in tokens.iter().enumerate() {
            match tt {
                TokenTree::Group(g) => self.tokens(g.stream()),
                TokenTree::Ident(id) if ["crate", "super", "self"].contains(&id.to_string().as_str()) => {
                    let mut segments = vec![id.to_string()];
                    let mut j = i + 1;
                    while is_sep(j) {
                        let Some(TokenTree::Ident(next)) = tokens.get(j + 2) else {
                            break;
                        };
                        segments.push(next.to_string());
                        j += 3;
                    }
                    if segments.len() > 1 {
                        self.import(&segments, id.span());
                    }
                }
                _ => {}
            }
        }
    }

    fn function(&mut self, sig: &Signature, body: &syn::Block) {
        let n = body.brace_token.span.close().end().line + 1 - sig.fn_token.span.start().line;
        if n > MAX_FN_LINES {
            let line = sig.fn_token.span.start().line;
            self.found.push(format!(
                "{}:{line}: fn {} is {n} lines (at most {MAX_FN_LINES})",
                self.path, sig.ident
            ));
        }
    }
}

impl<'ast> Visit<'ast> for Scan<'_> {
    fn visit_item(&mut self, item: &'ast Item) {
        if !is_test(item_attrs(item)) {
            visit::visit_item(self, item);
        }
    }

    fn visit_item_mod(&mut self, m: &'ast ItemMod) {
        if m.content.is_some() {
            self.module.push(m.ident.to_string());
            visit::visit_item_mod(self, m);
            self.module.pop();
        }
    }

    fn visit_item_fn(&mut self, f: &'ast ItemFn) {
        self.function(&f.sig, &f.block);
        visit::visit_item_fn(self, f);
    }

    fn visit_impl_item_fn(&mut self, f: &'ast ImplItemFn) {
        if !is_test(&f.attrs) {
            self.function(&f.sig, &f.block);
            visit::visit_impl_item_fn(self, f);
        }
    }

    fn visit_trait_item_fn(&mut self, f: &'ast TraitItemFn) {
        if let Some(body) = &f.default {
            self.function(&f.sig, body);
        }
        visit::visit_trait_item_fn(self, f);
    }

    fn visit_item_use(&mut self, u: &'ast ItemUse) {
        self.use_tree(&mut Vec::new(), &u.tree);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segments: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        self.import(&segments, p.span());
        visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.tokens(m.tokens.clone());
        visit::visit_macro(self, m);
    }
}

/// One shortest cycle through each set of modules that import each other, as `a -> b -> a` with the import that
/// makes each step.
fn cycles(tree: &str, edges: &BTreeMap<(String, String), String>) -> Vec<String> {
    let mut next: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for (from, to) in edges.keys() {
        next.entry(from).or_default().push(to);
    }
    let mut seen: BTreeSet<BTreeSet<&str>> = BTreeSet::new();
    let mut found = Vec::new();
    for &start in next.keys() {
        // Breadth first from `start` back to it: the shortest way round.
        let mut came_from: BTreeMap<&str, &str> = BTreeMap::new();
        let mut queue = VecDeque::from([start]);
        let mut closing = None;
        while let Some(at) = queue.pop_front() {
            for &to in next.get(at).into_iter().flatten() {
                if to == start {
                    closing = Some(at);
                    break;
                }
                if !came_from.contains_key(to) {
                    came_from.insert(to, at);
                    queue.push_back(to);
                }
            }
            if closing.is_some() {
                break;
            }
        }
        let Some(mut at) = closing else { continue };
        let mut back = Vec::new();
        while at != start {
            back.push(at);
            at = came_from[at];
        }
        let path: Vec<&str> = [start]
            .into_iter()
            .chain(back.into_iter().rev())
            .chain([start])
            .collect();
        if seen.insert(path.iter().copied().collect()) {
            let steps: Vec<&str> = path
                .windows(2)
                .map(|w| edges[&(w[0].to_string(), w[1].to_string())].as_str())
                .collect();
            found.push(format!(
                "{tree}: import cycle {} ({})",
                path.join(" -> "),
                steps.join("; ")
            ));
        }
    }
    found
}

/// Every rule broken in one tree's sources (`tree` names it in the messages).
fn check(tree: &str, sources: &[Source]) -> Vec<String> {
    let mut found = Vec::new();
    let mut crates: BTreeMap<String, Vec<(&Source, String, syn::File)>> = BTreeMap::new();
    for s in sources.iter().filter(|s| !is_test_file(&s.path)) {
        match syn::parse_file(&s.text) {
            Ok(file) => {
                let (krate, inside) = crate_of(&s.path);
                crates.entry(krate).or_default().push((s, inside, file));
            }
            Err(e) => found.push(format!("{tree}/{}: does not parse: {e}", s.path)),
        }
    }
    for (krate, files) in &crates {
        let label = if krate.is_empty() {
            tree.to_string()
        } else {
            format!("{tree}/{krate}")
        };
        found.extend(check_crate(tree, &label, files));
    }
    found
}

/// The rules in one crate of a tree: its files with their paths inside the crate.
fn check_crate(tree: &str, label: &str, files: &[(&Source, String, syn::File)]) -> Vec<String> {
    let mut found = Vec::new();
    let known: BTreeSet<Module> = files
        .iter()
        .map(|(_, inside, _)| module_of(inside))
        .chain([Vec::new()])
        .collect();
    let mut reexported = Reexports::new();
    for (_, inside, file) in files {
        reexports(file, &module_of(inside), &known, &mut reexported);
    }
    let mut edges = Edges::new();
    for (s, inside, file) in files {
        let n = lines_outside_tests(file, &s.text);
        if n > MAX_FILE_LINES {
            found.push(format!(
                "{tree}/{}: {n} lines outside tests (at most {MAX_FILE_LINES})",
                s.path
            ));
        }
        let path = format!("{tree}/{}", s.path);
        let mut scan = Scan {
            path: &path,
            module: module_of(inside),
            known: &known,
            reexports: &reexported,
            edges: &mut edges,
            found: &mut found,
        };
        scan.visit_file(file);
    }
    let mut by_folder: BTreeMap<&Module, BTreeMap<(String, String), String>> = BTreeMap::new();
    for ((folder, from, to), at) in &edges {
        by_folder
            .entry(folder)
            .or_default()
            .insert((from.clone(), to.clone()), at.clone());
    }
    for (folder, edges) in by_folder {
        let name = [label.to_string()]
            .into_iter()
            .chain(folder.iter().cloned())
            .collect::<Vec<_>>()
            .join("/");
        found.extend(cycles(&name, &edges));
    }
    found
}

#[test]
fn every_source_tree_keeps_the_layout_rules() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut found = Vec::new();
    for tree in TREES {
        let root = repo.join(tree);
        let mut sources = Vec::new();
        read_tree(&root, &root, &mut sources);
        assert!(sources.len() > 5, "{tree}: {} files read", sources.len());
        found.extend(check(tree, &sources));
    }
    assert!(found.is_empty(), "{} broken:\n{}", found.len(), found.join("\n"));
}

/// `n` lines of code.
fn filler(n: usize) -> String {
    (0..n).map(|i| format!("    let _x{i} = {i};\n")).collect()
}

#[test]
fn a_long_file_is_found_but_not_its_tests() {
    let long = format!("pub fn f() {{}}\n{}", "// a line\n".repeat(MAX_FILE_LINES));
    let found = check("t", &[Source::new("long.rs", &long)]);
    assert_eq!(found, ["t/long.rs: 501 lines outside tests (at most 500)"]);

    let with_tests = format!(
        "pub fn f() {{}}\n#[cfg(test)]\nmod tests {{\n{}}}\n",
        "// a line\n".repeat(600)
    );
    assert_eq!(check("t", &[Source::new("ok.rs", &with_tests)]), Vec::<String>::new());
    // 500 lines exactly, and test files of any length, pass.
    let exact = "// a line\n".repeat(MAX_FILE_LINES);
    let sources = [
        Source::new("exact.rs", &exact),
        Source::new("a/tests.rs", &long),
        Source::new("tests/x.rs", &long),
    ];
    assert_eq!(check("t", &sources), Vec::<String>::new());
}

#[test]
fn a_long_function_is_found_outside_tests_only() {
    // Braces in strings and comments do not end a function early.
    let body = |n: usize| format!("{{\n    let _s = \"}}\"; // }}\n{}}}\n", filler(n - 3));
    let src = format!(
        "fn exactly() {}\nstruct S;\nimpl S {{\n    fn method(&self) {}}}\ntrait T {{\n    fn provided() {}}}\n\
         #[test]\nfn a_test() {}\n#[cfg(test)]\nmod tests {{\n    fn helper() {}}}\n",
        body(MAX_FN_LINES),
        body(MAX_FN_LINES + 1),
        body(MAX_FN_LINES + 20),
        body(300),
        body(300),
    );
    let found = check("t", &[Source::new("f.rs", &src)]);
    assert_eq!(found.len(), 2, "{found:?}");
    assert!(
        found[0].starts_with("t/f.rs:") && found[0].ends_with("fn method is 101 lines (at most 100)"),
        "{found:?}"
    );
    assert!(
        found[1].ends_with("fn provided is 120 lines (at most 100)"),
        "{found:?}"
    );
}

#[test]
fn an_import_cycle_is_found_with_its_path() {
    let sources = [
        Source::new("lib.rs", "mod a;\nmod b;\nmod c;\nmod d;\npub use d::Reexported;\n"),
        Source::new("a.rs", "use crate::{b::B, d};\npub const NAME: &str = \"a\";\n"),
        // A child's `super::super` leaves the folder `b` for `c`.
        Source::new("b/mod.rs", "mod inner;\npub struct B;\n"),
        Source::new("b/inner.rs", "pub fn g() -> super::super::c::C { todo!() }\n"),
        // Inside a macro's arguments.
        Source::new(
            "c.rs",
            "pub struct C;\npub fn h() { println!(\"{}\", crate::a::NAME); }\n",
        ),
        Source::new("d.rs", "pub struct Reexported;\n"),
    ];
    let found = check("t", &sources);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].starts_with("t: import cycle a -> b -> c -> a ("), "{found:?}");
    assert!(found[0].contains("t/b/inner.rs:1 `super::super::c::C`"), "{found:?}");
    assert!(found[0].contains("t/c.rs:2 `crate::a::NAME`"), "{found:?}");

    // Through a name the root re-exports: `crate::Reexported` is d's.
    let sources = [
        Source::new("lib.rs", "mod a;\nmod d;\npub use d::{Reexported as R};\n"),
        Source::new("a.rs", "pub fn f(_: crate::R) {}\n"),
        Source::new("d.rs", "pub struct Reexported;\nfn g() { crate::a::f(Reexported) }\n"),
    ];
    let found = check("t", &sources);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].starts_with("t: import cycle a -> d -> a ("), "{found:?}");
}

#[test]
fn imports_within_a_module_or_from_tests_make_no_cycle() {
    let sources = [
        Source::new("main.rs", "mod a;\nmod b;\nuse a::A;\nfn main() {}\n"),
        Source::new("a/mod.rs", "mod x;\npub use x::A;\nuse crate::b::B;\n"),
        Source::new(
            "a/x.rs",
            "pub struct A;\nuse super::super::a::A as Same;\nuse self::inner::*;\nmod inner {}\n",
        ),
        Source::new(
            "b.rs",
            "pub struct B;\n#[cfg(test)]\nmod tests {\n    use crate::a::A;\n}\n",
        ),
        Source::new("b/tests.rs", "use crate::a::A;\n"),
    ];
    assert_eq!(check("t", &sources), Vec::<String>::new());
}

#[test]
fn a_cycle_between_sibling_files_of_a_folder_is_found() {
    let sources = [
        Source::new("lib.rs", "pub mod analysis;\npub mod out;\n"),
        Source::new(
            "analysis/mod.rs",
            "mod branches;\nmod kinematics;\npub use kinematics::Solve;\n",
        ),
        Source::new(
            "analysis/branches.rs",
            "use super::kinematics::Solve;\npub struct Branch;\n",
        ),
        // Through the folder's re-export: `crate::analysis::Solve` is kinematics'.
        Source::new(
            "analysis/kinematics.rs",
            "pub struct Solve;\nfn f(_: super::branches::Branch) {}\n",
        ),
        Source::new("out/mod.rs", "mod a;\nmod b;\n"),
        Source::new(
            "out/a.rs",
            "pub struct A;\nfn f() { let _ = crate::analysis::Solve; }\n",
        ),
        Source::new("out/b.rs", "pub struct B;\nuse crate::out::a::A;\n"),
    ];
    let found = check("t", &sources);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].starts_with("t/analysis: import cycle branches -> kinematics -> branches ("),
        "{found:?}"
    );
    assert!(
        found[0].contains("t/analysis/kinematics.rs:2 `super::branches::Branch`"),
        "{found:?}"
    );

    let sources = [
        Source::new("lib.rs", "pub mod out;\n"),
        Source::new("out/mod.rs", "mod a;\nmod b;\npub use a::A;\n"),
        Source::new("out/a.rs", "pub struct A;\nfn f() { let _ = super::b::B; }\n"),
        Source::new("out/b.rs", "pub struct B;\nfn g() { let _ = crate::out::A; }\n"),
    ];
    let found = check("t", &sources);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].starts_with("t/out: import cycle a -> b -> a ("), "{found:?}");
    assert!(found[0].contains("t/out/b.rs:2 `crate::out::A`"), "{found:?}");
}

#[test]
fn each_binary_is_a_crate_of_its_own() {
    // `crate::` in a binary is the binary's root: `bin/x/main.rs` and `bin/x/y.rs` import each other as root and
    // child, and the library's `a` and `b` are not the binary's.
    let sources = [
        Source::new("lib.rs", "pub mod a;\npub mod b;\n"),
        Source::new("a.rs", "pub struct A;\n"),
        Source::new("b.rs", "pub struct B;\n"),
        Source::new("bin/x/main.rs", "mod a;\nmod y;\nuse crate::y::Y;\nfn main() {}\n"),
        Source::new("bin/x/a.rs", "pub struct A;\nuse crate::y::Y;\n"),
        Source::new("bin/x/y.rs", "pub struct Y;\nuse crate::a::A;\n"),
        Source::new(
            "bin/z.rs",
            "mod inner { pub struct I; }\nuse crate::inner::I;\nfn main() {}\n",
        ),
    ];
    let found = check("t", &sources);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].starts_with("t/bin/x: import cycle a -> y -> a ("), "{found:?}");
    assert!(found[0].contains("t/bin/x/y.rs:2 `crate::a::A`"), "{found:?}");
}
