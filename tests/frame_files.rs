//! Recorded frames as users keep them (`dataset::frame_files`): folders of class folders of PNG and
//! JPEG images and numpy's `.npz`, made here or by numpy and Pillow themselves (the fixtures in
//! `tests/frame_files/`), read into the frames they hold; non-square and large grids imported
//! whole and every descriptor defined on them; malformed inputs named.

use std::path::Path;
use std::process::Command;

use taction::dataset::{Dataset, FramePlace, PadSize, RealData, RealImport, import_real, parse_real_csv};
use taction::describe::DescriptorKind;
use taction::tactile::TactileImage;

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/frame_files");

/// Writes a grayscale PNG of `rows x cols` pixels, 8 or 16 bit.
fn write_png(path: &Path, rows: usize, cols: usize, pixels: &[u16], sixteen: bool) {
    let file = std::fs::File::create(path).expect("creates the image");
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), cols as u32, rows as u32);
    encoder.set_color(png::ColorType::Grayscale);
    let data: Vec<u8> = if sixteen {
        encoder.set_depth(png::BitDepth::Sixteen);
        pixels.iter().flat_map(|p| p.to_be_bytes()).collect()
    } else {
        encoder.set_depth(png::BitDepth::Eight);
        pixels.iter().map(|&p| p as u8).collect()
    };
    let mut writer = encoder.write_header().expect("a header");
    writer.write_image_data(&data).expect("the pixels");
}

fn import(path: &Path) -> Result<RealData, String> {
    import_real(path, &RealImport::default()).map_err(|e| e.to_string())
}

/// A pixel value of frame `f` at taxel `k`, below 2^16.
fn pixel(f: usize, k: usize) -> u16 {
    ((f * 7919 + k * 104_729) % 60_000) as u16
}

#[test]
fn a_folder_of_class_folders_imports_every_image_whole() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let root = dir.path().join("frames");
    // A 28 x 50 array (rows x cols), 16 bit, two labels of two frames; a README at the top and a
    // hidden file are skipped.
    let (rows, cols) = (28, 50);
    for (label, frames) in [("pawn", [0, 1]), ("mug", [2, 3])] {
        std::fs::create_dir_all(root.join(label)).expect("a class folder");
        for f in frames {
            let pixels: Vec<u16> = (0..rows * cols).map(|k| pixel(f, k)).collect();
            write_png(
                &root.join(label).join(format!("{f:04}.png")),
                rows,
                cols,
                &pixels,
                true,
            );
        }
    }
    std::fs::write(root.join("README.txt"), "how the frames were taken").expect("writes");
    std::fs::write(root.join("mug").join(".DS_Store"), "").expect("writes");
    let data = import(&root).expect("imports");
    assert_eq!(
        (data.rows, data.cols),
        (rows, cols),
        "not cropped, not transposed"
    );
    let labels: Vec<&str> = data.readings.iter().map(|r| r.label.as_str()).collect();
    assert_eq!(
        labels,
        ["mug", "mug", "pawn", "pawn"],
        "labels then files in name order"
    );
    assert_eq!(data.readings[0].place, FramePlace::Image("mug/0002.png".into()));
    let max = (0..4)
        .flat_map(|f| (0..rows * cols).map(move |k| pixel(f, k)))
        .max()
        .map_or(1.0, f64::from);
    for (reading, f) in data.readings.iter().zip([2, 3, 0, 1]) {
        for k in [0, cols - 1, cols, rows * cols - 1] {
            let expected = f64::from(pixel(f, k)) / max;
            assert_eq!(
                reading.image.get(k / cols, k % cols),
                expected,
                "frame {f} taxel {k}"
            );
        }
    }
    // 8-bit PNGs and an 8-bit JPEG (Pillow's, the fixture) read as their pixels.
    let small = dir.path().join("small");
    std::fs::create_dir_all(small.join("a")).expect("a class folder");
    std::fs::create_dir_all(small.join("b")).expect("a class folder");
    let ramp: Vec<u16> = (0..8 * 16).map(|k| (k % 16 * 10) as u16).collect();
    write_png(&small.join("a/ramp.png"), 8, 16, &ramp, false);
    std::fs::copy(
        Path::new(FIXTURES).join("two_tone_8x16.jpg"),
        small.join("b/two_tone.JPG"),
    )
    .expect("copies");
    let data = import(&small).expect("imports");
    assert_eq!((data.rows, data.cols), (8, 16));
    let (ramp, jpeg) = (&data.readings[0].image, &data.readings[1].image);
    assert_eq!(
        ramp.get(3, 15),
        150.0 / 200.0,
        "the largest value is the JPEG's 200"
    );
    assert_eq!((jpeg.get(0, 0), jpeg.get(7, 7)), (50.0 / 200.0, 50.0 / 200.0));
    assert_eq!((jpeg.get(0, 8), jpeg.get(7, 15)), (1.0, 1.0));
}

