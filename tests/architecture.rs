//! The data flow of `src/lib.rs` and `ARCHITECTURE.md`, checked on the source: world -> sensor ->
//! control/explore -> descriptors -> recognizer -> results. Each top-level module may name only the
//! modules listed for it here (in code; doc comments are free to point anywhere), so a `use` that
//! runs back up the flow (recognition reaching into MuJoCo, say) fails this test instead of
//! growing unnoticed.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Modules every module may use: no domain, no MuJoCo.
const LEAVES: [&str; 9] = [
    "atomic", "bodies", "pose", "queue", "rng", "simd", "stats", "units", "valid",
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
        ("stats", vec![]),
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

/// The module paths `text`'s code names through `crate::`, `super::` (resolved from `module`, the
/// file's own module path) and `self::`, each expanded through its `{...}` groups: `use
/// super::{TriMesh, obj::parse as p}` in `mesh/load.rs` names `[mesh, TriMesh]` and `[mesh, obj,
/// parse]`. Code only: comment lines, and the `#[cfg(test)]` module that ends a file (a test may
/// reach anywhere in its own module), are skipped.
fn named_paths(text: &str, module: &[String]) -> Vec<Vec<String>> {
    let code: String = text
        .lines()
        .take_while(|l| l.trim() != "#[cfg(test)]")
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    let mut out = Vec::new();
    for keyword in ["crate::", "super::", "self::"] {
        for (at, _) in code.match_indices(keyword) {
            let before = code[..at].chars().next_back();
            if before.is_some_and(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | ':' | '$')) {
                continue; // inside a longer path (`super::super::`) or a macro's `$crate`
            }
            let mut rest = &code[at + keyword.len()..];
            let base: &[String] = match keyword {
                "crate::" => &[],
                "self::" => module,
                _ => {
                    let mut up = 1;
                    while let Some(more) = rest.strip_prefix("super::") {
                        rest = more;
                        up += 1;
                    }
                    &module[..module.len().saturating_sub(up)]
                }
            };
            use_tree(rest, base, &mut out);
        }
    }
    out
}

/// Expands the use tree at the start of `rest` (`a::b`, `a::{b, c::{d}}`, `a as x`) under `prefix`
/// into `out`; returns the bytes it read.
fn use_tree(rest: &str, prefix: &[String], out: &mut Vec<Vec<String>>) -> usize {
    let mut path = prefix.to_vec();
    let mut at = 0;
    loop {
        at += rest[at..].len() - rest[at..].trim_start().len();
        if rest[at..].starts_with('{') {
            at += 1;
            loop {
                at += use_tree(&rest[at..], &path, out);
                // On to the next item of the group, past an `as` alias; or out of it.
                let mut depth = 0;
                let mut next = None;
                for (i, c) in rest[at..].char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' if depth > 0 => depth -= 1,
                        ',' | '}' if depth == 0 => {
                            next = Some((i, c));
                            break;
                        }
                        _ => {}
                    }
                }
                match next {
                    Some((i, ',')) => at += i + 1,
                    Some((i, _)) => return at + i + 1,
                    None => return rest.len(),
                }
            }
        }
        let name: String = rest[at..]
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        if name.is_empty() {
            break;
        }
        at += name.len();
        path.push(name);
        match rest[at..].strip_prefix("::") {
            Some(_) => at += 2,
            None => break,
        }
    }
    if path.len() > prefix.len() {
        out.push(path);
    }
    at
}

/// The files of the module at `folder` (module path `base`) as nodes, each a file directly in it
/// (its stem) or a folder of files (its name), with the nodes each uses. The root (`mod.rs`,
/// `lib.rs`) re-exports its files for users and is no node.
fn file_graph(folder: &Path, base: &[String]) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(folder, &mut files);
    let module_path = |file: &Path| -> Vec<String> {
        let relative = file.strip_prefix(folder).expect("under the folder");
        let mut path = base.to_vec();
        path.extend(
            relative
                .with_extension("")
                .iter()
                .map(|c| c.to_string_lossy().into_owned()),
        );
        if path.last().is_some_and(|l| l == "mod" || l == "lib") {
            path.pop();
        }
        path
    };
    let nodes: BTreeSet<String> = files
        .iter()
        .filter_map(|f| module_path(f).get(base.len()).cloned())
        .collect();
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in &files {
        let module = module_path(file);
        let Some(node) = module.get(base.len()).cloned() else {
            continue;
        };
        let text = std::fs::read_to_string(file).expect("source is readable");
        let used = graph.entry(node.clone()).or_default();
        for path in named_paths(&text, &module) {
            if path.len() > base.len() && path[..base.len()] == *base {
                let other = &path[base.len()];
                if *other != node && nodes.contains(other) {
                    used.insert(other.clone());
                }
            }
        }
    }
    graph
}

