//! The layering of the library's middle, read from the source files (ARCHITECTURE.md's module
//! dependencies):
//!
//! - `run` (the run's vocabulary) is below every stage: it names none of `refine`, `improve`,
//!   `approx`, `pipeline`, `api`, `ffi`, `cli` or `io`.
//! - `refine` and `improve` name neither each other nor anything above them: `approx`,
//!   `pipeline`, `api`, `ffi`, `cli`, `quadratic`, `io`. Their test code (`#[cfg(test)]`
//!   modules, inline or in files of their own) may use `crate::io` to read test models.
//!
//! A module is named through a `crate::` path (in a `use` or inline, grouped `crate::{..}`
//! included) or a `super::` path that climbs out of the layer's folder. Comments and string
//! literals are not code; paths inside the layer's own folder are always allowed.

use std::path::{Path, PathBuf};

/// One layer: its folder under `src/`, the top-level modules it may not name, and those its
/// test code may name all the same.
struct Layer {
    name: &'static str,
    forbidden: &'static [&'static str],
    allowed_in_tests: &'static [&'static str],
}

const LAYERS: [Layer; 3] = [
    Layer {
        name: "run",
        forbidden: &[
            "refine", "improve", "approx", "pipeline", "api", "ffi", "cli", "io",
        ],
        allowed_in_tests: &[],
    },
    Layer {
        name: "refine",
        forbidden: &[
            "improve",
            "approx",
            "pipeline",
            "api",
            "ffi",
            "cli",
            "quadratic",
            "io",
        ],
        allowed_in_tests: &["io"],
    },
    Layer {
        name: "improve",
        forbidden: &[
            "refine",
            "approx",
            "pipeline",
            "api",
            "ffi",
            "cli",
            "quadratic",
            "io",
        ],
        allowed_in_tests: &["io"],
    },
];

/// A source file's lines as code: comments removed, string and char literals emptied (so
/// neither a path in a message nor a brace in a literal counts).
fn code_lines(text: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let chars: Vec<char> = text.chars().collect();
    let (mut i, mut block) = (0, 0usize);
    let push = |out: &mut Vec<String>, c: char| {
        if c == '\n' {
            out.push(String::new());
        } else {
            out.last_mut().unwrap().push(c);
        }
    };
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if block > 0 {
            if c == '*' && next == Some('/') {
                block -= 1;
                i += 2;
            } else if c == '/' && next == Some('*') {
                block += 1;
                i += 2;
            } else {
                if c == '\n' {
                    push(&mut out, c);
                }
                i += 1;
            }
            continue;
        }
        match (c, next) {
            ('/', Some('/')) => {
                while i < chars.len() && chars[i] != '\n' {
                    i += 1;
                }
            }
            ('/', Some('*')) => {
                block = 1;
                i += 2;
            }
            ('"', _) => {
                out.last_mut().unwrap().push_str("\"\"");
                i += 1;
                while i < chars.len() && chars[i] != '"' {
                    if chars[i] == '\\' {
                        i += 1;
                    }
                    if chars.get(i) == Some(&'\n') {
                        push(&mut out, '\n');
                    }
                    i += 1;
                }
                i += 1;
            }
            ('\'', _) => {
                // A char literal ('x', '\n', '\u{..}') or a lifetime ('a).
                if next == Some('\\') {
                    i += 2;
                    while i < chars.len() && chars[i] != '\'' {
                        i += 1;
                    }
                    i += 1;
                    out.last_mut().unwrap().push_str("' '");
                } else if chars.get(i + 2) == Some(&'\'') {
                    i += 3;
                    out.last_mut().unwrap().push_str("' '");
                } else {
                    push(&mut out, c);
                    i += 1;
                }
            }
            _ => {
                push(&mut out, c);
                i += 1;
            }
        }
    }
    out
}

/// The top-level module a path at `at` names, if it leaves the layer: `crate::m` (m not the
/// layer) or `super::` climbing past the layer's root (`depth`: how far below the root the
/// path is written).
fn left_for(code: &str, at: usize, layer: &str, depth: usize) -> Option<String> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let rest = &code[at..];
    if let Some(r) = rest.strip_prefix("crate::") {
        let m = ident(r);
        return (m != layer).then_some(m);
    }
    let mut r = rest;
    let mut ups = 0;
    while let Some(after) = r.strip_prefix("super::") {
        ups += 1;
        r = after;
    }
    (ups > depth).then(|| ident(r))
}