#[test]
fn an_npz_from_numpy_imports_as_its_frames() {
    // numpy.savez(frames=arange(30, dtype=int16).reshape(2, 3, 5), labels=['mug', 'pawn']), and
    // savez_compressed of the same values as big-endian float64 in Fortran order with the labels
    // 7 and 11.
    let plain = import(&Path::new(FIXTURES).join("numpy_2x3x5.npz")).expect("imports");
    let fortran = import(&Path::new(FIXTURES).join("numpy_fortran_2x3x5.npz")).expect("imports");
    for (data, labels) in [(&plain, ["mug", "pawn"]), (&fortran, ["7", "11"])] {
        assert_eq!((data.rows, data.cols), (3, 5));
        let got: Vec<&str> = data.readings.iter().map(|r| r.label.as_str()).collect();
        assert_eq!(got, labels);
        assert_eq!(data.readings[1].place, FramePlace::Frame(1));
        for (f, reading) in data.readings.iter().enumerate() {
            for k in 0..15 {
                let expected = (15 * f + k) as f64 / 29.0;
                assert_eq!(reading.image.get(k / 5, k % 5), expected, "frame {f} taxel {k}");
            }
        }
    }
    let pickled = import(&Path::new(FIXTURES).join("numpy_pickled_labels.npz")).unwrap_err();
    assert!(
        pickled.contains("numpy_pickled_labels.npz") && pickled.contains("pickle"),
        "{pickled}"
    );
}

