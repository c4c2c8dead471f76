//! The Python docstrings of `ndtgrid._core` come from its type stubs
//! (`python/ndtgrid/_core.pyi`, numpydoc), the one place they are written:
//! this script copies each class's, method's and function's docstring into
//! `$OUT_DIR/doc/<Class>.<name>.txt` (`<name>.txt` for a module function,
//! `<Class>.txt` for a class), which the binding's items take as their Rust
//! docs (`stub_doc!`), so `help()` shows what editors show. A name the stubs
//! give no docstring gets an empty file.

use std::collections::BTreeMap;
use std::env;
use std::fs;
use std::path::{Path, PathBuf};

fn main() {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let stub = manifest.join("../../python/ndtgrid/_core.pyi");
    println!("cargo:rerun-if-changed={}", stub.display());
    let text = match fs::read_to_string(&stub) {
        Ok(t) => t,
        Err(e) => panic!("reading the stubs {}: {e}", stub.display()),
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap_or_default()).join("doc");
    if let Err(e) = write_docs(&docstrings(&text), &out) {
        panic!("writing the docstrings to {}: {e}", out.display());
    }
}

/// Each documented name of the stubs (`Class`, `Class.method`, `function`)
/// with its docstring, cleaned as `inspect.cleandoc` cleans it.
fn docstrings(text: &str) -> BTreeMap<String, String> {
    let lines: Vec<&str> = text.lines().collect();
    let mut docs = BTreeMap::new();
    let mut class: Option<String> = None;
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        let indent = line.len() - line.trim_start().len();
        let body = line.trim_start();
        if indent == 0 && !body.is_empty() && !body.starts_with('@') && !body.starts_with('#') {
            class = None;
        }
        let name = if let Some(rest) = body.strip_prefix("class ").filter(|_| indent == 0) {
            class = Some(ident(rest).to_string());
            class.clone()
        } else if let Some(rest) = body.strip_prefix("def ") {
            match (&class, indent) {
                (Some(c), 4) => Some(format!("{c}.{}", ident(rest))),
                (None, 0) => Some(ident(rest).to_string()),
                _ => None,
            }
        } else {
            None
        };
        i += 1;
        let Some(name) = name else { continue };
        // The header ends at the line closing its brackets with `:`.
        let mut depth = bracket_depth(line);
        while depth > 0 && i < lines.len() {
            depth += bracket_depth(lines[i]);
            i += 1;
        }
        if let Some(doc) = lines.get(i).and_then(|l| docstring_at(&lines[i..], l)) {
            docs.insert(name, doc);
        } else {
            docs.entry(name).or_default();
        }
    }
    docs
}

/// The identifier a `class` or `def` line names.
fn ident(rest: &str) -> &str {
    let end = rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    &rest[..end]
}

/// Opening minus closing brackets on a line.
fn bracket_depth(line: &str) -> i32 {
    line.chars()
        .map(|c| match c {
            '(' | '[' | '{' => 1,
            ')' | ']' | '}' => -1,
            _ => 0,
        })
        .sum()
}

/// The docstring starting on `first` (the first of `lines`), if it starts one.
fn docstring_at(lines: &[&str], first: &str) -> Option<String> {
    let start = first.trim_start().strip_prefix("\"\"\"")?;
    if let Some(end) = start.find("\"\"\"") {
        return Some(cleandoc(&[&unescape(&start[..end])]));
    }
    let mut parts = vec![unescape(start)];
    for l in &lines[1..] {
        if let Some(end) = l.find("\"\"\"") {
            parts.push(unescape(&l[..end]));
            let parts: Vec<&str> = parts.iter().map(String::as_str).collect();
            return Some(cleandoc(&parts));
        }
        parts.push(unescape(l));
    }
    None
}

/// A line of a (non-raw) Python string as Python reads it: `\\`, `\'` and
/// `\"` are the character escaped; the stubs' docstrings use no other escape.
fn unescape(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        match (c, chars.clone().next()) {
            ('\\', Some(e @ ('\\' | '\'' | '"'))) => {
                out.push(e);
                chars.next();
            }
            _ => out.push(c),
        }
    }
    out
}

/// `inspect.cleandoc`: the first line stripped, the others' common
/// indentation removed, blank lines at either end dropped.
fn cleandoc(lines: &[&str]) -> String {
    let margin = lines[1..]
        .iter()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.len() - l.trim_start().len())
        .min()
        .unwrap_or(0);
    let mut out: Vec<String> = vec![lines[0].trim().to_string()];
    out.extend(
        lines[1..]
            .iter()
            .map(|l| l.get(margin..).unwrap_or("").trim_end().to_string()),
    );
    while out.last().is_some_and(|l| l.is_empty()) {
        out.pop();
    }
    while out.first().is_some_and(|l| l.is_empty()) {
        out.remove(0);
    }
    out.join("\n")
}

fn write_docs(docs: &BTreeMap<String, String>, dir: &Path) -> std::io::Result<()> {
    fs::create_dir_all(dir)?;
    for (name, doc) in docs {
        fs::write(dir.join(format!("{name}.txt")), doc)?;
    }
    Ok(())
}
