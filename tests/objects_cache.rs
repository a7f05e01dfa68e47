//! The object meshes' cache is the user's, not the working folder's: two working folders share one
//! download, the first download says what it fetches, and a fetch killed midway leaves nothing a
//! later fetch trips on.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use taction::mesh::{DEB_FILE, ObjectCache, cache_root_from};

fn fetch_in(cwd: &Path, env: &[(&str, &Path)], extra: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_taction"));
    command
        .args(["objects", "fetch"])
        .args(extra)
        .current_dir(cwd)
        .env_remove("TACTION_CACHE")
        .env_remove("XDG_CACHE_HOME");
    for (key, value) in env {
        command.env(key, value);
    }
    command.output().expect("the taction binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|d| {
            d.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

#[test]
fn the_cache_folder_follows_taction_cache_then_xdg_then_home() {
    let os = |s: &'static str| Some(OsStr::new(s));
    assert_eq!(cache_root_from(os("/c"), os("/x"), os("/h")), PathBuf::from("/c"));
    assert_eq!(
        cache_root_from(None, os("/x"), os("/h")),
        PathBuf::from("/x/taction")
    );
    assert_eq!(
        cache_root_from(os(""), os(""), os("/h")),
        PathBuf::from("/h/.cache/taction")
    );
    // XDG: a relative XDG_CACHE_HOME is invalid and ignored.
    assert_eq!(
        cache_root_from(None, os("rel"), os("/h")),
        PathBuf::from("/h/.cache/taction")
    );
}

#[test]
fn two_working_folders_share_one_announced_download() {
    let cache = tempfile::tempdir().unwrap();
    let xdg = cache.path().join("xdg");
    let (one, two) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());

    let first = fetch_in(one.path(), &[("XDG_CACHE_HOME", &xdg)], &[]);
    assert!(first.status.success(), "{}", text(&first.stderr));
    let announce = text(&first.stderr);
    assert!(
        announce.contains("libcgal-demo 5.5.1-2")
            && announce.contains("24.4 MB")
            && announce.contains("from ")
            && announce.contains(&xdg.join("taction/objects").display().to_string()),
        "{announce}"
    );
    let objects = xdg.join("taction/objects");
    ObjectCache::new(&objects).verify().unwrap();
    let deb = objects.join(DEB_FILE);
    let downloaded = std::fs::metadata(&deb).unwrap().modified().unwrap();

    let second = fetch_in(two.path(), &[("XDG_CACHE_HOME", &xdg)], &[]);
    assert!(second.status.success(), "{}", text(&second.stderr));
    assert!(
        text(&second.stdout).contains("already present"),
        "{}",
        text(&second.stdout)
    );
    assert!(
        !text(&second.stderr).contains("downloading"),
        "{}",
        text(&second.stderr)
    );
    assert_eq!(std::fs::metadata(&deb).unwrap().modified().unwrap(), downloaded);
    // Nothing landed in either working folder.
    assert!(entries(one.path()).is_empty() && entries(two.path()).is_empty());
    assert_eq!(
        entries(&objects),
        vec!["cgal-5.5.1-2".to_string(), DEB_FILE.to_string()]
    );

    // TACTION_CACHE overrides XDG: the package given with --deb, no download, no announcement.
    let own = cache.path().join("own");
    let third = fetch_in(
        two.path(),
        &[("XDG_CACHE_HOME", &xdg), ("TACTION_CACHE", &own)],
        &["--deb", deb.to_str().unwrap()],
    );
    assert!(third.status.success(), "{}", text(&third.stderr));
    assert!(
        !text(&third.stderr).contains("downloading"),
        "{}",
        text(&third.stderr)
    );
    ObjectCache::new(own.join("objects")).verify().unwrap();
}

#[test]
fn a_killed_fetchs_staging_folder_is_removed_by_the_next_fetch() {
    let shared = taction::mesh::ensure_fetched().unwrap();
    let root = tempfile::tempdir().unwrap();
    let objects = root.path().join("objects");
    // A process that has exited: its staging folder is abandoned (a killed fetch's leftovers).
    let mut child = Command::new("true").spawn().unwrap();
    let dead = child.id();
    child.wait().unwrap();
    let abandoned = objects.join(format!(".staging-{dead}-1-0"));
    std::fs::create_dir_all(abandoned.join("meshes")).unwrap();
    std::fs::write(abandoned.join(DEB_FILE), b"half a download").unwrap();
    // This process is alive: a concurrent fetch's folder stays.
    let live = objects.join(format!(".staging-{}-2-0", std::process::id()));
    std::fs::create_dir_all(&live).unwrap();

    let run = fetch_in(
        root.path(),
        &[("TACTION_CACHE", root.path())],
        &["--deb", shared.deb_path().to_str().unwrap()],
    );
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert!(!abandoned.exists(), "{:?}", entries(&objects));
    assert!(live.exists());
    ObjectCache::new(&objects).verify().unwrap();
}