/// The circles of `graph`: its strongly connected components of more than one node (Tarjan).
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct Search<'g> {
        graph: &'g BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'g str, usize>,
        low: BTreeMap<&'g str, usize>,
        stack: Vec<&'g str>,
        found: Vec<Vec<String>>,
    }
    impl<'g> Search<'g> {
        fn visit(&mut self, node: &'g str) {
            let index = self.index.len();
            self.index.insert(node, index);
            self.low.insert(node, index);
            self.stack.push(node);
            for next in self.graph.get(node).into_iter().flatten() {
                let next = next.as_str();
                if !self.index.contains_key(next) {
                    self.visit(next);
                    let low = self.low[node].min(self.low[next]);
                    self.low.insert(node, low);
                } else if self.stack.contains(&next) {
                    let low = self.low[node].min(self.index[next]);
                    self.low.insert(node, low);
                }
            }
            if self.low[node] == self.index[node] {
                let at = self.stack.iter().rposition(|n| *n == node).expect("on the stack");
                let mut component: Vec<String> =
                    self.stack.split_off(at).into_iter().map(String::from).collect();
                if component.len() > 1 {
                    component.sort();
                    self.found.push(component);
                }
            }
        }
    }
    let mut search = Search {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        found: Vec::new(),
    };
    for node in graph.keys() {
        if !search.index.contains_key(node.as_str()) {
            search.visit(node);
        }
    }
    search.found.sort();
    search.found
}

/// Every module of files (each folder of `src/`, and the Python package's crate `python/src`) with
/// the circles among its files.
fn module_circles() -> Vec<(String, Vec<Vec<String>>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut modules = vec![("python/src".to_string(), root.join("python/src"), Vec::new())];
    for entry in std::fs::read_dir(root.join("src")).expect("src is readable") {
        let dir = entry.expect("directory entry").path();
        if dir.is_dir() {
            let name = dir
                .file_name()
                .and_then(|n| n.to_str())
                .expect("a folder name")
                .to_string();
            modules.push((format!("src/{name}"), dir, vec![name]));
        }
    }
    modules
        .into_iter()
        .map(|(name, dir, base)| (name, circles(&file_graph(&dir, &base))))
        .filter(|(_, found)| !found.is_empty())
        .collect()
}

#[test]
fn no_module_has_a_circle_among_its_files() {
    let found = module_circles();
    assert!(
        found.is_empty(),
        "files that use each other, directly or around a circle (split what ties the circle: \
         a type both sides need into a file of its own, below them):\n{found:#?}"
    );
}

