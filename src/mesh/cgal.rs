//! The ten real meshes of the 3D object set, fetched from Debian's `libcgal-demo` package (CGAL's
//! demo data; files without a copyright notice are CC0 per the package's copyright file) into the
//! user's cache folder, pinned by checksums.
//!
//! The cache is shared by every working folder: `$TACTION_CACHE/objects` when that variable is set,
//! else `$XDG_CACHE_HOME/taction/objects`, else `~/.cache/taction/objects` (the XDG base directory
//! convention), so a second checkout or a run from another folder downloads nothing. The first
//! download says on stderr what it fetches, from where and how large.
//!
//! The paper used ten Princeton Shape Benchmark models (Sec. V-B, Fig. 5), which cannot be obtained
//! here; these ten cover a similar range of surface character: organic scans (dragon, bunny, hand),
//! animal and character models (elephant, cow, triceratops, camel, Homer) and two CAD parts
//! (fandisk, rotor) with sharp creases and flat faces.
//!
//! Fetching: `apt-get download libcgal-demo=5.5.1-2` (after `apt-get update` if apt does not know
//! the package yet), check the .deb's SHA-256, read its file system with `dpkg-deb --fsys-tarfile`,
//! find `usr/share/doc/libcgal-dev/data.tar.gz` in it and extract only the ten `data/meshes/*.off`
//! files, checking each one's SHA-256. Everything is staged in a private folder and moved into
//! place with one atomic rename, so several processes may fetch at once: the first rename wins and
//! the others find a complete, verified cache.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{SystemTime, UNIX_EPOCH};

use super::checksum::{sha256_file, sha256_hex};
use super::error::MeshError;
use super::load::{LoadedMesh, MeshFormat, parse};
use super::normalise::UpAxis;

/// The Debian package and version the meshes come from.
pub const PACKAGE: &str = "libcgal-demo";
pub const PACKAGE_VERSION: &str = "5.5.1-2";
/// File name `apt-get download` gives the package.
pub const DEB_FILE: &str = "libcgal-demo_5.5.1-2_all.deb";
/// SHA-256 of [`DEB_FILE`] (Debian bookworm).
pub const DEB_SHA256: &str = "78b09b23d4d6d1bf15552a1060b419ab3fc09918486462faed197e5fc6ac3735";
const DATA_TARBALL: &str = "usr/share/doc/libcgal-dev/data.tar.gz";
const MESH_FOLDER: &str = "data/meshes/";
/// Size of [`DEB_FILE`], bytes (announced before a download).
pub const DEB_BYTES: u64 = 24_358_884;
/// Environment variable naming taction's cache folder; it overrides the platform's.
pub const CACHE_ENV: &str = "TACTION_CACHE";
/// The object meshes' folder inside taction's cache folder.
pub const OBJECTS_SUBDIR: &str = "objects";
/// A staging folder left by a fetch this old is abandoned whatever its process id says.
const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(3600);

/// How to fill the cache, for messages.
pub const FETCH_HINT: &str = "run `taction objects fetch` (or `cargo run --release -- objects fetch`) \
     to download Debian's libcgal-demo 5.5.1-2 and extract them";

/// One mesh of the set: its object name, file in the package, checksum, and which axis its author
/// used as up (so it rests on the table in its natural pose).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CgalMesh {
    pub name: &'static str,
    pub file: &'static str,
    pub sha256: &'static str,
    pub up: UpAxis,
    pub description: &'static str,
}

