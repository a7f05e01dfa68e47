//! Object preparation costs: parsing and validating a real mesh (the 10k-vertex dragon OFF, fetched
//! on first use), normalising it, generating a chess piece and a raised letter; and a scanned
//! object's size (issue 39): the free pad's first reading of spheres 8 cm across of 20k and 200k
//! triangles (and 1.3M with `TACTION_BENCH_LARGE_MESH=1`: about two seconds an iteration),
//! generated in memory: the scene's MJCF, MuJoCo's compile (of a coarse copy above 100,000
//! triangles, the exact surface beside it), the sensor's BVH, the reading.

use std::hint::black_box;
use std::path::Path;

#[path = "../tests/sensor_support/mod.rs"]
mod sensor_support;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::DVec3;
use sensor_support::{geodesic_sphere, icosphere, pad_looking_down};
use taction::control::FreePad;
use taction::mesh::ChessPiece;
use taction::mesh::Font;
use taction::mesh::{
    CGAL_MESHES, MeshFormat, ValidationReport, ensure_fetched, normalise_to_diagonal, parse,
};
use taction::mesh::{LetterStyle, alphabet, raised_letter};
use taction::sim::ObjectSpec;
use taction::tactile::SensorConfig;
use taction::valid::Valid;

fn bench_mesh(c: &mut Criterion) {
    let cache = ensure_fetched().expect("the CGAL meshes can be fetched");
    let dragon = &CGAL_MESHES[0];
    let bytes = std::fs::read(cache.mesh_path(dragon)).expect("cached dragon");
    let path = Path::new(dragon.file);
    let mesh = parse(&bytes, MeshFormat::Off, path).expect("dragon parses").mesh;

    c.bench_function("parse_and_validate_dragon_off_20k_triangles", |b| {
        b.iter(|| parse(black_box(&bytes), MeshFormat::Off, path))
    });
    c.bench_function("validate_dragon_20k_triangles", |b| {
        b.iter(|| ValidationReport::of(black_box(&mesh)))
    });
    c.bench_function("normalise_dragon", |b| {
        b.iter(|| normalise_to_diagonal(black_box(&mesh), 0.12))
    });
    c.bench_function("revolve_pawn", |b| b.iter(|| ChessPiece::Pawn.mesh()));

    let font = Font::load_default().expect("DejaVu Sans is installed");
    let style = LetterStyle::default();
    c.bench_function("raised_letter_B", |b| {
        b.iter(|| raised_letter(&font, black_box('B'), &style))
    });
    c.bench_function("raised_letters_all_52", |b| {
        b.iter(|| {
            alphabet()
                .map(|ch| raised_letter(&font, ch, &style))
                .collect::<Result<Vec<_>, _>>()
        })
    });
}

/// Scene build and first reading of ever finer spheres of the same size (radius 4 cm).
fn bench_large_meshes(c: &mut Criterion) {
    const RADIUS_M: f64 = 0.04;
    let mut spheres = vec![
        ("20k", icosphere(DVec3::ZERO, RADIUS_M, 5)),
        ("200k", geodesic_sphere(DVec3::ZERO, RADIUS_M, 100)),
    ];
    if std::env::var_os("TACTION_BENCH_LARGE_MESH").is_some() {
        spheres.push(("1300k", icosphere(DVec3::ZERO, RADIUS_M, 8)));
    }
    let config = Valid::new(SensorConfig::default()).expect("the default sensor is valid");
    let pose = pad_looking_down(DVec3::new(0.0, 0.0, RADIUS_M - 1e-3));
    let mut group = c.benchmark_group("first_reading_of_a_sphere");
    for (name, mesh) in spheres {
        let object = ObjectSpec::new("sphere", mesh);
        group.bench_with_input(BenchmarkId::from_parameter(name), &object, |b, object| {
            b.iter(|| {
                let mut pad = FreePad::new(object.clone(), &config).expect("the sphere's scene compiles");
                pad.read_at(&pose).expect("the pad reads")
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = large_meshes;
    config = Criterion::default()
        .without_plots()
        .sample_size(10)
        .warm_up_time(std::time::Duration::from_millis(100))
        .measurement_time(std::time::Duration::from_secs(1));
    targets = bench_large_meshes
}

criterion_group! {
    name = benches;
    // No plots: the plotters backend needs system fonts a CI machine may not have.
    config = Criterion::default()
        .without_plots()
        .sample_size(20)
        .warm_up_time(std::time::Duration::from_millis(300))
        .measurement_time(std::time::Duration::from_secs(1));
    targets = bench_mesh
}
criterion_main!(benches, large_meshes);