/// Runs `taction args`, which must succeed; its standard output.
fn taction(args: &[&str]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(args)
        .output()
        .expect("the taction binary runs");
    assert!(
        output.status.success(),
        "taction {args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

#[test]
fn a_44x44_recording_round_trips_through_export_and_import() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let side = 44;
    let names: Vec<String> = (0..side * side)
        .map(|k| format!("r{}c{}", k / side, k % side))
        .collect();
    let mut csv = format!("label,{}\n", names.join(","));
    for f in 0..6 {
        let label = if f % 2 == 0 { "cup" } else { "key" };
        let values: Vec<String> = (0..side * side)
            .map(|k| {
                // A pressed blob, so that the frames count as contacts.
                let (r, c) = ((k / side) as f64 - 20.0, (k % side) as f64 - 22.0 + f as f64);
                format!("{:.0}", 1000.0 * (-(r * r + c * c) / 50.0).exp())
            })
            .collect();
        csv.push_str(&format!("{label},{}\n", values.join(",")));
    }
    let frames = dir.path().join("frames.csv");
    std::fs::write(&frames, csv).expect("writes");
    let (first, npz, second) = (
        dir.path().join("first.csv"),
        dir.path().join("first.npz"),
        dir.path().join("second.csv"),
    );
    let path = |p: &Path| p.to_str().expect("a UTF-8 path").to_string();
    let with_pitch = taction(&[
        "dataset",
        "import",
        &path(&frames),
        "--taxel-pitch-m",
        "0.0015",
        "--out",
        &path(&first),
    ]);
    assert!(
        with_pitch.contains("44x44 taxels, pad 66 mm x 66 mm"),
        "{with_pitch}"
    );
    taction(&[
        "dataset",
        "export",
        &path(&first),
        "--format",
        "npz",
        "--out",
        &path(&npz),
    ]);
    // Without its pitch the pad's size is recorded as unknown, never made up.
    let without = taction(&["dataset", "import", &path(&npz), "--out", &path(&second)]);
    assert!(
        without.contains("44x44 taxels, pad size unknown") && !without.contains("mm x"),
        "{without}"
    );
    let (a, b) = (
        Dataset::read(&first).expect("reads"),
        Dataset::read(&second).expect("reads"),
    );
    assert_eq!((a.header().sensor.rows, a.header().sensor.cols), (side, side));
    assert_eq!(
        (a.header().pad_size, b.header().pad_size),
        (PadSize::Known, PadSize::Unknown)
    );
    assert!((a.header().sensor.pad_width_m - 0.066).abs() < 1e-12);
    let header_line = |p: &Path| {
        std::fs::read_to_string(p)
            .expect("reads")
            .lines()
            .nth(1)
            .map(str::to_string)
    };
    assert!(!header_line(&first).unwrap_or_default().contains("pad_size"));
    assert!(
        header_line(&second)
            .unwrap_or_default()
            .contains(r#""pad_size":"unknown""#)
    );
    let refused = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args([
            "dataset",
            "import",
            &path(&frames),
            "--taxel-pitch-m",
            "0.02",
            "--out",
        ])
        .arg(dir.path().join("third.csv"))
        .output()
        .expect("the taction binary runs");
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        !refused.status.success() && stderr.contains("--taxel-pitch-m") && stderr.contains("0.0078125"),
        "{stderr}"
    );
    assert_eq!(a.readings().len(), 6);
    for (x, y) in a.readings().iter().zip(b.readings()) {
        assert_eq!((&x.object, x.status), (&y.object, y.status));
        // The export keeps float32 images; the largest of them is 1 again, so they come back.
        for (u, v) in x.image.values().iter().zip(y.image.values()) {
            assert!((u - v).abs() <= 1e-7, "{u} against {v}");
        }
    }
}

#[test]
fn malformed_frames_are_named_not_imported() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let folder = |name: &str, files: &[(&str, usize, usize)]| {
        let root = dir.path().join(name);
        for (file, rows, cols) in files {
            let path = root.join(file);
            std::fs::create_dir_all(path.parent().expect("a class folder")).expect("creates");
            if file.ends_with(".png") {
                write_png(&path, *rows, *cols, &vec![9; rows * cols], false);
            } else {
                std::fs::write(&path, "not an image").expect("writes");
            }
        }
        root
    };
    let mixed = folder("mixed", &[("a/1.png", 4, 6), ("b/1.png", 6, 4)]);
    let e = import(&mixed).unwrap_err();
    assert!(e.contains("b/1.png") && e.contains("but a/1.png is 4x6"), "{e}");
    let text = folder("text", &[("a/1.png", 4, 6), ("a/notes.txt", 0, 0)]);
    let e = import(&text).unwrap_err();
    assert!(e.contains("a/notes.txt") && e.contains("not an image"), "{e}");
    let fake = folder("fake", &[("a/1.png", 4, 6)]);
    std::fs::write(fake.join("a/2.png"), "no png").expect("writes");
    let e = import(&fake).unwrap_err();
    assert!(e.contains("a/2.png") && e.contains("not a readable PNG"), "{e}");
    let empty = folder("empty", &[("a/1.png", 4, 6)]);
    std::fs::create_dir_all(empty.join("b")).expect("creates");
    let e = import(&empty).unwrap_err();
    assert!(e.contains("class folder 'b' holds no image"), "{e}");
    let colour = folder("colour", &[("a/1.png", 8, 8)]);
    std::fs::copy(Path::new(FIXTURES).join("colour_8x8.jpg"), colour.join("a/2.jpg")).expect("copies");
    let e = import(&colour).unwrap_err();
    assert!(e.contains("a/2.jpg") && e.contains("grayscale"), "{e}");
    let thin = folder("thin", &[("a/1.png", 1, 6)]);
    let e = import(&thin).unwrap_err();
    assert!(e.contains("a 1x6 sensor; accepted are 2 to 128"), "{e}");
    let none = dir.path().join("none");
    std::fs::create_dir_all(&none).expect("creates");
    assert!(import(&none).unwrap_err().contains("no class folders"));
    let npy = dir.path().join("frames.npy");
    std::fs::write(&npy, "x").expect("writes");
    assert!(import(&npy).unwrap_err().contains("numpy.savez"));
}

#[test]
fn every_descriptor_describes_any_grid_it_imports() {
    for (rows, cols) in [(2, 2), (2, 7), (28, 50), (50, 28), (44, 44), (128, 128)] {
        let values: Vec<f64> = (0..rows * cols)
            .map(|k| {
                let (r, c) = (
                    (k / cols) as f64 / rows as f64 - 0.5,
                    (k % cols) as f64 / cols as f64 - 0.4,
                );
                (-(r * r + c * c) * 8.0).exp()
            })
            .collect();
        let image = TactileImage::new(rows, cols, values).expect("an image");
        for kind in DescriptorKind::ALL {
            let features = kind.build().describe(&image);
            assert!(!features.is_empty(), "{kind:?} on {rows}x{cols}: no feature");
            let length = features[0].len();
            assert!(length > 0, "{kind:?} on {rows}x{cols}: an empty feature");
            for feature in &features {
                assert_eq!(feature.len(), length, "{kind:?} on {rows}x{cols}");
                assert!(
                    feature.iter().all(|v| v.is_finite()),
                    "{kind:?} on {rows}x{cols}: {feature:?}"
                );
            }
        }
    }
}