/// The ten meshes, in the order of the object set.
pub const CGAL_MESHES: [CgalMesh; 10] = [
    CgalMesh {
        name: "dragon",
        file: "ChineseDragon-10kv.off",
        sha256: "f633bdfaac7a0f99e0fab668c34862f0c26f341cfdb4665bab282d79b788db02",
        up: UpAxis::Y,
        description: "'Chinese dragon' statue (a guardian lion), 10k vertices: curls, mane, deep folds",
    },
    CgalMesh {
        name: "bunny",
        file: "bunny00.off",
        sha256: "ab651cb04955c161efaeb079035a1e5e1f0e0d1f816a2df67beaea68f393ff2b",
        up: UpAxis::Y,
        description: "Stanford bunny scan, 38k vertices: smooth, bumpy scan surface",
    },
    CgalMesh {
        name: "elephant",
        file: "elephant.off",
        sha256: "be4e1ea68f5f840a3d2ada69d828222e76a57d9e25b21e19a9deacd3f2328e02",
        up: UpAxis::Y,
        description: "elephant, 2.8k vertices: coarse facets, trunk and ears",
    },
    CgalMesh {
        name: "cow",
        file: "cow.off",
        sha256: "1c5a25c3047fc6b14dd0c962d3562b1796671422ab4634f9d46f9f23814cd54a",
        up: UpAxis::Y,
        description: "cow, 2.9k vertices: smooth body, thin legs and horns",
    },
    CgalMesh {
        name: "triceratops",
        file: "triceratops.off",
        sha256: "0fb444933884486a09eb4329a832f15ab792590f2a5bb75385d157e654ddbf5c",
        up: UpAxis::Y,
        description: "triceratops, 2.8k vertices: horns, frill, ridges",
    },
    CgalMesh {
        name: "homer",
        file: "homer.off",
        sha256: "99396cceb6f97e9681545d5c718d4ed87da3ceb78d22afb0218d570e9f0a0873",
        up: UpAxis::Y,
        description: "Homer Simpson figure, 4.9k vertices: round, smooth",
    },
    CgalMesh {
        name: "hand",
        file: "hand.off",
        sha256: "cfcf1562726167ca704a091a8651bfd1d72f6eb96b4b2819321f0520721b35c7",
        up: UpAxis::Z,
        description: "human hand, 1.2k vertices: fingers, knuckles",
    },
    CgalMesh {
        name: "fandisk",
        file: "fandisk.off",
        sha256: "edffb263f037b023757259befd5532fccb48bdc3c35a1da2e11e235a647bd050",
        up: UpAxis::Y,
        description: "fandisk CAD part, 6.5k vertices: flat faces, sharp creases, fillets",
    },
    CgalMesh {
        name: "rotor",
        file: "rotor.off",
        sha256: "8db85ca5041eef6d952e48f0553a25fddb42f237b80a37b7aff096b8df3aca32",
        up: UpAxis::X,
        description: "rotor CAD part, 600 vertices: a ring with radial slots",
    },
    CgalMesh {
        name: "camel",
        file: "camel.off",
        sha256: "9ac960a9fee27e6fcc6baaa2340260834625084ee20f4a97194212404e650a22",
        up: UpAxis::Z,
        description: "camel, 9.8k vertices: humps, long neck and legs",
    },
];

/// The mesh of the set named `name`.
pub fn cgal_mesh(name: &str) -> Option<&'static CgalMesh> {
    CGAL_MESHES.iter().find(|m| m.name == name)
}

/// taction's cache folder from the environment's values: `taction_cache` (`$TACTION_CACHE`) when
/// set, else `xdg_cache_home/taction` (`$XDG_CACHE_HOME`, used only when absolute, as the XDG base
/// directory specification says), else `home/.cache/taction`, else `taction-cache` in the system's
/// temporary folder (no home at all). Empty values count as unset.
pub fn cache_root_from(
    taction_cache: Option<&std::ffi::OsStr>,
    xdg_cache_home: Option<&std::ffi::OsStr>,
    home: Option<&std::ffi::OsStr>,
) -> PathBuf {
    let set = |v: Option<&std::ffi::OsStr>| v.filter(|v| !v.is_empty()).map(PathBuf::from);
    if let Some(dir) = set(taction_cache) {
        return dir;
    }
    if let Some(xdg) = set(xdg_cache_home).filter(|p| p.is_absolute()) {
        return xdg.join("taction");
    }
    match set(home) {
        Some(home) => home.join(".cache").join("taction"),
        None => std::env::temp_dir().join("taction-cache"),
    }
}

