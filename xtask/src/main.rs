//! `cargo xtask`: the project's own set-up, so that the README's two commands work on a fresh machine.
//!
//! MuJoCo is a C library; `mujoco-rs` links it dynamically from `MUJOCO_DYNAMIC_LINK_DIR`, which
//! `.cargo/config.toml` points at `.runtime/mujoco/lib`. This task fills that folder from the official
//! PyPI wheel `mujoco==3.17.0` (fetched with pip, the library inside checked against a pinned sha256),
//! then runs cargo. It has no MuJoCo dependency itself, so it builds before the runtime exists
//! (matklad's xtask pattern). A second run finds the checked library and does no network work.

use std::ffi::OsString;
use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use sha2::{Digest, Sha256};

const MUJOCO_VERSION: &str = "3.17.0";
const LIBRARY_IN_WHEEL: &str = "mujoco/libmujoco.so.3.17.0";
const LIBRARY_FILE: &str = "libmujoco.so.3.17.0";
/// sha256 of `libmujoco.so.3.17.0` for x86_64 Linux; identical in the cp311 and cp312 wheels
/// (the wheels' own hashes differ per Python version, the library inside does not).
const LIBRARY_SHA256: &str = "23496b023ee80fb61ab71167e94bc649f9941710fde96b18bb8204fb332523ad";

const USAGE: &str = "\
usage: cargo xtask <task> [args...]