/// Runs `experiment real-frames --real <frames> --trials 1` and returns its accuracy CSV.
fn real_frames_csv(frames: &Path, out: &Path) -> Vec<u8> {
    let path = |p: &Path| p.to_str().expect("a UTF-8 path").to_string();
    taction(&[
        "experiment",
        "real-frames",
        "--real",
        &path(frames),
        "--trials",
        "1",
        "--out",
        &path(out),
    ]);
    std::fs::read(out.join("real-frames/real-frames.csv")).expect("the experiment's CSV")
}

#[test]
fn the_real_frames_experiment_reads_a_folder_of_images_as_the_same_frames_in_a_csv() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let (rows, cols) = (6, 6);
    let names: Vec<String> = (0..rows * cols)
        .map(|k| format!("r{}c{}", k / cols, k % cols))
        .collect();
    let mut csv = format!("label,{}\n", names.join(","));
    let images = dir.path().join("images");
    for (label, shape) in [("bar", 0usize), ("cross", 1)] {
        std::fs::create_dir_all(images.join(label)).expect("a class folder");
        for f in 0..14 {
            let pixels: Vec<u16> = (0..rows * cols)
                .map(|k| {
                    let (r, c) = (k / cols, k % cols);
                    let pressed = if shape == 0 {
                        r == 2 || r == 3
                    } else {
                        r == 2 || c == 3
                    };
                    if pressed {
                        900 + (f * 13 + k) as u16 % 50
                    } else {
                        (f + k) as u16 % 30
                    }
                })
                .collect();
            write_png(
                &images.join(label).join(format!("{f:02}.png")),
                rows,
                cols,
                &pixels,
                true,
            );
            let values: Vec<String> = pixels.iter().map(u16::to_string).collect();
            csv.push_str(&format!("{label},{}\n", values.join(",")));
        }
    }
    let text = dir.path().join("frames.csv");
    std::fs::write(&text, csv).expect("writes");
    let from_csv = real_frames_csv(&text, &dir.path().join("from-csv"));
    let from_images = real_frames_csv(&images, &dir.path().join("from-images"));
    assert!(!from_csv.is_empty());
    assert_eq!(from_csv, from_images, "the same frames, the same results");
}

/// The contact each frame of `data` is one of.
fn contacts(data: &RealData) -> Vec<Option<u32>> {
    data.readings.iter().map(|r| r.contact).collect()
}

/// A frames CSV of 2x3 frames with a `contact` column: `(label, contact)` per line.
fn contact_csv(frames: &[(&str, &str)]) -> String {
    let mut csv = "label,contact,r0c0,r0c1,r0c2,r1c0,r1c1,r1c2\n".to_string();
    for (f, (label, contact)) in frames.iter().enumerate() {
        let values: Vec<String> = (0..6).map(|k| (f * 6 + k).to_string()).collect();
        csv.push_str(&format!("{label},{contact},{}\n", values.join(",")));
    }
    csv
}