/// taction's cache folder for this process's environment (see [`cache_root_from`]).
pub fn cache_root() -> PathBuf {
    cache_root_from(
        std::env::var_os(CACHE_ENV).as_deref(),
        std::env::var_os("XDG_CACHE_HOME").as_deref(),
        std::env::var_os("HOME").as_deref(),
    )
}

/// The cache of fetched meshes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjectCache {
    root: PathBuf,
}

/// Removes a staging folder however the fetch ends.
struct Staging(PathBuf);

impl Drop for Staging {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A folder-name suffix no other fetch uses: process id, time, and a per-process counter (threads of
/// one test binary may fetch at the same time).
fn unique_suffix() -> String {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    format!("{}-{nanos}-{n}", std::process::id())
}

impl ObjectCache {
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self { root: root.into() }
    }

    /// The user's cache: the `objects` folder of [`cache_root`], whatever the current directory.
    pub fn from_env() -> Self {
        Self::new(cache_root().join(OBJECTS_SUBDIR))
    }

    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The folder holding the extracted meshes.
    pub fn mesh_dir(&self) -> PathBuf {
        self.root.join(format!("cgal-{PACKAGE_VERSION}"))
    }

    pub fn mesh_path(&self, mesh: &CgalMesh) -> PathBuf {
        self.mesh_dir().join(mesh.file)
    }

    /// The cached .deb, kept so a damaged mesh can be extracted again without a download.
    pub fn deb_path(&self) -> PathBuf {
        self.root.join(DEB_FILE)
    }

    /// Checks that all ten files are present with their checksums.
    pub fn verify(&self) -> Result<(), MeshError> {
        for mesh in &CGAL_MESHES {
            let path = self.mesh_path(mesh);
            if !path.is_file() {
                return Err(self.not_fetched());
            }
            check_sha256(&path, &sha256_file(&path)?, mesh.sha256)?;
        }
        Ok(())
    }

    fn not_fetched(&self) -> MeshError {
        MeshError::NotFetched {
            set: "CGAL".into(),
            dir: self.mesh_dir(),
            hint: FETCH_HINT.into(),
        }
    }

    /// Loads one cached mesh (as authored: no rescaling), after checking its checksum.
    pub fn load(&self, mesh: &CgalMesh) -> Result<LoadedMesh, MeshError> {
        let path = self.mesh_path(mesh);
        let bytes = std::fs::read(&path).map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => self.not_fetched(),
            _ => MeshError::Io {
                path: path.clone(),
                source: e,
            },
        })?;
        check_sha256(&path, &sha256_hex(&bytes), mesh.sha256)?;
        parse(&bytes, MeshFormat::Off, &path)
    }

    /// Fetches the meshes unless the cache already holds them all, verified.
    pub fn ensure_fetched(&self) -> Result<(), MeshError> {
        match self.verify() {
            Ok(()) => Ok(()),
            Err(_) => self.fetch(None),
        }
    }

    /// Fills the cache from `deb` (a downloaded `libcgal-demo_5.5.1-2_all.deb`), or from the cached
    /// .deb, or by downloading it with apt. Replaces a damaged cache.
    pub fn fetch(&self, deb: Option<&Path>) -> Result<(), MeshError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| MeshError::Io { path, source }
        };
        std::fs::create_dir_all(&self.root).map_err(io(&self.root))?;
        self.remove_abandoned_staging();
        let staging = Staging(self.root.join(format!(".staging-{}", unique_suffix())));
        std::fs::create_dir_all(&staging.0).map_err(io(&staging.0))?;

        let deb_path = match deb {
            Some(path) => path.to_path_buf(),
            None if self.deb_path().is_file() && sha256_file(&self.deb_path())? == DEB_SHA256 => {
                self.deb_path()
            }
            None => {
                announce_download(&self.root);
                apt_download(&staging.0)?;
                let downloaded = staging.0.join(DEB_FILE);
                check_sha256(&downloaded, &sha256_file(&downloaded)?, DEB_SHA256)?;
                std::fs::rename(&downloaded, self.deb_path()).map_err(io(&self.deb_path()))?;
                self.deb_path()
            }
        };
        check_sha256(&deb_path, &sha256_file(&deb_path)?, DEB_SHA256)?;

        let meshes = staging.0.join("meshes");
        std::fs::create_dir_all(&meshes).map_err(io(&meshes))?;
        extract_meshes(&deb_path, &meshes)?;
        for mesh in &CGAL_MESHES {
            let path = meshes.join(mesh.file);
            check_sha256(&path, &sha256_file(&path)?, mesh.sha256)?;
        }

        let target = self.mesh_dir();
        if std::fs::rename(&meshes, &target).is_ok() {
            return Ok(());
        }
        // Another process got there first, or the cache is damaged: keep a verified one.
        if self.verify().is_ok() {
            return Ok(());
        }
        let damaged = self.root.join(format!(".damaged-{}", unique_suffix()));
        std::fs::rename(&target, &damaged).map_err(io(&target))?;
        let _cleanup = Staging(damaged);
        std::fs::rename(&meshes, &target).map_err(io(&target))?;
        Ok(())
    }

    /// Removes the staging and damaged-cache folders of fetches whose process is gone (killed
    /// mid-fetch, so their own clean-up never ran) or that are older than an hour. Folders of
    /// live fetches are left alone: several processes may fetch at once.
    fn remove_abandoned_staging(&self) {
        let Ok(entries) = std::fs::read_dir(&self.root) else {
            return;
        };
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            let Some(rest) = name
                .strip_prefix(".staging-")
                .or_else(|| name.strip_prefix(".damaged-"))
            else {
                continue;
            };
            let pid = rest.split('-').next().and_then(|p| p.parse::<u32>().ok());
            let old = entry
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age > STALE_AFTER);
            if old || pid.is_none_or(|pid| !process_alive(pid)) {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
    }
}

