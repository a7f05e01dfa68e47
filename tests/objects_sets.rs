//! Object-set manifests: stable ids, user sets from folders and files, checksums of user files,
//! manifest round trips, and the `taction objects` command line.

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::DVec3;
use taction::mesh::Font;
use taction::mesh::LetterStyle;
use taction::mesh::{BuildOptions, MeshError, ObjectSet, ObjectSource, load, write_obj};

mod common;

fn write_boxes(dir: &Path) -> Vec<PathBuf> {
    let a = dir.join("tall_box.obj");
    let b = dir.join("flat_box.obj");
    write_obj(&common::box_mesh(DVec3::new(0.02, 0.03, 0.2)), &a, "tall").unwrap();
    write_obj(
        &common::box_mesh(DVec3::new(0.3, 0.2, 0.01)).flipped(),
        &b,
        "flat, inside out",
    )
    .unwrap();
    vec![a, b]
}

#[test]
fn builtin_ids_are_stable_and_change_with_content() {
    assert_eq!(ObjectSet::shapes().id(), ObjectSet::shapes().id());
    assert_eq!(ObjectSet::shapes().id().len(), 16);
    assert_ne!(ObjectSet::shapes().id(), ObjectSet::chess().id());
    let mut rescaled = ObjectSet::chess();
    rescaled.diagonal_m = Some(0.1);
    assert_ne!(rescaled.id(), ObjectSet::chess().id());

    let font = Font::load_default().unwrap();
    let letters = ObjectSet::default_letters(LetterStyle::default()).unwrap();
    assert_eq!(letters.objects.len(), 52);
    assert_eq!(letters.object_names()[..2], ["upper_A", "upper_B"]);
    let raised_more = ObjectSet::letters_with(
        &font,
        &Font::load_capital_i().unwrap(),
        LetterStyle {
            raise_m: 0.004,
            ..LetterStyle::default()
        },
    );
    assert_ne!(letters.id(), raised_more.id());
    let other_font = Font::load(Path::new("/usr/share/fonts/truetype/dejavu/DejaVuSerif.ttf")).unwrap();
    assert_ne!(
        letters.id(),
        ObjectSet::letters(&other_font, LetterStyle::default()).id()
    );
    assert_eq!(ObjectSet::builtin("letters", None).unwrap(), letters);
    let reference = letters.reference();
    assert_eq!(
        (reference.name.as_str(), reference.version, reference.id),
        ("letters", 1, letters.id())
    );
}

#[test]
fn user_sets_are_named_by_file_stem_normalised_and_path_independent() {
    let dir = tempfile::tempdir().unwrap();
    let paths = write_boxes(dir.path());
    let set = ObjectSet::from_dir(dir.path(), Some(0.1)).unwrap();
    assert_eq!(set.object_names(), ["flat_box", "tall_box"]);
    let built = set.build(&BuildOptions::default()).unwrap();
    for object in &built {
        assert!((object.mesh.bounding_diagonal_m().unwrap() - 0.1).abs() < 1e-15);
        assert_eq!(object.mesh.bounds().unwrap().0.z, 0.0);
        assert!(object.mesh.signed_volume() > 0.0);
        assert!(object.warnings.is_clean());
    }
    assert!(built[0].flipped && !built[1].flipped);
    // As given (metres), no rescaling.
    let as_given = ObjectSet::from_files("mine", &paths, None).unwrap();
    let tall = as_given
        .build_object("tall_box", &BuildOptions::default())
        .unwrap();
    assert_eq!(tall.mesh, load(&paths[0]).unwrap().mesh);

    // The same files elsewhere make the same set id.
    let elsewhere = tempfile::tempdir().unwrap();
    let moved = elsewhere.path().join(dir.path().file_name().unwrap());
    std::fs::create_dir(&moved).unwrap();
    for p in &paths {
        std::fs::copy(p, moved.join(p.file_name().unwrap())).unwrap();
    }
    assert_eq!(ObjectSet::from_dir(&moved, Some(0.1)).unwrap().id(), set.id());
    assert_ne!(ObjectSet::from_dir(&moved, Some(0.2)).unwrap().id(), set.id());

    // A file changed after the set was made is caught by its checksum.
    write_obj(&common::box_mesh(DVec3::ONE), &paths[1], "changed").unwrap();
    let e = set
        .build_object("flat_box", &BuildOptions::default())
        .unwrap_err();
    assert!(
        matches!(e, MeshError::Checksum { .. }) && e.to_string().contains("flat_box.obj"),
        "{e}"
    );
    assert!(set.build_object("tall_box", &BuildOptions::default()).is_ok());
}

#[test]
fn bad_user_sets_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let e = ObjectSet::from_dir(dir.path(), None).unwrap_err();
    assert!(e.to_string().contains("no .obj, .off or .stl"), "{e}");
    let paths = write_boxes(dir.path());
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let twin = dir.path().join("sub/tall_box.stl");
    std::fs::copy("tests/broken_meshes/tetra_binary.stl", &twin).unwrap();
    let e = ObjectSet::from_files("twins", &[paths[0].clone(), twin], None).unwrap_err();
    assert!(e.to_string().contains("both be named 'tall_box'"), "{e}");
    let e = ObjectSet::from_files("bad", &[dir.path().join("notes.txt")], None).unwrap_err();
    assert!(matches!(e, MeshError::UnknownFormat { .. }));
    assert!(ObjectSet::from_files("neg", &paths, Some(-1.0)).is_err());
    let e = ObjectSet::resolve(&[PathBuf::from("no-such-set")], None, None).unwrap_err();
    assert!(e.to_string().contains("shapes, chess, letters"), "{e}");
    let e = ObjectSet::chess()
        .build_object("queen", &BuildOptions::default())
        .unwrap_err();
    assert!(e.to_string().contains("pawn, rook"), "{e}");
}

