//! The data flow of `src/lib.rs` and `ARCHITECTURE.md`, checked on the source: world -> sensor ->
//! control/explore -> descriptors -> recognizer -> results. Each top-level module may name only the
//! modules listed for it here (in code; doc comments are free to point anywhere), so a `use` that
//! runs back up the flow (recognition reaching into MuJoCo, say) fails this test instead of
//! growing unnoticed.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Modules every module may use: no domain, no MuJoCo.
const LEAVES: [&str; 8] = [
    "atomic", "bodies", "pose", "queue", "rng", "simd", "units", "valid",
];

/// The paper's modules in the order of the flow: world -> sensor -> hand-off -> control/explore ->
/// descriptors -> recognizer.
const DOMAIN: [&str; 9] = [
    "mesh",
    "sim",
    "tactile",
    "dataset",
    "control",
    "explore",
    "describe",
    "locate",
    "recognize",
];

/// For each top-level module, the domain modules it may use besides [`LEAVES`].
fn allowed() -> BTreeMap<&'static str, Vec<&'static str>> {
    BTreeMap::from([
        ("atomic", vec![]),
        ("bodies", vec![]),
        ("pose", vec![]),
        ("queue", vec![]),
        ("rng", vec![]),
        ("simd", vec![]),
        ("units", vec![]),
        ("valid", vec![]),
        ("mesh", vec![]),
        ("sim", vec!["mesh"]),
        ("tactile", vec!["mesh", "sim"]),
        // The hand-off: readings and their file, knowing the tactile image and nothing of MuJoCo.
        ("dataset", vec!["tactile"]),
        ("control", vec!["mesh", "sim", "tactile", "dataset"]),
        ("explore", vec!["mesh", "sim", "tactile", "dataset", "control"]),
        ("describe", vec!["tactile"]),
        // Contact geometry: readings and meshes, nothing of MuJoCo.
        ("locate", vec!["mesh", "tactile", "dataset"]),
        ("recognize", vec!["tactile", "dataset", "describe", "locate"]),
        ("active_touch", DOMAIN.to_vec()),
        // The run framework: it knows the accuracy row it plots, nothing of MuJoCo or the paper.
        ("experiment", vec!["recognize"]),
        (
            "paper",
            [DOMAIN.as_slice(), &["active_touch", "experiment"]].concat(),
        ),
        // Re-exports only, for users: it may name any module, and no module may name it.
        ("prelude", DOMAIN.to_vec()),
    ])
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src is readable") {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The `crate::name` paths named in `text`'s code lines (comment lines skipped).
fn crate_paths(text: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
        let mut rest = line;
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                .collect();
            if !name.is_empty() {
                names.insert(name);
            }
        }
    }
    names
}

#[test]
fn every_module_uses_only_modules_earlier_in_the_flow() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let allowed = allowed();
    let mut violations = Vec::new();
    let mut seen = BTreeSet::new();
    for file in &files {
        let relative = file.strip_prefix(&src).expect("under src");
        let top = relative
            .components()
            .next()
            .and_then(|c| c.as_os_str().to_str())
            .map(|s| s.trim_end_matches(".rs").to_string())
            .expect("a file name");
        let Some(may_use) = allowed.get(top.as_str()) else {
            // lib.rs, main.rs and the command line (`cli`, the binary) sit on top of everything.
            assert!(
                ["lib", "main", "cli"].contains(&top.as_str()),
                "{}: top-level module '{top}' is not in this test's flow; add it where it belongs",
                relative.display()
            );
            continue;
        };
        seen.insert(top.clone());
        let text = std::fs::read_to_string(file).expect("source is readable");
        for used in crate_paths(&text) {
            if used == top || LEAVES.contains(&used.as_str()) || may_use.contains(&used.as_str()) {
                continue;
            }
            violations.push(format!("{} uses crate::{used}", relative.display()));
        }
    }
    assert!(
        violations.is_empty(),
        "imports against the flow:\n{}",
        violations.join("\n")
    );
    for module in allowed.keys() {
        assert!(
            seen.contains(*module),
            "module '{module}' of the flow has no source file"
        );
    }
}