tasks:
  setup          fetch and check the MuJoCo runtime if missing, build the MuJoCo plugin library
                 (target/release/libtaction_covering.so, for Python and MuJoCo's viewer), and make the
                 project venv .venv/ with the Python package `taction` built from this checkout;
                 object meshes are fetched on first use
  runtime        only fetch and check the MuJoCo runtime (what `pip install .` runs first)
  demo [args]    setup, then `cargo run --release -- demo [args]`
  test [args]    setup, then run the whole test suite (`cargo test --workspace [args]`), then each
                 example (`cargo run --release --example NAME`, see examples/), then the Python
                 package's tests (`.venv/bin/python -m pytest python/tests`)
  bench [args]   setup, then `cargo bench [args]`
  run [args]     setup, then `cargo run --release -- [args]` (any taction subcommand)";

fn main() -> ExitCode {
    let mut args = std::env::args_os().skip(1);
    let task = args.next().and_then(|t| t.into_string().ok());
    let rest: Vec<OsString> = args.collect();
    let result = match task.as_deref() {
        Some("setup") => setup(),
        Some("runtime") => ensure_mujoco_runtime(&project_root().join(".runtime")),
        Some("demo") => setup().and_then(|()| {
            let mut a = os(&[
                "run",
                "--release",
                "--quiet",
                "--package",
                "taction",
                "--",
                "demo",
            ]);
            a.extend(rest);
            cargo(&a)
        }),
        Some("run") => setup().and_then(|()| {
            let mut a = os(&["run", "--release", "--quiet", "--package", "taction", "--"]);
            a.extend(rest);
            cargo(&a)
        }),
        Some("test") => setup().and_then(|()| {
            let mut a = os(&["test", "--workspace"]);
            a.extend(rest);
            cargo(&a)?;
            run_examples()?;
            run_python_tests()
        }),
        Some("bench") => setup().and_then(|()| {
            let mut a = os(&["bench", "--package", "taction"]);
            a.extend(rest);
            cargo(&a)
        }),
        Some("help") | Some("--help") | Some("-h") => {
            println!("{USAGE}");
            Ok(())
        }
        _ => Err(format!("unknown or missing task\n{USAGE}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("xtask: {message}");
            ExitCode::FAILURE
        }
    }
}

/// Runs every example of the library (`examples/*.rs`, in name order) as a user would; each checks
/// what it shows and exits non-zero when the check fails.
fn run_examples() -> Result<(), String> {
    let dir = project_root().join("examples");
    let entries = fs::read_dir(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut names: Vec<String> = entries
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|e| e == "rs"))
        .filter_map(|path| path.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    for name in &names {
        cargo(&os(&[
            "run",
            "--release",
            "--quiet",
            "--package",
            "taction",
            "--example",
            name,
        ]))?;
    }
    Ok(())
}

fn os(items: &[&str]) -> Vec<OsString> {
    items.iter().map(OsString::from).collect()
}

fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn setup() -> Result<(), String> {
    ensure_mujoco_runtime(&project_root().join(".runtime"))?;
    build_plugin_library()?;
    install_python_package()
}

/// The project venv `.venv/` with the Python package built from this checkout (`pip install .`,
/// through maturin) and its runtime and development dependencies (`pyproject.toml`'s `dev` extra:
/// maturin, pytest, pandas, pyarrow). The MuJoCo wheel `setup` fetched is offered to pip first, so
/// it is not downloaded twice. The package is rebuilt only when a source it is built from changed
/// since the last install (a stamp in the venv), so a second run does no work.
fn install_python_package() -> Result<(), String> {
    let root = project_root();
    let venv = root.join(".venv");
    let python = venv.join("bin").join("python");
    let succeeds = |args: &[&str]| {
        Command::new(&python)
            .args(args)
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !succeeds(&["-m", "pip", "--version"]) {
        // A venv without pip (made where python3-venv is missing) is made again.
        let _ = fs::remove_dir_all(&venv);
        eprintln!("xtask: making the project venv .venv/ (python3 -m venv)");
        run(Command::new("python3").args(["-m", "venv"]).arg(&venv))
            .map_err(|e| format!("{e}; on Debian and Ubuntu, install python3-venv"))?;
    }
    let stamp_file = venv.join("taction-build.stamp");
    let stamp = python_sources_stamp(&root);
    if fs::read_to_string(&stamp_file).is_ok_and(|s| s == stamp) && succeeds(&["-c", "import taction"]) {
        return Ok(());
    }
    // As in an activated venv: maturin's backend runs the `maturin` program it installed there.
    let path = std::env::join_paths(
        std::iter::once(venv.join("bin"))
            .chain(std::env::var_os("PATH").iter().flat_map(std::env::split_paths)),
    )
    .map_err(|e| format!("PATH: {e}"))?;
    let pip = |args: &[&str]| {
        run(Command::new(&python)
            .env("PATH", &path)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
            .arg("--find-links")
            .arg(root.join(".runtime").join("download"))
            .args(args)
            .current_dir(&root))
    };
    if !succeeds(&["-c", "import maturin"]) {
        pip(&["maturin>=1.5,<2"])?;
    }
    pip(&["--no-build-isolation", ".[dev]"])?;
    fs::write(&stamp_file, stamp).map_err(|e| format!("{}: {e}", stamp_file.display()))
}

/// The newest modification time and the number of the files the Python package is built from.
fn python_sources_stamp(root: &Path) -> String {
    fn visit(path: &Path, newest: &mut std::time::SystemTime, count: &mut usize) {
        if path.file_name().is_some_and(|n| n == "__pycache__") {
            return;
        }
        if path.is_dir() {
            for entry in fs::read_dir(path).into_iter().flatten().flatten() {
                visit(&entry.path(), newest, count);
            }
        } else if let Ok(modified) = fs::metadata(path).and_then(|m| m.modified()) {
            *newest = (*newest).max(modified);
            *count += 1;
        }
    }
    let mut newest = std::time::SystemTime::UNIX_EPOCH;
    let mut count = 0;
    for input in [
        "src",
        "python/src",
        "python/taction",
        "python/Cargo.toml",
        "python/build.rs",
        "python/build_backend.py",
        "Cargo.toml",
        "Cargo.lock",
        "pyproject.toml",
    ] {
        visit(&root.join(input), &mut newest, &mut count);
    }
    let since = newest
        .duration_since(std::time::SystemTime::UNIX_EPOCH)
        .unwrap_or_default();
    format!("{} {count}\n", since.as_nanos())
}

/// Runs the Python package's tests in the project venv.
fn run_python_tests() -> Result<(), String> {
    let root = project_root();
    run(Command::new(root.join(".venv").join("bin").join("python"))
        .args(["-m", "pytest", "-q", "python/tests"])
        .current_dir(&root))
}

fn run(command: &mut Command) -> Result<(), String> {
    let shown = format!("{command:?}");
    let status = command
        .status()
        .map_err(|e| format!("cannot start {shown}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{shown} failed ({status})"))
    }
}

/// Builds the `taction.covering` plugin library in release, so that the README's Python recipe
/// finds `target/release/libtaction_covering.so` after the first command. It shares the release
/// dependency build with `demo`, `run` and `bench`; when nothing changed cargo does no work.
fn build_plugin_library() -> Result<(), String> {
    cargo(&os(&[
        "build",
        "--release",
        "--quiet",
        "--package",
        "taction-plugin",
    ]))?;
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| project_root().join("target"));
    let library = target.join("release").join("libtaction_covering.so");
    if !library.is_file() {
        return Err(format!("the plugin build left no {}", library.display()));
    }
    Ok(())
}

fn cargo(args: &[OsString]) -> Result<(), String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| OsString::from("cargo"));
    let status = Command::new(&cargo)
        .args(args)
        .current_dir(project_root())
        .status()
        .map_err(|e| format!("cannot start cargo: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("cargo {} failed ({status})", display_args(args)))
    }
}

