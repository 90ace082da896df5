//! Reference: issue 47 part 3 (a short front page; the rest in docs/; no link leaving the
//! repository; the layout table kept true).
//! Goal: README.md has at most 200 lines; every link in README.md and docs/*.md is relative
//! and resolves to a file or folder of the repository (and an `#anchor` to a heading of
//! the page it names); README.md's layout table lists every module under src/ and only
//! modules that exist; docs/scenes.md shows the files of examples/adding-a-scene as they are.
//! Data: README.md, docs/*.md, src/, examples/adding-a-scene/ as committed.

use std::path::{Component, Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// README.md and every page under docs/.
fn pages() -> Vec<PathBuf> {
    let mut pages = vec![root().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .expect("a docs/ folder")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    assert!(docs.len() >= 5, "docs/ has {} pages", docs.len());
    pages.extend(docs);
    pages
}

/// The text of a page outside fenced code blocks and inline code spans, line by line.
fn prose(text: &str) -> Vec<String> {
    let mut fenced = false;
    let mut lines = Vec::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        // Drop `...` spans: brackets in code ("[[bodies]]") are not links.
        let mut out = String::new();
        for (i, part) in line.split('`').enumerate() {
            if i % 2 == 0 {
                out.push_str(part);
            }
        }
        lines.push(out);
    }
    lines
}

/// The targets of the inline links `[text](target)` and images `![alt](target)` of a page.
fn links(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    for line in prose(text) {
        let mut rest = line.as_str();
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            let Some(end) = after.find(')') else { break };
            targets.push(after[..end].trim().to_string());
            rest = &after[end..];
        }
    }
    targets
}

/// GitHub's anchor of a heading: lower case, spaces to hyphens, other punctuation dropped.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a markdown page's headings.
fn anchors(text: &str) -> Vec<String> {
    prose(text)
        .iter()
        .filter(|l| l.starts_with('#'))
        .map(|l| slug(l.trim_start_matches('#')))
        .collect()
}

/// `path` with `.` and `..` resolved lexically, or None where `..` climbs above `root`.
fn inside(root: &Path, path: &Path) -> Option<PathBuf> {
    let mut parts: Vec<Component> = Vec::new();
    for c in path.strip_prefix(root).ok()?.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                parts.pop()?;
            }
            c => parts.push(c),
        }
    }
    Some(root.join(parts.iter().collect::<PathBuf>()))
}

#[test]
fn readme_is_at_most_200_lines() {
    let lines = read(&root().join("README.md")).lines().count();
    println!("README.md: {lines} lines");
    assert!(lines <= 200, "README.md has {lines} lines (at most 200)");
}

#[test]
fn every_link_resolves_inside_the_repository() {
    let mut checked = 0;
    for page in pages() {
        let text = read(&page);
        let name = page.strip_prefix(root()).unwrap().display().to_string();
        for target in links(&text) {
            assert!(
                !target.contains("://") && !target.starts_with("mailto:"),
                "{name}: link `{target}` leaves the repository; cite the source in full instead"
            );
            let (file, anchor) = target.split_once('#').unwrap_or((target.as_str(), ""));
            let path = if file.is_empty() {
                page.clone()
            } else {
                assert!(
                    !file.starts_with('/'),
                    "{name}: link `{target}` is absolute; make it relative to the page"
                );
                let joined = page.parent().unwrap().join(file);
                inside(root(), &joined).unwrap_or_else(|| {
                    panic!("{name}: link `{target}` climbs out of the repository")
                })
            };
            assert!(
                path.exists(),
                "{name}: link `{target}` names {}, which does not exist",
                path.display()
            );
            if !anchor.is_empty() {
                let headings = anchors(&read(&path));
                assert!(
                    headings.iter().any(|h| h == anchor),
                    "{name}: link `{target}`: no heading with anchor #{anchor} in {} (anchors: {headings:?})",
                    path.display()
                );
            }
            checked += 1;
        }
    }
    println!("{checked} links checked");
    assert!(checked > 20);
}

