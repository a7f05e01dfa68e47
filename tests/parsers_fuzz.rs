//! Seeded fuzzing of every parser a user's file reaches: the OBJ, OFF and STL mesh parsers, the
//! dataset parser, the recorded-frame CSV and calibration parsers and the tactile-image CSV
//! parser. Each gets arbitrary bytes and mutations of a valid file (bytes flipped, ranges cut or
//! repeated, hostile tokens such as `nan`, `-9223372036854775808` or `1e999` spliced in) and must
//! return `Ok` or an error, never panic. A fixed number of cases from fixed seeds: a failure
//! prints its input, and reruns reproduce it.

mod recognize_toy;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use rand::RngExt;
use taction::dataset::Dataset;
use taction::dataset::{Calibration, RealImport, parse_real_csv};
use taction::mesh::{MeshFormat, parse};
use taction::rng::{Rng, stream};
use taction::tactile::TactileImage;

/// Cases per parser: half arbitrary bytes, half mutated valid files.
const CASES: u64 = 1000;

const TOKENS: &[&str] = &[
    "-",
    "0",
    "1",
    "-1",
    "nan",
    "inf",
    "-inf",
    "1e999",
    "1e30",
    "-9223372036854775808",
    "9223372036854775807",
    "18446744073709551616",
    "4294967295",
    "\n",
    "\r\n",
    ",",
    ",,",
    "#",
    " ",
    "/",
    "//",
    "\0",
    "\u{e9}",
    "\u{fffd}",
    "v ",
    "f ",
    "f -1 -2 -99999999999",
    "OFF",
    "OFF 999999999999 1 0",
    "solid",
    "facet normal",
    "outer loop",
    "vertex",
    "endloop",
    "endfacet",
    "endsolid",
    "label",
    "r0c0",
    "r99999c99999",
    "taxel,gain,offset",
];

/// One input: arbitrary bytes for even `case`, a mutation of one of `valid` for odd.
fn input(valid: &[Vec<u8>], seed: u64, case: u64) -> Vec<u8> {
    let mut rng = stream(seed, case);
    if case.is_multiple_of(2) {
        let len = rng.random_range(0..400);
        return (0..len).map(|_| rng.random::<u8>()).collect();
    }
    let mut bytes = valid[rng.random_range(0..valid.len())].clone();
    for _ in 0..rng.random_range(1..4) {
        mutate(&mut bytes, &mut rng);
    }
    bytes
}

fn mutate(bytes: &mut Vec<u8>, rng: &mut Rng) {
    let at = |rng: &mut Rng, len: usize| rng.random_range(0..=len);
    match rng.random_range(0..5) {
        0 if !bytes.is_empty() => {
            let i = rng.random_range(0..bytes.len());
            bytes[i] = rng.random();
        }
        1 => {
            let token = TOKENS[rng.random_range(0..TOKENS.len())].as_bytes();
            let i = at(rng, bytes.len());
            bytes.splice(i..i, token.iter().copied());
        }
        2 => {
            let (a, b) = (at(rng, bytes.len()), at(rng, bytes.len()));
            bytes.drain(a.min(b)..a.max(b));
        }
        3 => {
            let (a, b) = (at(rng, bytes.len()), at(rng, bytes.len()));
            let piece: Vec<u8> = bytes[a.min(b)..a.max(b)].to_vec();
            let i = at(rng, bytes.len());
            bytes.splice(i..i, piece);
        }
        _ => {
            let i = at(rng, bytes.len());
            bytes.truncate(i);
        }
    }
}

/// Runs `parser` on `CASES` inputs; panics (failing the test) with the first input that panicked.
fn fuzz(name: &str, seed: u64, valid: &[Vec<u8>], parser: impl Fn(&[u8])) {
    for case in 0..CASES {
        let bytes = input(valid, seed, case);
        if catch_unwind(AssertUnwindSafe(|| parser(&bytes))).is_err() {
            panic!(
                "{name} panicked on case {case} of seed {seed}: {:?}",
                String::from_utf8_lossy(&bytes)
            );
        }
    }
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/broken_meshes")
            .join(name),
    )
    .unwrap()
}

#[test]
fn mesh_parsers_never_panic() {
    let obj = vec![
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n".to_vec(),
        b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1/1 2/2/2 3//3 4\nf -1 -2 -3\n".to_vec(),
        fixture("quad_cube.obj"),
    ];
    let off = vec![
        b"OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n".to_vec(),
        b"COFF 4 1 0\n0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 9 9 9\n4 0 1 2 3 1 1 1\n".to_vec(),
    ];
    let stl = vec![fixture("tetra_ascii.stl"), fixture("tetra_binary.stl")];
    for (format, valid, seed) in [
        (MeshFormat::Obj, &obj, 1),
        (MeshFormat::Off, &off, 2),
        (MeshFormat::Stl, &stl, 3),
    ] {
        fuzz(&format!("{format:?}"), seed, valid, |bytes| {
            let _ = parse(bytes, format, Path::new("fuzz"));
        });
    }
}

#[test]
fn dataset_parser_never_panics() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("d.csv");
    recognize_toy::dataset(2, 1).write(&path).unwrap();
    let valid = vec![std::fs::read(&path).unwrap()];
    fuzz("dataset", 4, &valid, |bytes| {
        let _ = Dataset::parse(&text(bytes), "fuzz");
    });
}

#[test]
fn recorded_frame_and_image_parsers_never_panic() {
    let header: Vec<String> = (0..4)
        .flat_map(|r| (0..4).map(move |c| format!("r{r}c{c}")))
        .collect();
    let frame = |v: usize| (0..16).map(|i| (i * v).to_string()).collect::<Vec<_>>().join(",");
    let real = vec![
        format!(
            "# frames\nlabel,{}\nA,{}\nB,{}\n\nA,{}\n",
            header.join(","),
            frame(1),
            frame(3),
            frame(7)
        )
        .into_bytes(),
    ];
    fuzz("recorded frames", 5, &real, |bytes| {
        let _ = parse_real_csv(&text(bytes), "fuzz", &RealImport::default());
    });
    let calibration = vec![
        format!(
            "taxel,gain,offset\n{}\n",
            header
                .iter()
                .map(|t| format!("{t},1.02,13"))
                .collect::<Vec<_>>()
                .join("\n")
        )
        .into_bytes(),
    ];
    fuzz("calibration", 6, &calibration, |bytes| {
        let _ = Calibration::parse(&text(bytes), "fuzz");
    });
    let images = vec![b"0,0.5,1\n0.25,0.75,0\n".to_vec(), b"1\n".to_vec()];
    fuzz("tactile image", 7, &images, |bytes| {
        let _ = TactileImage::parse_csv(&text(bytes), "fuzz");
    });
}

/// The fuzzer itself reaches the parsers' error paths and their success paths, so that a parser
/// that returned early on everything would not pass unnoticed.
#[test]
fn the_mutations_reach_both_accepted_and_refused_files() {
    let valid = vec![b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n".to_vec()];
    let (mut ok, mut refused) = (0, 0);
    for case in (1..CASES).step_by(2) {
        match parse(&input(&valid, 1, case), MeshFormat::Obj, Path::new("fuzz")) {
            Ok(_) => ok += 1,
            Err(_) => refused += 1,
        }
    }
    assert!(ok >= 10 && refused >= 10, "{ok} accepted, {refused} refused");
}
