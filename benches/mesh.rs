//! Object preparation costs: parsing and validating a real mesh (the 10k-vertex dragon OFF, fetched
//! on first use), normalising it, generating a chess piece and a raised letter.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use taction::mesh::ChessPiece;
use taction::mesh::Font;
use taction::mesh::{
    CGAL_MESHES, MeshFormat, ValidationReport, ensure_fetched, normalise_to_diagonal, parse,
};
use taction::mesh::{LetterStyle, alphabet, raised_letter};

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
criterion_main!(benches);
