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

/// The experiment folders under `root` that hold an accuracy table (`<name>/<name>.csv` whose
/// header starts `experiment,descriptor`), with that table.
fn accuracy_tables(root: &Path) -> Vec<(String, PathBuf)> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(root).unwrap_or_else(|e| panic!("{}: {e}", root.display())) {
        let dir = entry.expect("a directory entry").path();
        let Some(name) = dir.file_name().and_then(|n| n.to_str()).map(str::to_string) else {
            continue;
        };
        let csv = dir.join(format!("{name}.csv"));
        let header = std::fs::read_to_string(&csv)
            .ok()
            .and_then(|t| t.lines().next().map(str::to_string));
        if header.is_some_and(|h| h.starts_with("experiment,descriptor,")) {
            found.push((name, csv));
        }
    }
    found.sort();
    found
}

/// Every shipped accuracy table (the run's and the neighbour codebook's) has one column per factor
/// between `descriptor` and `trial`, each cell one level (no `parameter`/`value` pair, no packed
/// `validation 6x6`, no empty cell); its per-object table is there, or the index says why not.
#[test]
fn shipped_accuracy_tables_have_one_column_per_factor_and_account_for_per_object_rows() {
    let mut tables = accuracy_tables(&results());
    tables.extend(accuracy_tables(&results().join("knn")));
    assert!(tables.len() >= 15, "every recognition experiment: {tables:?}");
    for (name, csv) in &tables {
        let mut reader = csv::Reader::from_path(csv).unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
        let header = reader.headers().expect("a header").clone();
        let trial = header
            .iter()
            .position(|c| c == "trial")
            .unwrap_or_else(|| panic!("{}: no trial column", csv.display()));
        let factors: Vec<&str> = header.iter().take(trial).skip(2).collect();
        assert!(
            !factors.iter().any(|c| *c == "parameter" || *c == "value"),
            "{}: factor columns {factors:?}",
            csv.display()
        );
        for record in reader.records() {
            let record = record.expect("a CSV record");
            for (k, column) in factors.iter().enumerate() {
                let cell = &record[2 + k];
                assert!(
                    !cell.is_empty() && !cell.contains(char::is_whitespace),
                    "{}: {column} = '{cell}' is not one level",
                    csv.display()
                );
            }
        }
        let per_object = csv.with_file_name(format!("{name}_per_object.csv"));
        let root = csv.parent().and_then(Path::parent).expect("the results root");
        let index = std::fs::read_to_string(root.join("README.md")).expect("the index");
        assert!(
            per_object.is_file() || index.contains(&format!("`{name}_per_object.csv` is not here")),
            "{name}: neither {} nor a word on its absence in {}/README.md",
            per_object.display(),
            root.display()
        );
    }
    let validation = csv::Reader::from_path(results().join("validation/validation.csv"))
        .expect("validation.csv")
        .headers()
        .expect("a header")
        .clone();
    assert_eq!(
        validation.iter().take(5).collect::<Vec<_>>(),
        ["experiment", "descriptor", "data", "resolution", "trial"]
    );
}
