//! The shape of the code, checked: imports point one way (no cycle between the library's
//! modules, nor between the files of one module), and the sampler facts have no catch-all arm,
//! so that the compiler names every fact a new sampler must state.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
    files
}

/// The code of a file without its comments and its unit tests.
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The names following `prefix` in `code` (`crate::sampler::…` gives `sampler`).
fn references(code: &str, prefix: &str) -> BTreeSet<String> {
    code.match_indices(prefix)
        .map(|(i, _)| {
            code[i + prefix.len()..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect::<String>()
        })
        .filter(|name| !name.is_empty())
        .collect()
}

/// A cycle of `graph`, if it has one.
fn cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == node) {
            return Some(path[i..].to_vec());
        }
        if done.contains(node) {
            return None;
        }
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(c) = visit(next, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(node.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|n| visit(n, graph, &mut Vec::new(), &mut done))
}

#[test]
fn the_library_modules_import_one_way() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in rust_files(&src) {
        let rel = file.strip_prefix(&src).unwrap();
        let top = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let module = top.trim_end_matches(".rs").to_string();
        if module == "bin" || module == "lib" {
            continue;
        }
        let targets = references(&code(&file), "crate::");
        let entry = graph.entry(module.clone()).or_default();
        entry.extend(targets.into_iter().filter(|t| *t != module));
    }
    assert!(graph.len() > 10, "found {} modules", graph.len());
    assert_eq!(cycle(&graph), None, "an import cycle between modules");
}

#[test]
fn the_files_of_each_module_import_one_way() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    for dir in [
        "spectrum/nufft",
        "predict",
        "predict/fourier",
        "predict/strata",
        "predict/digits",
        "predict/walsh",
        "sampler",
        "integrand",
        "report",
        "render",
        "rate",
    ] {
        let dir = src.join(dir);
        let files: Vec<PathBuf> = rust_files(&dir)
            .into_iter()
            .filter(|f| f.parent() == Some(dir.as_path()) && !f.ends_with("mod.rs"))
            .collect();
        let stem = |f: &Path| f.file_stem().unwrap().to_string_lossy().to_string();
        let names: BTreeSet<String> = files.iter().map(|f| stem(f)).collect();
        let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for file in &files {
            let name = stem(file);
            // `super::x` names a sibling file, or an item the module re-exports.
            let siblings = references(&code(file), "super::");
            graph.entry(name.clone()).or_default().extend(
                siblings
                    .into_iter()
                    .filter(|s| *s != name && names.contains(s)),
            );
        }
        assert_eq!(cycle(&graph), None, "an import cycle in {}", dir.display());
    }
}

#[test]
fn the_sampler_facts_have_no_catch_all_arm() {
    let sampler = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/sampler");
    for file in ["kind.rs", "facts.rs"] {
        let code = code(&sampler.join(file));
        assert!(
            !code.contains("_ =>"),
            "a catch-all arm in src/sampler/{file}"
        );
    }
}

/// Every ignored test says why it does not run by default.
#[test]
fn every_ignored_test_says_why() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for dir in ["src", "tests"] {
        for file in rust_files(&root.join(dir)) {
            let text = std::fs::read_to_string(&file).unwrap();
            assert!(
                !text.lines().any(|l| l.trim() == "#[ignore]"),
                "a bare #[ignore] in {}",
                file.display()
            );
        }
    }
}

/// The analyses name no sampler: they read its facts. The non-test code of `src/predict/`
/// names at most three, each with its reason beside it.
#[test]
fn the_analyses_read_facts_not_names() {
    let predict = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/predict");
    let mut named = Vec::new();
    for file in rust_files(&predict) {
        let text = std::fs::read_to_string(&file).unwrap();
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        for line in code.lines() {
            if line.contains("SamplerKind::") && !line.trim_start().starts_with("//") {
                named.push(format!("{}: {}", file.display(), line.trim()));
            }
        }
    }
    assert!(named.len() <= 3, "{}", named.join("\n"));
}