#[test]
fn frames_of_one_press_import_as_one_contact_from_every_source() {
    // A CSV: two frames of press p1, a frame of its own, press p2; the other label's p1 is
    // another contact.
    let csv = contact_csv(&[
        ("A", "p1"),
        ("A", "p1"),
        ("A", ""),
        ("A", "p2"),
        ("B", "p1"),
        ("B", "p1"),
    ]);
    let data = parse_real_csv(&csv, "seq.csv", &RealImport::default()).expect("imports");
    assert_eq!(
        contacts(&data),
        [Some(0), Some(0), None, Some(1), Some(2), Some(2)]
    );
    assert!(data.has_contacts());
    assert_eq!(
        data.readings[5].image.get(1, 2),
        1.0,
        "the taxels start after the contact column"
    );
    assert_eq!(data.readings[0].image.get(0, 1), 1.0 / 35.0);
    // A folder: a folder inside a class folder is one press, an image beside it a contact of its
    // own.
    let dir = tempfile::tempdir().expect("a temporary folder");
    let root = dir.path().join("frames");
    for file in [
        "A/loose.png",
        "A/p1/0.png",
        "A/p1/1.png",
        "A/p2/0.png",
        "B/p1/0.png",
        "B/p1/1.png",
    ] {
        let path = root.join(file);
        std::fs::create_dir_all(path.parent().expect("a folder")).expect("creates");
        write_png(&path, 2, 3, &[1, 2, 3, 4, 5, 6], false);
    }
    let data = import(&root).expect("imports");
    assert_eq!(
        contacts(&data),
        [None, Some(0), Some(0), Some(1), Some(2), Some(2)]
    );
    assert_eq!(data.readings[2].place, FramePlace::Image("A/p1/1.png".into()));
    // An npz from numpy with a `contacts` array of strings, '' a frame of its own.
    let npz = import(&Path::new(FIXTURES).join("numpy_contacts_5x3x5.npz")).expect("imports");
    assert_eq!(contacts(&npz), [Some(0), Some(0), None, Some(1), Some(1)]);
    // Without contacts, every frame is its own.
    let plain = import(&Path::new(FIXTURES).join("numpy_2x3x5.npz")).expect("imports");
    assert!(!plain.has_contacts());
}

#[test]
fn a_press_that_comes_back_or_an_empty_press_is_named() {
    let csv = contact_csv(&[("A", "p1"), ("A", "p2"), ("A", "p1")]);
    let e = parse_real_csv(&csv, "seq.csv", &RealImport::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("seq.csv: line 4") && e.contains("contact 'p1' of label 'A' comes back"),
        "{e}"
    );
    let short = "label,contact,r0c0,r0c1,r1c0,r1c1\nA,p1,1,2,3\n";
    let e = parse_real_csv(short, "seq.csv", &RealImport::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("5 columns, expected 6 (label, contact + 2x2 taxels)"),
        "{e}"
    );
    let e = import(&Path::new(FIXTURES).join("numpy_contacts_resumed.npz")).unwrap_err();
    assert!(
        e.contains("frame 2") && e.contains("contact '3' of label 'mug'"),
        "{e}"
    );
    let dir = tempfile::tempdir().expect("a temporary folder");
    let root = dir.path().join("frames");
    write_png_at(&root.join("A/0.png"));
    std::fs::create_dir_all(root.join("A/p1")).expect("creates");
    let e = import(&root).unwrap_err();
    assert!(e.contains("contact folder 'A/p1' holds no image"), "{e}");
    write_png_at(&root.join("A/p1/deeper/0.png"));
    let e = import(&root).unwrap_err();
    assert!(
        e.contains("A/p1/deeper") && e.contains("a folder inside a contact folder"),
        "{e}"
    );
}

/// A 2x3 frame at `path`, its folders made.
fn write_png_at(path: &Path) {
    std::fs::create_dir_all(path.parent().expect("a folder")).expect("creates");
    write_png(path, 2, 3, &[1, 2, 3, 4, 5, 6], false);
}

#[test]
fn an_imported_sequence_keeps_its_contacts_through_the_dataset_and_its_export() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let frames = dir.path().join("seq.csv");
    std::fs::write(
        &frames,
        contact_csv(&[
            ("A", "7"),
            ("A", "7"),
            ("A", ""),
            ("B", "7"),
            ("B", "7"),
            ("B", "8"),
        ]),
    )
    .expect("writes");
    let (dataset, npz, again) = (
        dir.path().join("dataset.csv"),
        dir.path().join("dataset.npz"),
        dir.path().join("again.csv"),
    );
    let path = |p: &Path| p.to_str().expect("a UTF-8 path").to_string();
    taction(&["dataset", "import", &path(&frames), "--out", &path(&dataset)]);
    let read = Dataset::read(&dataset).expect("reads");
    let numbers: Vec<Option<u32>> = read.readings().iter().map(|r| r.contact).collect();
    assert_eq!(numbers, [Some(0), Some(0), None, Some(1), Some(1), Some(2)]);
    taction(&[
        "dataset",
        "export",
        &path(&dataset),
        "--format",
        "npz",
        "--out",
        &path(&npz),
    ]);
    taction(&["dataset", "import", &path(&npz), "--out", &path(&again)]);
    let again = Dataset::read(&again).expect("reads");
    let back: Vec<Option<u32>> = again.readings().iter().map(|r| r.contact).collect();
    assert_eq!(back, numbers, "the npz's contact array, -1 for none, reads back");
}