/// Whether process `pid` is running, where `/proc` tells (Linux); elsewhere every process is
/// assumed alive, so only age removes staging folders.
fn process_alive(pid: u32) -> bool {
    let proc_root = Path::new("/proc");
    !proc_root.join("self").exists() || proc_root.join(pid.to_string()).exists()
}

/// Says on stderr, before the first download, what is fetched, from where and how large. The
/// address comes from apt itself (`apt-get download --print-uris`), which may know a local mirror.
fn announce_download(cache_root: &Path) {
    let uri = Command::new("apt-get")
        .args([
            "download",
            "--print-uris",
            &format!("{PACKAGE}={PACKAGE_VERSION}"),
        ])
        .stderr(Stdio::null())
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| {
            let text = String::from_utf8_lossy(&o.stdout).into_owned();
            text.split('\'').nth(1).map(str::to_string)
        })
        .unwrap_or_else(|| "the Debian archive through apt (your apt sources)".into());
    eprintln!(
        "taction: first use of the CGAL object meshes: downloading Debian's {PACKAGE} {PACKAGE_VERSION} \
         ({:.1} MB) from {uri} into {} (shared by every working folder; set {CACHE_ENV} to move it)",
        DEB_BYTES as f64 / 1e6,
        cache_root.display()
    );
}

fn check_sha256(path: &Path, actual: &str, expected: &str) -> Result<(), MeshError> {
    if actual == expected {
        Ok(())
    } else {
        Err(MeshError::Checksum {
            path: path.to_path_buf(),
            expected: expected.into(),
            actual: actual.into(),
            hint: format!("the file is damaged or not the pinned version; {FETCH_HINT}"),
        })
    }
}

fn run(command: &mut Command, what: &str) -> Result<(), MeshError> {
    let output = command.output().map_err(|e| MeshError::Fetch {
        what: what.into(),
        why: e.to_string(),
    })?;
    if output.status.success() {
        Ok(())
    } else {
        let stderr = String::from_utf8_lossy(&output.stderr);
        Err(MeshError::Fetch {
            what: what.into(),
            why: format!("{}: {}", output.status, stderr.trim()),
        })
    }
}