#[test]
fn manifests_round_trip_and_resolve() {
    let dir = tempfile::tempdir().unwrap();
    let paths = write_boxes(dir.path());
    let set = ObjectSet::from_files("boxes", &paths, Some(0.05)).unwrap();
    let manifest = dir.path().join("boxes.json");
    set.save_manifest(&manifest).unwrap();
    let back = ObjectSet::load_manifest(&manifest).unwrap();
    assert_eq!(back, set);
    assert_eq!(back.id(), set.id());
    assert_eq!(
        ObjectSet::resolve(std::slice::from_ref(&manifest), None, None).unwrap(),
        set
    );
    assert_eq!(
        ObjectSet::resolve(&paths, None, Some(0.05)).unwrap().objects,
        set.objects
    );
    assert!(matches!(&back.objects[0].source, ObjectSource::File { sha256, .. } if sha256.len() == 64));
    assert_eq!(
        ObjectSet::resolve(&[PathBuf::from("chess")], None, None).unwrap(),
        ObjectSet::chess()
    );
    // Several entries are mesh files; a set among them is named as one.
    for set in [PathBuf::from("chess"), dir.path().to_path_buf(), manifest.clone()] {
        let e = ObjectSet::resolve(&[paths[0].clone(), set.clone()], None, None).unwrap_err();
        assert!(
            e.to_string().contains(&format!("'{}' is a set", set.display())),
            "{e}"
        );
    }

    std::fs::write(&manifest, "{\"name\": \"x\",\n \"version\": \"one\"}").unwrap();
    let e = ObjectSet::load_manifest(&manifest).unwrap_err();
    assert!(
        e.to_string().contains("boxes.json") && e.to_string().contains("line 2"),
        "{e}"
    );
}

#[test]
fn cli_writes_letters_and_exports_sets() {
    let exe = env!("CARGO_BIN_EXE_taction");
    let out = tempfile::tempdir().unwrap();
    let letters = out.path().join("letters");
    let status = Command::new(exe)
        .args(["objects", "letters", "--out"])
        .arg(&letters)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    for name in ["upper_A.obj", "lower_z.obj", "upper_B.obj", "manifest.json"] {
        assert!(letters.join(name).is_file(), "{name} missing");
    }
    let b = load(letters.join("upper_B.obj")).unwrap();
    assert!(b.warnings.is_clean());
    assert_eq!(std::fs::read_dir(&letters).unwrap().count(), 53);

    let chess = out.path().join("chess");
    let run = Command::new(exe)
        .args(["objects", "export", "chess", "--out"])
        .arg(&chess)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let pawn = load(chess.join("pawn.obj")).unwrap().mesh;
    assert_eq!(
        pawn,
        ObjectSet::chess()
            .build_object("pawn", &BuildOptions::default())
            .unwrap()
            .mesh
    );
    let manifest = ObjectSet::load_manifest(&chess.join("manifest.json")).unwrap();
    assert_eq!(manifest.id(), ObjectSet::chess().id());

    let missing = Command::new(exe)
        .args(["objects", "export", "shapes", "--cache"])
        .arg(out.path().join("no-cache"))
        .arg("--out")
        .arg(out.path().join("shapes"))
        .output()
        .unwrap();
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("taction objects fetch"));

    let bad_font = Command::new(exe)
        .args([
            "objects",
            "letters",
            "--font",
            "tests/broken_meshes/README.md",
            "--out",
        ])
        .arg(out.path().join("x"))
        .output()
        .unwrap();
    assert!(!bad_font.status.success());
    assert!(String::from_utf8_lossy(&bad_font.stderr).contains("README.md"));
}

/// A random start may turn the 3D objects any way about the vertical, but a set with a raised
/// letter in it only within 10 degrees: 'b' turned half round is 'q'.
#[test]
fn a_set_with_letters_keeps_its_heading_within_ten_degrees() {
    use taction::pose::MaxHeading;
    let letters = ObjectSet::default_letters(LetterStyle::default()).unwrap();
    assert_eq!(letters.start_heading(), MaxHeading::LETTERS);
    assert!((MaxHeading::LETTERS.rad().to_degrees() - 10.0).abs() < 1e-12);
    assert_eq!(ObjectSet::shapes().start_heading(), MaxHeading::ANY);
    assert_eq!(ObjectSet::chess().start_heading(), MaxHeading::ANY);
    let mut chess_and_b = ObjectSet::chess();
    chess_and_b
        .objects
        .extend(letters.objects.into_iter().filter(|o| o.name == "lower_b"));
    assert_eq!(chess_and_b.objects.len(), 3);
    assert_eq!(chess_and_b.start_heading(), MaxHeading::LETTERS);
    let dir = tempfile::tempdir().unwrap();
    let files = ObjectSet::from_files("boxes", &write_boxes(dir.path()), None).unwrap();
    assert_eq!(files.start_heading(), MaxHeading::ANY);
}