#[test]
fn the_scan_sees_a_use_that_runs_back_up_the_flow() {
    let text = "//! see crate::sim for the world\nuse crate::sim::Scene;\nuse crate::dataset::{Reading};\n";
    let names = crate_paths(text);
    assert_eq!(
        names,
        BTreeSet::from(["sim".to_string(), "dataset".to_string()]),
        "code lines count, comment lines do not"
    );
    assert!(!allowed()["recognize"].contains(&"sim"));
}

/// Pairs of files of one module that use each other and are known, to be untangled: the arm and
/// the scene (the scene owns the arm, the arm moves in the scene). No new pair may join them.
const KNOWN_MUTUAL_USES: [(&str, &str, &str); 1] = [("sim", "arm", "scene")];

#[test]
fn no_two_files_of_a_module_use_each_other() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut found = Vec::new();
    for entry in std::fs::read_dir(&src).expect("src is readable") {
        let dir = entry.expect("directory entry").path();
        if !dir.is_dir() {
            continue;
        }
        let module = dir
            .file_name()
            .and_then(|n| n.to_str())
            .expect("a folder name")
            .to_string();
        // Each file's uses of its siblings, by `super::x` or `crate::module::x`.
        let mut uses: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        let mut files = Vec::new();
        rust_files(&dir, &mut files);
        for file in files.iter().filter(|f| f.parent() == Some(dir.as_path())) {
            let stem = file
                .file_stem()
                .and_then(|s| s.to_str())
                .expect("a file name")
                .to_string();
            let text = std::fs::read_to_string(file).expect("source is readable");
            let mut siblings = BTreeSet::new();
            for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
                for prefix in ["super::".to_string(), format!("crate::{module}::")] {
                    for (at, _) in line.match_indices(&prefix) {
                        let name: String = line[at + prefix.len()..]
                            .chars()
                            .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '_')
                            .collect();
                        if !name.is_empty() && name != stem {
                            siblings.insert(name);
                        }
                    }
                }
            }
            uses.insert(stem, siblings);
        }
        for (a, used) in &uses {
            for b in used {
                let mutual = uses.get(b).is_some_and(|back| back.contains(a));
                if mutual && a < b && a != "mod" && b != "mod" {
                    found.push((module.clone(), a.clone(), b.clone()));
                }
            }
        }
    }
    let known: Vec<(String, String, String)> = KNOWN_MUTUAL_USES
        .iter()
        .map(|(m, a, b)| (m.to_string(), a.to_string(), b.to_string()))
        .collect();
    let new: Vec<_> = found.iter().filter(|f| !known.contains(f)).collect();
    assert!(new.is_empty(), "files that use each other: {new:?}");
    // `experiment` (the framework) and `paper` have none: the circles index <-> merge and
    // context <-> recognition were taken apart.
    assert!(
        found.iter().all(|(m, _, _)| m != "experiment" && m != "paper"),
        "{found:?}"
    );
}

/// The crate's top-level modules that have files of their own (a folder under `src/`), each with
/// the names of those files (`arm` for `sim/arm.rs`, `figure1` for `paper/figure1/mod.rs`). The
/// command line (`cli`) is the binary, not the library.
fn file_modules() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut modules = BTreeMap::new();
    for entry in std::fs::read_dir(&src).expect("src is readable") {
        let dir = entry.expect("directory entry").path();
        let Some(module) = dir.file_name().and_then(|n| n.to_str()).map(str::to_string) else {
            continue;
        };
        if !dir.is_dir() || module == "cli" {
            continue;
        }
        let mut files = BTreeSet::new();
        for file in std::fs::read_dir(&dir).expect("module folder is readable") {
            let path = file.expect("directory entry").path();
            let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
            if path.is_dir() || (path.extension().is_some_and(|e| e == "rs") && stem != "mod") {
                files.insert(stem.to_string());
            }
        }
        modules.insert(module, files);
    }
    modules
}

