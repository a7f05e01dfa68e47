//! A toy object set for the recognition tests: three "objects" whose surfaces read as ridges,
//! bumps, or flat, at random orientation, phase and position, with uniform noise.
#![allow(dead_code)]

use std::f64::consts::PI;

use rand::RngExt;
use taction::dataset::ContactStatus;
use taction::dataset::Strategy;
use taction::dataset::{Dataset, DatasetHeader, Reading};
use taction::pose::Pose;
use taction::rng::{Rng, stream};
use taction::tactile::{SensorConfig, TactileImage};

pub const SIZE: usize = 8;
pub const OBJECTS: [&str; 3] = ["ridges", "bumps", "flat"];

pub fn sensor() -> SensorConfig {
    SensorConfig {
        rows: SIZE,
        cols: SIZE,
        pad_width_m: 0.012,
        pad_height_m: 0.012,
        thickness_m: 0.0012,
        psf_sigma_m: 0.0,
        rays_per_taxel: 1,
        noise_fraction: 0.05,
        noise_seed: 0,
    }
}

/// One reading of `object` (an index of [`OBJECTS`]).
pub fn image(object: usize, rng: &mut Rng) -> TactileImage {
    let theta = rng.random::<f64>() * PI;
    let phase = rng.random::<f64>() * 2.0 * PI;
    let (bx, by) = (rng.random::<f64>() * 2.0 - 1.0, rng.random::<f64>() * 2.0 - 1.0);
    let mut values = Vec::with_capacity(SIZE * SIZE);
    for r in 0..SIZE {
        for c in 0..SIZE {
            let (x, y) = (c as f64 - 3.5, r as f64 - 3.5);
            let clean = match object {
                // Stripes 3 taxels apart.
                0 => 0.5 + 0.4 * ((x * theta.cos() + y * theta.sin()) * 2.0 * PI / 3.0 + phase).sin(),
                // One round bump of radius ~2 taxels near the centre.
                1 => 0.15 + 0.8 * (-((x - bx).powi(2) + (y - by).powi(2)) / 4.0).exp(),
                _ => 0.5,
            };
            let noise = (rng.random::<f64>() - 0.5) * 0.1;
            values.push((clean + noise).clamp(0.0, 1.0));
        }
    }
    TactileImage::new(SIZE, SIZE, values).expect("toy values are in [0, 1]")
}

/// `per_object` readings of each object, interleaved, all converged, seeded.
pub fn dataset(per_object: usize, seed: u64) -> Dataset {
    let header = DatasetHeader::new(
        sensor(),
        "toy",
        OBJECTS.iter().map(|s| s.to_string()).collect(),
        format!("toy seed={seed}"),
        seed,
    );
    let mut readings = Vec::new();
    for i in 0..per_object {
        for (j, name) in OBJECTS.iter().enumerate() {
            let mut rng = stream(seed, (i * OBJECTS.len() + j) as u64);
            readings.push(Reading {
                image: image(j, &mut rng),
                object: name.to_string(),
                object_pose: Pose::IDENTITY,
                object_pose_after: None,
                status: ContactStatus::Converged,
                iterations: 3,
                strategy: Strategy::Sampler,
                cause: None,
                contact: None,
            });
        }
    }
    Dataset::new(header, readings).expect("toy readings match the header")
}

/// A standard normal draw (Box-Muller).
pub fn normal(rng: &mut Rng) -> f64 {
    let u = 1.0 - rng.random::<f64>();
    let v = rng.random::<f64>();
    (-2.0 * u.ln()).sqrt() * (2.0 * PI * v).cos()
}
