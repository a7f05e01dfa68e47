//! The README a newcomer reads first, and the guides it points to: short enough to read in five
//! minutes, its tables in step with the binary (`taction --help`, `taction experiment list`), and
//! every link between the documents leading to a file and a heading that exist.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn taction(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(args)
        .output()
        .unwrap();
    assert!(out.status.success(), "{args:?}");
    String::from_utf8(out.stdout).unwrap()
}

/// The first cell of every row of the table that follows the line `header`, with backticks
/// removed.
fn first_column(markdown: &str, header: &str) -> Vec<String> {
    let start = markdown
        .find(header)
        .unwrap_or_else(|| panic!("no table headed {header}"));
    markdown[start..]
        .lines()
        .skip(2)
        .take_while(|line| line.starts_with('|'))
        .map(|line| line.split('|').nth(1).unwrap_or("").trim().replace('`', ""))
        .collect()
}

#[test]
fn the_readme_is_a_five_minute_read() {
    let readme = read(&repo().join("README.md"));
    let lines = readme.lines().count();
    assert!(
        lines <= 200,
        "README.md has {lines} lines: measurements and details belong in docs/"
    );
}

#[test]
fn the_command_table_lists_every_command_of_the_binary() {
    let help = taction(&["--help"]);
    let commands: BTreeSet<String> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_owned)
        .collect();
    let readme = read(&repo().join("README.md"));
    let listed: BTreeSet<String> = first_column(&readme, "| command | what it does |")
        .iter()
        .flat_map(|cell| {
            // "train / recognize" and "objects list / fetch / ..." name commands and subcommands.
            cell.split(" / ")
                .filter_map(|part| part.split_whitespace().next().map(str::to_owned))
                .collect::<Vec<_>>()
        })
        .filter(|name| commands.contains(name))
        .collect();
    assert_eq!(
        listed, commands,
        "README's command table against `taction --help`"
    );
}

#[test]
fn the_experiment_table_lists_every_experiment() {
    let list = taction(&["experiment", "list"]);
    let experiments: BTreeSet<String> = list
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_owned)
        .collect();
    let readme = read(&repo().join("README.md"));
    let listed: BTreeSet<String> = first_column(&readme, "| name | figure | varies |")
        .into_iter()
        .collect();
    assert_eq!(
        listed, experiments,
        "README's experiment table against `taction experiment list`"
    );
}

/// GitHub's anchor of a heading: lower case, punctuation but `-` and `_` dropped, spaces to `-`.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn anchors(markdown: &str) -> BTreeSet<String> {
    let mut in_code = false;
    let mut found = BTreeSet::new();
    for line in markdown.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
        } else if !in_code && line.starts_with('#') {
            found.insert(anchor(line.trim_start_matches('#')));
        }
    }
    found
}

/// Every `[text](target)` of `markdown` outside code blocks.
fn links(markdown: &str) -> Vec<String> {
    let mut in_code = false;
    let mut found = Vec::new();
    for line in markdown.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            let Some(end) = after.find(')') else { break };
            found.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    found
}

#[test]
fn every_link_between_the_documents_leads_somewhere() {
    let root = repo();
    let mut documents = vec![
        root.join("README.md"),
        root.join("ARCHITECTURE.md"),
        root.join("results/README.md"),
        root.join("results/PAPER.md"),
        root.join("meshes/README.md"),
        root.join("data/README.md"),
        root.join("fonts/README.md"),
    ];
    for entry in std::fs::read_dir(root.join("docs")).expect("docs/ holds the guides") {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            documents.push(path);
        }
    }
    let mut checked = 0;
    for document in &documents {
        let text = read(document);
        for link in links(&text) {
            if link.starts_with("http://") || link.starts_with("https://") || link.starts_with("mailto:") {
                continue;
            }
            let (file, fragment) = match link.split_once('#') {
                Some((file, fragment)) => (file, Some(fragment)),
                None => (link.as_str(), None),
            };
            let target = if file.is_empty() {
                document.clone()
            } else {
                document.parent().unwrap().join(file)
            };
            assert!(
                target.exists(),
                "{} links {link}: {} does not exist",
                document.display(),
                target.display()
            );
            if let Some(fragment) = fragment {
                assert!(
                    anchors(&read(&target)).contains(fragment),
                    "{} links {link}: {} has no such heading",
                    document.display(),
                    target.display()
                );
            }
            checked += 1;
        }
    }
    assert!(checked >= 10, "only {checked} links found");
}

#[test]
fn the_project_carries_its_licence_and_citation() {
    let root = repo();
    let manifest = read(&root.join("Cargo.toml"));
    assert!(manifest.contains("license = \"Apache-2.0\""));
    let licence = read(&root.join("LICENSE"));
    assert!(licence.contains("Apache License") && licence.contains("Version 2.0, January 2004"));
    let citation = read(&root.join("CITATION.cff"));
    for field in [
        "cff-version: 1.2.0",
        "license: Apache-2.0",
        "preferred-citation:",
        "doi: 10.1109/TRO.2011.2125350",
        "family-names: Pezzementi",
    ] {
        assert!(citation.contains(field), "CITATION.cff lacks {field}");
    }
    let version = manifest
        .lines()
        .find_map(|l| l.strip_prefix("version = \""))
        .and_then(|v| v.strip_suffix('"'))
        .unwrap();
    assert!(
        citation.contains(&format!("version: {version}")),
        "CITATION.cff's version is the crate's ({version})"
    );
}