/// Where a path starts in `code`: `crate::` or `super::` not preceded by part of a path or an
/// identifier.
fn path_starts(code: &str) -> Vec<usize> {
    let mut at = vec![];
    for pat in ["crate::", "super::"] {
        for (i, _) in code.match_indices(pat) {
            let before = code[..i].chars().next_back();
            let prefixed = code[..i].ends_with("::");
            if !prefixed && !before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                at.push(i);
            }
        }
    }
    at.sort_unstable();
    at
}

/// The modules named by a grouped `crate::{a, b::c, ..}` starting at `at` (the group may span
/// lines: `rest` holds the code from there on).
fn grouped(rest: &str) -> Vec<String> {
    let Some(body) = rest.strip_prefix("crate::{") else {
        return vec![];
    };
    let mut depth = 1;
    let mut names = vec![];
    let mut item = String::new();
    for c in body.chars() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ => {}
        }
        if depth == 0 || (depth == 1 && c == ',') {
            let m: String = item
                .trim()
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !m.is_empty() {
                names.push(m);
            }
            item.clear();
            if depth == 0 {
                break;
            }
        } else if depth == 1 {
            item.push(c);
        } else if depth > 1 && !item.contains("::") {
            item.push_str("::");
        }
    }
    names
}

/// A file of a layer: its path (for messages), its text, how far its module is below the
/// layer's root (`mod.rs` of the layer: 0), and whether all of it is test code.
struct Source {
    path: String,
    text: String,
    depth: usize,
    test: bool,
}

/// The forbidden names in `file`, as "path:line: message".
fn violations(layer: &Layer, file: &Source) -> Vec<String> {
    let lines = code_lines(&file.text);
    let mut found = vec![];
    // Inline modules open at brace depth d: (d, is a test module).
    let mut open: Vec<(usize, bool)> = vec![];
    let mut braces = 0usize;
    let mut cfg_test = false;
    for (n, code) in lines.iter().enumerate() {
        let trimmed = code.trim();
        let in_test = file.test || open.iter().any(|&(_, t)| t);
        let depth = file.depth + open.len();
        for at in path_starts(code) {
            let mut names: Vec<String> =
                left_for(code, at, layer.name, depth).into_iter().collect();
            if code[at..].starts_with("crate::{") {
                let rest = lines[n..].join("\n");
                names.extend(grouped(&rest[at..]).into_iter().filter(|m| m != layer.name));
            }
            for m in names {
                let allowed = in_test && layer.allowed_in_tests.contains(&m.as_str());
                if layer.forbidden.contains(&m.as_str()) && !allowed {
                    found.push(format!(
                        "{}:{}: `{}` names `{m}`, which layer `{}` may not use{}",
                        file.path,
                        n + 1,
                        trimmed,
                        layer.name,
                        if in_test {
                            " (not even in test code)"
                        } else {
                            ""
                        }
                    ));
                }
            }
        }
        let words: Vec<&str> = trimmed.split_whitespace().collect();
        let mod_at = words.iter().position(|w| *w == "mod");
        // `mod name {` or `mod name{` (a `mod name;` is a file of its own).
        let opens_mod = mod_at.is_some_and(|k| {
            words.get(k + 2) == Some(&"{") || words.get(k + 1).is_some_and(|w| w.ends_with('{'))
        });
        for c in code.chars() {
            match c {
                '{' => braces += 1,
                '}' => {
                    braces = braces.saturating_sub(1);
                    while open.last().is_some_and(|&(d, _)| d > braces) {
                        open.pop();
                    }
                }
                _ => {}
            }
        }
        if opens_mod {
            // The module's body is everything inside the brace just opened.
            open.push((braces, cfg_test));
        }
        if trimmed.starts_with("#[cfg(test)]") {
            cfg_test = true;
        } else if !trimmed.starts_with("#[") && !trimmed.is_empty() {
            cfg_test = false;
        }
    }
    found
}