fn display_args(args: &[OsString]) -> String {
    args.iter()
        .map(|a| a.to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join(" ")
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// Makes `<runtime>/mujoco/lib/{libmujoco.so.3.17.0, libmujoco.so}` exist and match the pin.
fn ensure_mujoco_runtime(runtime: &Path) -> Result<(), String> {
    let lib_dir = runtime.join("mujoco").join("lib");
    let library = lib_dir.join(LIBRARY_FILE);
    let link = lib_dir.join("libmujoco.so");
    if let Ok(bytes) = fs::read(&library) {
        if sha256_hex(&bytes) == LIBRARY_SHA256 && link.exists() {
            return Ok(());
        }
        eprintln!(
            "xtask: {} does not match the pinned sha256; fetching it again",
            library.display()
        );
    }
    fs::create_dir_all(&lib_dir).map_err(|e| format!("cannot create {}: {e}", lib_dir.display()))?;
    let download = runtime.join("download");
    fs::create_dir_all(&download).map_err(|e| format!("cannot create {}: {e}", download.display()))?;

    let wheel = match find_wheel(&download) {
        Some(w) => w,
        None => {
            eprintln!("xtask: fetching MuJoCo {MUJOCO_VERSION} from PyPI (wheel mujoco=={MUJOCO_VERSION})");
            let status = Command::new("python3")
                .args(["-m", "pip", "download", "--no-deps", "--only-binary=:all:"])
                .args(["--disable-pip-version-check", "--quiet", "--dest"])
                .arg(&download)
                .arg(format!("mujoco=={MUJOCO_VERSION}"))
                .status()
                .map_err(|e| format!("cannot run `python3 -m pip` (python3 with pip is required): {e}"))?;
            if !status.success() {
                return Err(format!(
                    "`python3 -m pip download mujoco=={MUJOCO_VERSION}` failed ({status})"
                ));
            }
            find_wheel(&download)
                .ok_or_else(|| format!("pip left no mujoco wheel in {}", download.display()))?
        }
    };

    let bytes = read_library_from_wheel(&wheel)?;
    let digest = sha256_hex(&bytes);
    if digest != LIBRARY_SHA256 {
        let _ = fs::remove_file(&wheel);
        return Err(format!(
            "{LIBRARY_IN_WHEEL} in {} has sha256 {digest}, expected {LIBRARY_SHA256}; the wheel was removed, run again",
            wheel.display()
        ));
    }
    let partial = lib_dir.join(format!("{LIBRARY_FILE}.partial"));
    fs::write(&partial, &bytes).map_err(|e| format!("cannot write {}: {e}", partial.display()))?;
    fs::rename(&partial, &library).map_err(|e| format!("cannot write {}: {e}", library.display()))?;
    let _ = fs::remove_file(&link);
    std::os::unix::fs::symlink(LIBRARY_FILE, &link)
        .map_err(|e| format!("cannot link {}: {e}", link.display()))?;
    eprintln!(
        "xtask: MuJoCo {MUJOCO_VERSION} runtime ready in {}",
        lib_dir.display()
    );
    Ok(())
}

fn find_wheel(dir: &Path) -> Option<PathBuf> {
    let mut wheels: Vec<PathBuf> = fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(&format!("mujoco-{MUJOCO_VERSION}-")) && n.ends_with(".whl"))
        })
        .collect();
    wheels.sort();
    wheels.pop()
}

fn read_library_from_wheel(wheel: &Path) -> Result<Vec<u8>, String> {
    let file = fs::File::open(wheel).map_err(|e| format!("cannot open {}: {e}", wheel.display()))?;
    let mut archive =
        zip::ZipArchive::new(file).map_err(|e| format!("{} is not a valid wheel: {e}", wheel.display()))?;
    let mut entry = archive
        .by_name(LIBRARY_IN_WHEEL)
        .map_err(|e| format!("{} holds no {LIBRARY_IN_WHEEL}: {e}", wheel.display()))?;
    let mut bytes = Vec::new();
    entry
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {LIBRARY_IN_WHEEL} from {}: {e}", wheel.display()))?;
    Ok(bytes)
}