/// `apt-get download libcgal-demo=5.5.1-2` into `dir`; when apt does not know the package (empty or
/// old package lists), `apt-get update` once and retry.
fn apt_download(dir: &Path) -> Result<(), MeshError> {
    let what = format!("apt-get download {PACKAGE}={PACKAGE_VERSION}");
    let download = || {
        run(
            Command::new("apt-get")
                .args(["download", &format!("{PACKAGE}={PACKAGE_VERSION}")])
                .current_dir(dir),
            &what,
        )
    };
    let Err(first) = download() else { return Ok(()) };
    run(Command::new("apt-get").arg("update"), "apt-get update").map_err(|e| MeshError::Fetch {
        what: what.clone(),
        why: format!("{first}; then {e} (apt-get update needs root)"),
    })?;
    download()
}

/// Streams the package's file system (`dpkg-deb --fsys-tarfile`) and writes the wanted meshes of its
/// data tarball into `out`.
fn extract_meshes(deb: &Path, out: &Path) -> Result<(), MeshError> {
    let fail = |why: String| MeshError::Fetch {
        what: format!("extracting {}", deb.display()),
        why,
    };
    let mut child = Command::new("dpkg-deb")
        .arg("--fsys-tarfile")
        .arg(deb)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| fail(format!("cannot run dpkg-deb (Debian's dpkg package): {e}")))?;
    let result = child
        .stdout
        .take()
        .ok_or_else(|| fail("dpkg-deb gave no output".into()))
        .and_then(|stdout| extract_from_fsys(stdout, out).map_err(|e| fail(e.to_string())));
    // Stop dpkg-deb if the meshes were found before the end of its output.
    let _ = child.kill();
    let status = child.wait().map_err(|e| fail(e.to_string()))?;
    match result {
        Ok(true) => Ok(()),
        Ok(false) => Err(fail(format!("{DATA_TARBALL} or some of its meshes are missing"))),
        Err(e) => {
            let mut stderr = String::new();
            if let Some(mut s) = child.stderr.take() {
                let _ = s.read_to_string(&mut stderr);
            }
            Err(fail(format!("{e} (dpkg-deb {status}: {})", stderr.trim())))
        }
    }
}

fn strip_dot(path: &Path) -> String {
    let s = path.to_string_lossy();
    s.strip_prefix("./").unwrap_or(&s).to_string()
}

/// Returns whether all ten meshes were written.
fn extract_from_fsys(fsys: impl Read, out: &Path) -> std::io::Result<bool> {
    let mut fsys = tar::Archive::new(fsys);
    for entry in fsys.entries()? {
        let entry = entry?;
        if strip_dot(&entry.path()?) != DATA_TARBALL {
            continue;
        }
        let mut data = tar::Archive::new(flate2::read::GzDecoder::new(entry));
        let mut found = 0;
        for inner in data.entries()? {
            let mut inner = inner?;
            let path = strip_dot(&inner.path()?);
            let Some(file) = path.strip_prefix(MESH_FOLDER) else {
                continue;
            };
            if let Some(mesh) = CGAL_MESHES.iter().find(|m| m.file == file) {
                let mut bytes = Vec::new();
                inner.read_to_end(&mut bytes)?;
                std::fs::write(out.join(mesh.file), bytes)?;
                found += 1;
                if found == CGAL_MESHES.len() {
                    return Ok(true);
                }
            }
        }
        return Ok(false);
    }
    Ok(false)
}

/// Fetches the CGAL meshes into the default cache ([`ObjectCache::from_env`]) on first use and
/// returns the cache; safe to call from several processes at once.
pub fn ensure_fetched() -> Result<ObjectCache, MeshError> {
    let cache = ObjectCache::from_env();
    cache.ensure_fetched()?;
    Ok(cache)
}