/// The `pub mod name;` declarations of a module root: each makes a file part of the interface.
/// An inline grouping module (`pub mod pipeline { pub use super::...; }`) is allowed.
fn public_file_modules(root: &str) -> Vec<String> {
    root.lines()
        .map(str::trim)
        .filter(|l| !l.starts_with("//"))
        .filter_map(|l| l.strip_prefix("pub mod "))
        .filter(|rest| !rest.trim_end().ends_with('{'))
        .map(|rest| rest.trim_end_matches(';').trim().to_string())
        .collect()
}

#[test]
fn module_roots_keep_their_files_private() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut public = Vec::new();
    for module in file_modules().keys() {
        let root = std::fs::read_to_string(src.join(module).join("mod.rs")).expect("a module root");
        for file in public_file_modules(&root) {
            public.push(format!("src/{module}/mod.rs: pub mod {file};"));
        }
    }
    assert!(
        public.is_empty(),
        "a module's files are private (`pub(crate) mod`); re-export what users need from its root:\n{}",
        public.join("\n")
    );
}

/// The paths `taction::<module>::<file>::...` in `text`'s code lines that go through one of the
/// module's files instead of its root, also inside a group (`taction::paper::{data::X, Scale}`).
fn deep_paths(text: &str, modules: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    let code: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut found = Vec::new();
    for (at, _) in code.match_indices("taction::") {
        let rest = &code[at + "taction::".len()..];
        let module = ident(rest);
        let Some(files) = modules.get(&module) else {
            continue;
        };
        let Some(after) = rest[module.len()..].strip_prefix("::") else {
            continue;
        };
        // The first segment after the module, or each first segment of a `{...}` group.
        let mut firsts = Vec::new();
        if let Some(group) = after.strip_prefix('{') {
            let mut depth = 1;
            let mut start = true;
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 1 => break,
                    '}' => depth -= 1,
                    ',' if depth == 1 => start = true,
                    c if start && !c.is_whitespace() => {
                        start = false;
                        firsts.push(&group[i..]);
                    }
                    _ => {}
                }
            }
        } else {
            firsts.push(after);
        }
        for first in firsts {
            let name = ident(first);
            if files.contains(&name) && first[name.len()..].starts_with("::") {
                found.push(format!("taction::{module}::{name}::"));
            }
        }
    }
    found
}

#[test]
fn tests_benches_and_the_command_line_use_module_roots() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let modules = file_modules();
    let mut files = vec![root.join("src/main.rs")];
    for dir in [
        "tests",
        "benches",
        "examples",
        "src/cli",
        "plugin/src",
        "python/src",
        "xtask/src",
    ] {
        rust_files(&root.join(dir), &mut files);
    }
    let mut deep = Vec::new();
    // This file's own samples of what the scan looks for are not uses.
    for file in files.iter().filter(|f| !f.ends_with("tests/architecture.rs")) {
        let text = std::fs::read_to_string(file).expect("source is readable");
        for path in deep_paths(&text, &modules) {
            let relative = file.strip_prefix(root).expect("under the root");
            deep.push(format!("{}: {path}", relative.display()));
        }
    }
    assert!(
        deep.is_empty(),
        "{} paths through a module's files; use the module's root:\n{}",
        deep.len(),
        deep.join("\n")
    );
}

#[test]
fn the_scans_see_a_public_file_and_a_deep_path() {
    let modules = BTreeMap::from([(
        "sim".to_string(),
        BTreeSet::from(["arm".to_string(), "mjcf".to_string()]),
    )]);
    let text = "// taction::sim::arm::PAD_SITE in a comment\nuse taction::sim::arm::PAD_SITE;\n\
                use taction::sim::{Scene, mjcf::{Section, numbers}};\nuse taction::sim::Arm;\n";
    assert_eq!(
        deep_paths(text, &modules),
        ["taction::sim::arm::", "taction::sim::mjcf::"]
    );
    let root = "pub(crate) mod arm;\npub mod mjcf;\n/// Grouped.\npub mod pipeline {\n";
    assert_eq!(public_file_modules(root), ["mjcf"]);
}