/// The module paths of the files under src/ (`a/b.rs` and `a/b/mod.rs` are `a::b`), the
/// crate roots lib.rs and main.rs aside.
fn modules_under_src() -> Vec<String> {
    fn walk(dir: &Path, src: &Path, out: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, src, out);
            } else if path.extension().is_some_and(|x| x == "rs") {
                let rel = path.strip_prefix(src).unwrap().with_extension("");
                let parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                let parts = match parts.last().map(String::as_str) {
                    Some("mod") => &parts[..parts.len() - 1],
                    _ => &parts[..],
                };
                if parts != ["lib"] && parts != ["main"] {
                    out.push(parts.join("::"));
                }
            }
        }
    }
    let src = root().join("src");
    let mut out = Vec::new();
    walk(&src, &src, &mut out);
    out.sort();
    out
}

/// README.md's layout table: each row's module path (the first column's code span) and the
/// row's words.
fn layout_rows() -> Vec<(String, Vec<String>)> {
    let readme = read(&root().join("README.md"));
    let start = readme
        .find("\n## Layout\n")
        .expect("README.md has a Layout section");
    let section = &readme[start + 1..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |i| i + 3)];
    section
        .lines()
        .filter(|l| l.starts_with("| `"))
        .map(|l| {
            let cell = l.split('|').nth(1).unwrap().trim();
            let path = cell.trim_matches('`').to_string();
            assert!(
                !path.contains('`') && !path.contains(' '),
                "layout row `{l}`: the first column must be one module path in backticks"
            );
            let words = l
                .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .filter(|w| !w.is_empty())
                .map(str::to_string)
                .collect();
            (path, words)
        })
        .collect()
}

/// Whether `module` is `ancestor` or lies under it.
fn under(module: &str, ancestor: &str) -> bool {
    module == ancestor || module.starts_with(&format!("{ancestor}::"))
}

#[test]
fn layout_table_matches_src() {
    let modules = modules_under_src();
    let rows = layout_rows();
    assert!(rows.len() >= 10, "{} layout rows", rows.len());
    let listed: Vec<&str> = rows.iter().map(|(p, _)| p.as_str()).collect();
    let mut problems = Vec::new();
    for (i, path) in listed.iter().enumerate() {
        if listed[..i].contains(path) {
            problems.push(format!("`{path}` is listed twice"));
        }
        if !modules.iter().any(|m| m == path) {
            problems.push(format!(
                "`{path}` is listed but src/ has no {0}.rs or {0}/mod.rs",
                path.replace("::", "/")
            ));
        }
    }
    for module in &modules {
        if listed.contains(&module.as_str()) {
            continue;
        }
        // A folder listed as one row (none of its modules has a row of its own) covers
        // its files, and its row names each of them.
        let folder_row = rows
            .iter()
            .find(|(p, _)| under(module, p) && !listed.iter().any(|q| q != p && under(q, p)));
        match folder_row {
            Some((p, words)) => {
                let name = module.rsplit("::").next().unwrap();
                if !words.iter().any(|w| w == name) {
                    problems.push(format!(
                        "`{module}` is covered by the row of `{p}`, which does not name `{name}`"
                    ));
                }
            }
            None => problems.push(format!(
                "`{module}` (src/{}) has no row in README.md's layout table",
                module.replace("::", "/")
            )),
        }
    }
    println!("{} modules under src/, {} rows", modules.len(), rows.len());
    assert!(
        problems.is_empty(),
        "README.md's layout table does not match src/:\n{}",
        problems.join("\n")
    );
}

#[test]
fn scenes_page_shows_the_example_files_as_they_are() {
    let page = read(&root().join("docs/scenes.md"));
    for f in ["blocks.geo", "blocks.toml", "blocks-study.toml"] {
        let file = read(&root().join("examples/adding-a-scene").join(f));
        assert!(
            page.contains(file.trim_end()),
            "docs/scenes.md no longer shows examples/adding-a-scene/{f} as it is; copy the file into the page"
        );
    }
}