#[test]
fn the_circle_scan_reads_groups_aliases_and_parents_and_sees_a_long_circle() {
    let module = ["mesh".to_string(), "load".to_string()];
    let text = "//! crate::mesh::stl in a comment\nuse super::{TriMesh, obj::{parse as p, Obj}, off};\n\
                use crate::mesh::stl::Stl;\nfn f() { super::super::sim::x(); self::g(); }\n\
                #[cfg(test)]\nmod tests { use super::ply; }\n";
    let named: BTreeSet<String> = named_paths(text, &module).iter().map(|p| p.join("::")).collect();
    let expected = [
        "mesh::TriMesh",
        "mesh::obj::parse",
        "mesh::obj::Obj",
        "mesh::off",
        "mesh::stl::Stl",
        "sim::x",
        "mesh::load::g",
    ];
    assert_eq!(named, expected.iter().map(|s| s.to_string()).collect());
    let graph = |edges: &[(&str, &str)]| {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    // Three files around a circle, a fourth hanging off it, and a line that closes nothing.
    let found = circles(&graph(&[
        ("bag", "calibration"),
        ("calibration", "evaluate"),
        ("evaluate", "bag"),
        ("evaluate", "confusion"),
    ]));
    assert_eq!(
        found,
        vec![vec!["bag".to_string(), "calibration".into(), "evaluate".into()]]
    );
    assert!(circles(&graph(&[("a", "b"), ("b", "c"), ("a", "c")])).is_empty());
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
    let mut found = Vec::new();
    for (at, _) in code.match_indices("taction::") {
        let mut paths = Vec::new();
        use_tree(&code[at + "taction::".len()..], &[], &mut paths);
        // A path that goes on past a file of its module (`sim::arm::PAD_SITE`), once per use.
        let mut deep = BTreeSet::new();
        for path in &paths {
            if let [module, file, _, ..] = path.as_slice()
                && modules.get(module).is_some_and(|files| files.contains(file))
                && deep.insert((module.clone(), file.clone()))
            {
                found.push(format!("taction::{module}::{file}::"));
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

/// The longest a function may be: beyond it, a function does several things that want names.
const MAX_FUNCTION_LINES: usize = 80;

/// Every function of `text` (rustfmt's layout: a `fn` item's body closes on a line holding its
/// own indentation and `}`) with its first line (1-based) and its length in lines, signature,
/// body and closing brace counted.
fn function_lengths(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut found = Vec::new();
    for (start, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let indent = &line[..line.len() - trimmed.len()];
        let item = trimmed
            .split_once("fn ")
            .filter(|(before, _)| {
                before.split_whitespace().all(|w| {
                    ["pub", "const", "async", "unsafe", "extern", "\"C\""].contains(&w)
                        || w.starts_with("pub(")
                })
            })
            .map(|(_, after)| after);
        let Some(name) = item.and_then(|rest| rest.split(['(', '<']).next()) else {
            continue;
        };
        // A declaration without a body (a trait's) ends with `;` before any `{`.
        let Some(open) = (start..lines.len()).find(|&i| lines[i].trim_end().ends_with(['{', ';'])) else {
            continue;
        };
        if lines[open].trim_end().ends_with(';') {
            continue;
        }
        let closing = format!("{indent}}}");
        if lines[open].trim_end().ends_with("{}") {
            continue;
        }
        if let Some(end) = (open + 1..lines.len()).find(|&i| lines[i].trim_end() == closing) {
            found.push((name.to_string(), start + 1, end - start + 1));
        }
    }
    found
}

#[test]
fn no_function_in_the_library_or_the_bindings_is_over_80_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    rust_files(&root.join("python/src"), &mut files);
    let mut long = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (name, line, length) in function_lengths(&text) {
            if length > MAX_FUNCTION_LINES {
                let shown = file.strip_prefix(root).unwrap_or(file).display();
                long.push(format!("{shown}:{line} {name}: {length} lines"));
            }
        }
    }
    assert!(files.len() > 100, "the scan found {} files", files.len());
    assert!(
        long.is_empty(),
        "functions over {MAX_FUNCTION_LINES} lines (split them into steps with names):\n{}",
        long.join("\n")
    );
}

#[test]
fn the_length_scan_counts_a_function_from_its_signature_to_its_closing_brace() {
    let body: String = (0..79).map(|i| format!("        let _x{i} = {i};\n")).collect();
    let text = format!(
        "impl A {{\n    pub(crate) fn long(\n        a: u8,\n    ) -> u8 {{\n{body}    }}\n\n    fn short() {{}}\n}}\n\
         trait T {{\n    fn declared(&self);\n}}\nfn free() -> u8 {{\n    1\n}}\n"
    );
    assert_eq!(
        function_lengths(&text),
        [("long".to_string(), 2, 83), ("free".to_string(), 91, 3)]
    );
}

/// The requests the library owns (issue 72): each was once assembled again at an edge, by the
/// command line (`src/cli`) and by the Python bindings (`python/src`); a spelling of one there is
/// a twin growing back. Each entry: what an edge must not write, and the library's one place for it.
const OWNED_BY_THE_LIBRARY: [(&str, &str); 8] = [
    (
        "CollectMode::",
        "explore::CollectRequest::of_mode (one collect request keyed by mode)",
    ),
    (
        "TrainConfig {",
        "recognize::train_recognizer (one training entry, single or fused)",
    ),
    ("FusedModel::fit", "recognize::train_recognizer"),
    (
        "PlannerConfig {",
        "PlannerConfig::exploring and CollectPlan::planner_for",
    ),
    (
        ".collect_plan(",
        "active_touch::ArmTrainingRecipe::train (the demo's and the environment's model)",
    ),
    (
        "with_arm_and_table(",
        "tactile::arm_with_sensor (one arm-with-sensor scene)",
    ),
    ("add_sensor(", "tactile::arm_with_sensor"),
    (
        "\"covering\"",
        "tactile::SENSOR_NAME (the sensor users read as m.sensor(\"tactile\"))",
    ),
];

/// The lines of `text` that are code: comments may name anything.
fn code_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .filter(|(_, line)| !line.trim_start().starts_with("//"))
}

fn edge_twins(files: &[(String, String)]) -> Vec<String> {
    let mut found = Vec::new();
    for (shown, text) in files {
        for (number, line) in code_lines(text) {
            for (spelling, owner) in OWNED_BY_THE_LIBRARY {
                if line.contains(spelling) {
                    found.push(format!("{shown}:{} writes `{spelling}`: use {owner}", number + 1));
                }
            }
        }
    }
    found
}

#[test]
fn the_edges_build_no_request_the_library_owns() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut paths = Vec::new();
    rust_files(&root.join("src/cli"), &mut paths);
    rust_files(&root.join("python/src"), &mut paths);
    let files: Vec<(String, String)> = paths
        .iter()
        .map(|p| {
            let shown = p.strip_prefix(root).unwrap_or(p).display().to_string();
            (shown, std::fs::read_to_string(p).unwrap())
        })
        .collect();
    assert!(files.len() > 20, "the scan found {} edge files", files.len());
    let twins = edge_twins(&files);
    assert!(
        twins.is_empty(),
        "the edges rebuild what the library owns:\n{}",
        twins.join("\n")
    );
}

#[test]
fn the_twin_scan_sees_a_request_built_at_an_edge_but_not_one_named_in_a_comment() {
    let files = [(
        "src/cli/x.rs".to_string(),
        "/// Builds no `TrainConfig { .. }` itself.\nfn f() {\n    let c = TrainConfig { k: 3 };\n    let s = \"covering\";\n}\n"
            .to_string(),
    )];
    let twins = edge_twins(&files);
    assert_eq!(twins.len(), 2, "{twins:?}");
    assert!(
        twins[0].starts_with("src/cli/x.rs:3 writes `TrainConfig {`"),
        "{}",
        twins[0]
    );
    assert!(
        twins[1].starts_with("src/cli/x.rs:4 writes `\"covering\"`"),
        "{}",
        twins[1]
    );
}
