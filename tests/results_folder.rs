//! The shipped `results/` folder: every CSV that its index (`results/README.md`) or the paper
//! comparison (`results/PAPER.md`) names exists, parses as a tidy table, and sits beside the
//! `config.json` of the run that made it; every figure PAPER.md discusses links its data.

use std::path::{Path, PathBuf};

fn results() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("results")
}

/// The targets of the markdown links `[text](target)` in `text` that end in `.csv`.
fn csv_links(text: &str) -> Vec<String> {
    let mut links = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find("](") {
        rest = &rest[start + 2..];
        if let Some(end) = rest.find(')') {
            let target = &rest[..end];
            if target.ends_with(".csv") {
                links.push(target.to_string());
            }
            rest = &rest[end..];
        }
    }
    links
}

/// Reads `path` as a CSV with a header and at least one row, every row as long as the header.
fn assert_tidy_csv(path: &Path) {
    let mut reader = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header = reader
        .headers()
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .clone();
    assert!(!header.is_empty(), "{}: no header", path.display());
    let mut rows = 0;
    for record in reader.records() {
        let record = record.unwrap_or_else(|e| panic!("{}: row {}: {e}", path.display(), rows + 1));
        assert_eq!(record.len(), header.len(), "{}: row {}", path.display(), rows + 1);
        rows += 1;
    }
    assert!(rows > 0, "{}: no rows", path.display());
}

/// The `scale` of the run recorded in `config.json` beside `csv`.
fn config_scale(csv: &Path) -> f64 {
    let config = csv.with_file_name("config.json");
    let text = std::fs::read_to_string(&config).unwrap_or_else(|e| panic!("{}: {e}", config.display()));
    let value: serde_json::Value =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", config.display()));
    value["scale"].as_f64().unwrap_or(f64::NAN)
}

#[test]
fn every_csv_the_results_index_names_exists_and_parses() {
    let index = std::fs::read_to_string(results().join("README.md")).expect("results/README.md is shipped");
    let links = csv_links(&index);
    assert!(
        links.len() >= 14,
        "the index links every experiment's CSV: {links:?}"
    );
    for link in &links {
        let path = results().join(link);
        assert!(path.is_file(), "results/README.md links {link}, which is missing");
        assert_tidy_csv(&path);
        assert!(
            path.with_file_name("config.json").is_file(),
            "{link} has no config.json beside it"
        );
    }
}

#[test]
fn every_figure_paper_md_discusses_links_its_csv_from_one_run() {
    let paper = std::fs::read_to_string(results().join("PAPER.md")).expect("results/PAPER.md is shipped");
    let sections: Vec<&str> = paper.split("\n## ").skip(1).collect();
    let figures: Vec<&str> = sections
        .iter()
        .copied()
        .filter(|s| s.starts_with("Fig."))
        .collect();
    assert!(
        figures.len() >= 12,
        "PAPER.md discusses the paper's figures one by one"
    );
    let mut scales = Vec::new();
    for section in figures {
        let title = section.lines().next().unwrap_or_default();
        let links = csv_links(section);
        assert!(!links.is_empty(), "PAPER.md's '{title}' links no CSV");
        for link in links {
            let path = results().join(&link);
            assert!(
                path.is_file(),
                "PAPER.md's '{title}' links {link}, which is missing"
            );
            assert_tidy_csv(&path);
            if path
                .parent()
                .and_then(Path::file_name)
                .is_some_and(|n| n != "exploration")
            {
                scales.push((link, config_scale(&path)));
            }
        }
        assert!(
            section.contains("**Verdict:"),
            "PAPER.md's '{title}' gives a verdict"
        );
    }
    // The shipped results are the paper's data sizes, every one of them.
    for (link, scale) in &scales {
        assert_eq!(
            *scale, 1.0,
            "{link} comes from a run at scale {scale}, not the paper's 1.0"
        );
    }
}
