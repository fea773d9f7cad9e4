//! The layout of `src/`: no import cycle between files, nor between folders.
//!
//! A cycle means two files (or folders) can only be read, changed and tested together; the
//! layout note in `docs/layout.md` draws which way the imports run. This test reads the
//! sources as text (no compiler API): it resolves every path a file names (`use` lines and
//! paths written inline, through `crate::`, `super::`, `self::`, child modules and the
//! names a `use` brought in) to the file that defines the item, following re-exports.
//!
//! A module's root file (`mod.rs`, `lib.rs`) and the files below it are one module: a part
//! implementing its parent's type, and the parent calling into its parts, is how Rust lays
//! out a module, so edges between a root and its own descendants are not counted. Code
//! under `#[cfg(test)]` is not counted either (a unit test may reach anywhere), nor
//! `#[cfg(doc)]` imports (names for the docs' links).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Module path (`["shape", "quad"]`) of every file under `src/`.
fn modules(src: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    fn walk(dir: &Path, prefix: &[String], out: &mut BTreeMap<Vec<String>, PathBuf>) {
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_str().unwrap().to_string();
            if path.is_dir() {
                let mut p = prefix.to_vec();
                p.push(name);
                walk(&path, &p, out);
            } else if let Some(stem) = name.strip_suffix(".rs") {
                let mut p = prefix.to_vec();
                if stem != "mod" && !(prefix.is_empty() && stem == "lib") {
                    p.push(stem.to_string());
                }
                out.insert(p, path);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(src, &[], &mut out);
    out
}

/// The code of a file without comments, string literals and `#[cfg(test)]` and
/// `#[cfg(doc)]` items.
fn code(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        if text[i..].starts_with("//") {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
        } else if text[i..].starts_with("/*") {
            let end = text[i + 2..]
                .find("*/")
                .map_or(bytes.len(), |e| i + 2 + e + 2);
            i = end;
        } else if bytes[i] == b'"' {
            i += 1;
            while i < bytes.len() && bytes[i] != b'"' {
                i += if bytes[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if let Some(attribute) = ["#[cfg(test)]", "#[cfg(doc)]"]
            .into_iter()
            .find(|a| text[i..].starts_with(a))
        {
            // Skip the attribute and the item it guards: up to its matching close brace, or
            // its semicolon when one comes first.
            i += attribute.len();
            let mut depth = 0;
            while i < bytes.len() {
                match bytes[i] {
                    b'{' => depth += 1,
                    b'}' => {
                        depth -= 1;
                        if depth == 0 {
                            i += 1;
                            break;
                        }
                    }
                    b';' if depth == 0 => {
                        i += 1;
                        break;
                    }
                    _ => {}
                }
                i += 1;
            }
        } else {
            let c = text[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Expands a `use` tree (`a::{b, c::{d as e}}`) into (path, local name) pairs.
fn expand(prefix: &[String], tree: &str, out: &mut Vec<(Vec<String>, String)>) {
    let tree = tree.trim();
    if tree.is_empty() {
        return;
    }
    if let Some(open) = tree.find('{') {
        let head: Vec<String> = tree[..open]
            .split("::")
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect();
        let mut base = prefix.to_vec();
        base.extend(head);
        let inner = &tree[open + 1..tree.rfind('}').unwrap()];
        let mut depth = 0;
        let mut start = 0;
        for (k, c) in inner.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand(&base, &inner[start..k], out);
                    start = k + 1;
                }
                _ => {}
            }
        }
        expand(&base, &inner[start..], out);
        return;
    }
    let (path, alias) = match tree.split_once(" as ") {
        Some((p, a)) => (p, Some(a.trim().to_string())),
        None => (tree, None),
    };
    let mut full = prefix.to_vec();
    full.extend(path.split("::").map(str::trim).map(String::from));
    if full.last().is_some_and(|s| s == "self") {
        full.pop();
    }
    let name = alias.unwrap_or_else(|| full.last().cloned().unwrap_or_default());
    out.push((full, name));
}

struct File {
    module: Vec<String>,
    /// Items defined here (types, functions, constants, traits, inline modules).
    defines: BTreeSet<String>,
    /// Names a `use` brings in, with the path it names.
    uses: Vec<(Vec<String>, String)>,
    /// Child modules declared with `mod name;`.
    children: BTreeSet<String>,
    /// Paths written in the code, `use` lines included.
    paths: Vec<Vec<String>>,
}

fn parse(module: Vec<String>, text: &str) -> File {
    let code = code(text);
    let mut defines = BTreeSet::new();
    let mut children = BTreeSet::new();
    let words: Vec<&str> = code
        .split(|c: char| !is_ident(c) && c != '!')
        .filter(|w| !w.is_empty())
        .collect();
    for pair in words.windows(2) {
        let kind = pair[0];
        if matches!(
            kind,
            "struct" | "enum" | "trait" | "fn" | "type" | "const" | "static" | "union" | "mod"
        ) {
            defines.insert(pair[1].to_string());
        }
    }
    for line in code.lines() {
        let l = line.trim();
        let l = l
            .strip_prefix("pub(crate) ")
            .or_else(|| l.strip_prefix("pub(super) "))
            .or_else(|| l.strip_prefix("pub "))
            .unwrap_or(l);
        if let Some(name) = l.strip_prefix("mod ").and_then(|r| r.strip_suffix(';')) {
            children.insert(name.trim().to_string());
        }
    }
    // `use` statements, which may span lines.
    let mut uses = Vec::new();
    let mut rest = code.as_str();
    while let Some(at) = rest.find("use ") {
        let before = rest[..at].chars().last();
        let after = &rest[at + 4..];
        if before.is_some_and(is_ident) {
            rest = after;
            continue;
        }
        let end = after.find(';').unwrap_or(after.len());
        expand(&[], &after[..end], &mut uses);
        rest = &after[end..];
    }
    // Every `a::b::c` path in the code.
    let mut paths = Vec::new();
    let chars: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        if is_ident(chars[i]) && (i == 0 || !is_ident(chars[i - 1]) && chars[i - 1] != ':') {
            let mut segs = Vec::new();
            let mut j = i;
            loop {
                let s = j;
                while j < chars.len() && is_ident(chars[j]) {
                    j += 1;
                }
                segs.push(chars[s..j].iter().collect::<String>());
                if j + 2 < chars.len()
                    && chars[j] == ':'
                    && chars[j + 1] == ':'
                    && is_ident(chars[j + 2])
                {
                    j += 2;
                } else {
                    break;
                }
            }
            if segs.len() > 1 {
                paths.push(segs);
            }
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    for (path, _) in &uses {
        paths.push(path.clone());
    }
    File {
        module,
        defines,
        uses,
        children,
        paths,
    }
}

struct Crate {
    files: BTreeMap<Vec<String>, File>,
}

impl Crate {
    /// The absolute module path a path written in `from` starts at, or `None` for an
    /// external crate.
    fn absolute(&self, from: &[String], path: &[String]) -> Option<Vec<String>> {
        let file = &self.files[from];
        let mut base: Vec<String> = from.to_vec();
        let mut segs = path;
        match segs.first()?.as_str() {
            "crate" => {
                base.clear();
                segs = &segs[1..];
            }
            "self" => segs = &segs[1..],
            "super" => {
                while segs.first().is_some_and(|s| s == "super") {
                    base.pop();
                    segs = &segs[1..];
                }
            }
            first if file.children.contains(first) => {}
            first => {
                // A name a `use` of this file brought in (not a glob).
                let (target, _) = file.uses.iter().find(|(p, n)| n == first && p.len() > 1)?;
                if target.first().is_some_and(|s| s == first) {
                    return None;
                }
                let mut resolved = self.absolute(from, target)?;
                resolved.extend(segs[1..].iter().cloned());
                return Some(resolved);
            }
        }
        base.extend(segs.iter().cloned());
        Some(base)
    }

    /// The file that defines the item an absolute path names.
    fn defining(&self, path: &[String], depth: usize) -> Option<Vec<String>> {
        if depth > 16 {
            return None;
        }
        let mut module: Vec<String> = Vec::new();
        for (k, seg) in path.iter().enumerate() {
            let mut child = module.clone();
            child.push(seg.clone());
            if self.files.contains_key(&child) {
                module = child;
                continue;
            }
            let file = &self.files[&module];
            if file.defines.contains(seg) {
                return Some(module);
            }
            // A name this module's `use` brought in: follow it.
            if let Some((target, _)) = file.uses.iter().find(|(_, n)| n == seg) {
                let mut target = self.absolute(&module, target)?;
                target.extend(path[k + 1..].iter().cloned());
                return self.defining(&target, depth + 1);
            }
            return Some(module);
        }
        Some(module)
    }
}

/// Strongly connected components of more than one node (Tarjan's algorithm).
fn cycles<N: Ord + Clone>(edges: &BTreeMap<N, BTreeSet<N>>) -> Vec<Vec<N>> {
    struct State<N> {
        index: BTreeMap<N, usize>,
        low: BTreeMap<N, usize>,
        stack: Vec<N>,
        on: BTreeSet<N>,
        out: Vec<Vec<N>>,
    }
    fn visit<N: Ord + Clone>(n: &N, edges: &BTreeMap<N, BTreeSet<N>>, s: &mut State<N>) {
        let i = s.index.len();
        s.index.insert(n.clone(), i);
        s.low.insert(n.clone(), i);
        s.stack.push(n.clone());
        s.on.insert(n.clone());
        for m in edges.get(n).into_iter().flatten() {
            if !s.index.contains_key(m) {
                visit(m, edges, s);
                let low = s.low[n].min(s.low[m]);
                s.low.insert(n.clone(), low);
            } else if s.on.contains(m) {
                let low = s.low[n].min(s.index[m]);
                s.low.insert(n.clone(), low);
            }
        }
        if s.low[n] == s.index[n] {
            let mut component = Vec::new();
            loop {
                let m = s.stack.pop().unwrap();
                s.on.remove(&m);
                let done = &m == n;
                component.push(m);
                if done {
                    break;
                }
            }
            if component.len() > 1 {
                s.out.push(component);
            }
        }
    }
    let mut s = State {
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for n in edges.keys() {
        if !s.index.contains_key(n) {
            visit(n, edges, &mut s);
        }
    }
    s.out
}

fn name(files: &BTreeMap<Vec<String>, PathBuf>, module: &[String]) -> String {
    files[module]
        .strip_prefix(env!("CARGO_MANIFEST_DIR"))
        .unwrap()
        .display()
        .to_string()
}

/// `(file graph, folder graph)`: which file names which, and which top-level folder (or
/// file at the top) names which.
#[allow(clippy::type_complexity)]
fn graphs() -> (
    BTreeMap<Vec<String>, PathBuf>,
    BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
    BTreeMap<String, BTreeSet<String>>,
) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let paths = modules(&src);
    let krate = Crate {
        files: paths
            .iter()
            .map(|(m, p)| (m.clone(), parse(m.clone(), &fs::read_to_string(p).unwrap())))
            .collect(),
    };
    let is_root = |m: &[String]| {
        let p = &paths[m];
        p.ends_with("mod.rs") || p.ends_with("lib.rs")
    };
    let mut files: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    let mut folders: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let top = |m: &[String]| m.first().cloned().unwrap_or_else(|| "lib".into());
    for (module, file) in &krate.files {
        for path in &file.paths {
            let Some(abs) = krate.absolute(module, path) else {
                continue;
            };
            let Some(target) = krate.defining(&abs, 0) else {
                continue;
            };
            if &target == module {
                continue;
            }
            // A module's root and its own parts are one module (see the top of this file).
            let within = |root: &[String], part: &[String]| {
                is_root(root) && part.starts_with(root) && part.len() > root.len()
            };
            if within(module, &target) || within(&target, module) {
                continue;
            }
            assert_eq!(file.module, *module);
            files
                .entry(module.clone())
                .or_default()
                .insert(target.clone());
            if top(module) != top(&target) && !module.is_empty() && !target.is_empty() {
                folders.entry(top(module)).or_default().insert(top(&target));
            }
        }
    }
    (paths, files, folders)
}

#[test]
fn no_file_names_a_file_that_names_it_back() {
    let (paths, files, _) = graphs();
    let found: Vec<String> = cycles(&files)
        .iter()
        .map(|c| {
            c.iter()
                .map(|m| name(&paths, m))
                .collect::<Vec<_>>()
                .join(" <-> ")
        })
        .collect();
    assert!(
        found.is_empty(),
        "import cycles between files:\n{}",
        found.join("\n")
    );
}

#[test]
fn no_folder_names_a_folder_that_names_it_back() {
    let (_, _, folders) = graphs();
    let found: Vec<String> = cycles(&folders).iter().map(|c| c.join(" <-> ")).collect();
    assert!(
        found.is_empty(),
        "import cycles between folders:\n{}",
        found.join("\n")
    );
}

/// The check resolves what it must: a file known to import another is seen to (guards
/// against a parser that finds no edge at all and so no cycle).
#[test]
fn the_check_sees_known_imports() {
    let (_, files, folders) = graphs();
    let quad = vec!["shape".to_string(), "quad".to_string()];
    let plane = vec!["shape".to_string(), "plane".to_string()];
    assert!(files[&quad].contains(&plane), "{:?}", files[&quad]);
    assert!(folders["mesh"].contains("aabb"), "{:?}", folders["mesh"]);
}

/// Prints both graphs, for redrawing `docs/layout.md`:
/// `cargo test --test layout -- --ignored --nocapture`.
#[test]
#[ignore = "prints the import graphs; asserts nothing"]
fn print_graph() {
    let (paths, files, folders) = graphs();
    for (a, bs) in &folders {
        println!("{a} -> {bs:?}");
    }
    for (a, bs) in &files {
        println!(
            "{} -> {:?}",
            name(&paths, a),
            bs.iter().map(|b| name(&paths, b)).collect::<Vec<_>>()
        );
    }
}
