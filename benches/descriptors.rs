//! Per-image time of each descriptor of Sec. IV-B at the paper's three resolutions (6x6, 14x14,
//! 26x26), each descriptor built once and reused as in training (FFT plans and filter banks cached).

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::RngExt;
use taction::describe::DescriptorKind;
use taction::rng::stream;
use taction::tactile::TactileImage;

/// A seeded contact-like image: an off-centre elliptical bump over a soft edge, plus taxel noise.
fn contact_image(n: usize, seed: u64) -> TactileImage {
    let mut rng = stream(seed, n as u64);
    let (cx, cy) = (rng.random_range(-0.3..0.3), rng.random_range(-0.3..0.3));
    let angle: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let (s, c) = angle.sin_cos();
    let values = (0..n * n)
        .map(|i| {
            let x = 2.0 * ((i % n) as f64 + 0.5) / n as f64 - 1.0;
            let y = 1.0 - 2.0 * ((i / n) as f64 + 0.5) / n as f64;
            let (u, v) = (c * (x - cx) + s * (y - cy), -s * (x - cx) + c * (y - cy));
            let bump = 0.8 * (-(u * u / 0.18 + v * v / 0.05)).exp();
            let edge = 0.3 / (1.0 + (-(x * s - y * c) / 0.15).exp());
            (bump + edge + rng.random_range(0.0..0.05)).clamp(0.0, 1.0)
        })
        .collect();
    TactileImage::new(n, n, values).expect("values are clamped to [0, 1]")
}

fn descriptors(c: &mut Criterion) {
    for kind in DescriptorKind::ALL {
        let descriptor = kind.build();
        let mut group = c.benchmark_group(format!("describe/{}", kind.name()));
        for n in [6, 14, 26] {
            let image = contact_image(n, 2011);
            // Warm the caches (FFT plans, filter bank) outside the measurement.
            black_box(descriptor.describe(&image));
            group.bench_with_input(
                BenchmarkId::from_parameter(format!("{n}x{n}")),
                &image,
                |b, image| b.iter(|| descriptor.describe(black_box(image))),
            );
        }
        group.finish();
    }
}

criterion_group! {
    name = benches;
    // No plots: the plotters backend needs system fonts a CI machine may not have.
    config = Criterion::default()
        .without_plots()
        .sample_size(30)
        .warm_up_time(std::time::Duration::from_millis(300))
        .measurement_time(std::time::Duration::from_secs(1));
    targets = descriptors
}
criterion_main!(benches);