/// The files of `src/<layer>`, each with its depth and whether a `#[cfg(test)] mod x;` of its
/// parent (or a test file above it) makes all of it test code.
fn layer_sources(root: &Path, layer: &str) -> Vec<Source> {
    let dir = root.join("src").join(layer);
    let mut out = vec![];
    // (file, depth, test)
    let mut todo = vec![(dir.join("mod.rs"), 0usize, false)];
    while let Some((path, depth, test)) = todo.pop() {
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        // The folder of this module's children.
        let children: PathBuf = if path.file_name().is_some_and(|f| f == "mod.rs") {
            path.parent().unwrap().to_path_buf()
        } else {
            path.with_extension("")
        };
        let mut cfg_test = false;
        for line in code_lines(&text) {
            let t = line.trim();
            let words: Vec<&str> = t.split_whitespace().collect();
            if let Some(k) = words.iter().position(|w| *w == "mod") {
                if let Some(name) = words.get(k + 1).and_then(|w| w.strip_suffix(';')) {
                    let file = children.join(format!("{name}.rs"));
                    let file = if file.exists() {
                        file
                    } else {
                        children.join(name).join("mod.rs")
                    };
                    todo.push((file, depth + 1, test || cfg_test));
                }
            }
            if t.starts_with("#[cfg(test)]") {
                cfg_test = true;
            } else if !t.starts_with("#[") && !t.is_empty() {
                cfg_test = false;
            }
        }
        let shown = path
            .strip_prefix(root)
            .unwrap_or(&path)
            .display()
            .to_string();
        out.push(Source {
            path: shown,
            text,
            depth,
            test,
        });
    }
    out
}

#[test]
fn run_refine_and_improve_name_nothing_above_them() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut found = vec![];
    for layer in &LAYERS {
        let sources = layer_sources(root, layer.name);
        assert!(sources.len() > 2, "src/{}: too few files found", layer.name);
        for file in &sources {
            found.extend(violations(layer, file));
        }
    }
    assert!(
        found.is_empty(),
        "forbidden imports (see tests/layering.rs):\n{}",
        found.join("\n")
    );
}

/// The scan itself: what it must catch and what it must let pass.
#[test]
fn the_scan_catches_forbidden_paths_and_only_those() {
    let refine = &LAYERS[1];
    let file = |text: &str, depth: usize, test: bool| Source {
        path: "src/refine/x.rs".into(),
        text: text.into(),
        depth,
        test,
    };
    let count = |text: &str, depth: usize, test: bool| violations(refine, &file(text, depth, test));
    // Forbidden: a use, an inline path, a group, a super path out of the folder.
    assert_eq!(
        count("use crate::improve::ImproveStats;\n", 1, false).len(),
        1
    );
    let v = count(
        "fn f() {\n    let s = crate::pipeline::mesh;\n}\n",
        1,
        false,
    );
    assert_eq!(v.len(), 1);
    assert!(v[0].starts_with("src/refine/x.rs:2: "), "{v:?}");
    assert_eq!(
        count("use crate::{geom, improve::Options};\n", 1, false).len(),
        1
    );
    assert_eq!(
        count(
            "use crate::{\n    geom::orient3d,\n    approx,\n};\n",
            1,
            false
        )
        .len(),
        1
    );
    assert_eq!(count("use super::super::api::Mesher;\n", 1, false).len(), 1);
    assert_eq!(count("use crate::io::read_plc;\n", 1, false).len(), 1);
    // io in test code only: a test file, or an inline test module.
    assert!(count("use crate::io::read_plc;\n", 2, true).is_empty());
    let inline = "fn f() {}\n#[cfg(test)]\nmod tests {\n    use crate::io::read_plc;\n}\nuse crate::io::X;\n";
    let v = count(inline, 1, false);
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(v[0].starts_with("src/refine/x.rs:6: "), "{v:?}");
    assert_eq!(
        count("mod tests {\n    use crate::io::X;\n}\n", 1, false).len(),
        1
    );
    assert_eq!(count("use crate::improve::X;\n", 2, true).len(), 1);
    // Allowed: lower layers, the layer itself, super paths within the folder, comments, strings.
    assert!(count(
        "use crate::run::params::Params;\nuse crate::refine::X;\n",
        1,
        false
    )
    .is_empty());
    assert!(count("use super::super::mark::Unseeded;\n", 2, false).is_empty());
    assert!(count(
        "mod tests {\n    use super::super::levels::X;\n}\n",
        1,
        false
    )
    .is_empty());
    assert!(count("// crate::improve::finish\n/* crate::api */\n", 1, false).is_empty());
    assert!(count(
        "let s = \"crate::improve\";\nlet c = '{';\nuse crate::geom::X;\n",
        1,
        false
    )
    .is_empty());
    assert!(count(
        "use crate::run::report::ImproveStats; // improve's stats\n",
        1,
        false
    )
    .is_empty());
}
