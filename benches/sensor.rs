//! The covering sensor's cost per image at 6x6, 14x14 and 26x26 with 4 rays per taxel, on a
//! 20480-triangle mesh (an icosphere of 5 cm radius, pad pressed on it slightly tilted), against
//! the same rays cast by MuJoCo (`mj_ray` one by one, and `mj_multiRay` from a point 1 m behind
//! the pad through the same sample points) and by plain `obvhs` closest-hit traversal.
//!
//! `plugin/read` is what a user pays: `mj_forward` (which runs the plugin) plus the copy out of
//! `sensordata`; `scene/forward_without_sensor` is the same scene's `mj_forward` with no sensor.

#[path = "../tests/sensor_support/mod.rs"]
mod sensor_support;

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::{DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use sensor_support::icosphere;
use taction::sim::{ObjectSpec, SceneBuilder};
use taction::tactile::free_floating::{free_floating_builder, free_pad_body_xml, pad_rotation};
use taction::tactile::grid::SampleGrid;
use taction::tactile::{FreeFloatingSensor, PadPose, SensorConfig};

const RADIUS_M: f64 = 0.05;

fn config(n: usize) -> SensorConfig {
    SensorConfig {
        rows: n,
        cols: n,
        rays_per_taxel: 4,
        ..SensorConfig::default()
    }
}

/// The pad pressed 0.6 t into the top of the sphere, tilted 10°.
fn pad_pose(config: &SensorConfig) -> PadPose {
    let normal = DVec3::new(0.17, 0.05, -1.0).normalize();
    let center = -normal * (RADIUS_M - 0.6 * config.thickness_m);
    PadPose::new(center, normal, DVec3::Y).unwrap()
}

/// World points where the pad's rays pierce the pad plane.
fn sample_points(config: &SensorConfig, pose: &PadPose) -> Vec<DVec3> {
    let grid = SampleGrid::new(config);
    (0..grid.rows)
        .flat_map(|i| (0..grid.cols).map(move |j| (i, j)))
        .map(|(i, j)| pose.center_m + pose.right() * grid.x(j) + pose.up * grid.y(i))
        .collect()
}

fn sensor(c: &mut Criterion) {
    let mesh = icosphere(DVec3::ZERO, RADIUS_M, 5);
    assert_eq!(mesh.triangles.len(), 20480);
    let triangles: Vec<Triangle> = mesh
        .triangles
        .iter()
        .map(|t| {
            let p = |i: u32| Vec3A::from(mesh.vertices[i as usize].as_vec3());
            Triangle {
                v0: p(t[0]),
                v1: p(t[1]),
                v2: p(t[2]),
            }
        })
        .collect();
    let cwbvh = build_cwbvh_from_tris(
        &triangles,
        BvhBuildParams::medium_build(),
        &mut Duration::default(),
    );

    for n in [6usize, 14, 26] {
        let config = config(n);
        let pose = pad_pose(&config);
        let points = sample_points(&config, &pose);
        let t = config.thickness_m;
        let mut group = c.benchmark_group(format!("sensor/{n}x{n}x4rays"));
        group
            .sample_size(30)
            .measurement_time(Duration::from_secs(3))
            .warm_up_time(Duration::from_millis(500));

        let mut free = FreeFloatingSensor::new(ObjectSpec::new("sphere", mesh.clone()), &config).unwrap();
        free.place(&pose);
        let image = free.read().unwrap();
        assert!(image.max() > 0.3, "the pad should touch the sphere");
        let stats = free
            .sensor()
            .stats(free.scene().model(), free.scene().data())
            .unwrap();
        eprintln!(
            "{n}x{n}: {} rays, {} faces rasterised",
            points.len(),
            stats.last_faces
        );
        group.bench_function(BenchmarkId::new("plugin", "read"), |b| {
            b.iter(|| black_box(free.read().unwrap()))
        });

        let mut bare = SceneBuilder::new()
            .table(false)
            .object(ObjectSpec::new("sphere", mesh.clone()))
            .add(taction::sim::mjcf::Section::Worldbody, free_pad_body_xml(&config))
            .build()
            .unwrap();
        {
            let q = pad_rotation(&pose);
            let data = bare.data_mut();
            data.mocap_pos_mut()[1] = pose.center_m.to_array();
            data.mocap_quat_mut()[1] = [q.w, q.x, q.y, q.z];
        }
        group.bench_function(BenchmarkId::new("scene", "forward_without_sensor"), |b| {
            b.iter(|| bare.forward())
        });

        let pad_body = free.scene().model().site_bodyid()[free.sensor().site_id()] as usize;
        let dir = pose.normal.to_array();
        group.bench_function(BenchmarkId::new("mujoco", "mj_ray_each"), |b| {
            b.iter(|| {
                let data = free.scene_mut().data_mut();
                let mut sum = 0.0;
                for p in &points {
                    let (_, d) = data.ray(&p.to_array(), &dir, None, true, Some(pad_body), None);
                    sum += d.min(t);
                }
                black_box(sum)
            })
        });

        let eye = pose.center_m - pose.normal;
        let dirs: Vec<[f64; 3]> = points.iter().map(|p| (*p - eye).to_array()).collect();
        group.bench_function(BenchmarkId::new("mujoco", "mj_multiRay"), |b| {
            b.iter(|| {
                let data = free.scene_mut().data_mut();
                black_box(data.multi_ray(&eye.to_array(), &dirs, None, true, Some(pad_body), 2.0, None))
            })
        });

        let rays: Vec<Ray> = points
            .iter()
            .map(|p| {
                Ray::new(
                    Vec3A::from(p.as_vec3()),
                    Vec3A::from(pose.normal.as_vec3()),
                    0.0,
                    t as f32,
                )
            })
            .collect();
        group.bench_function(BenchmarkId::new("obvhs", "cwbvh_closest_hit"), |b| {
            b.iter(|| {
                let mut sum = 0.0f32;
                for ray in &rays {
                    let mut hit = RayHit::none();
                    if cwbvh.ray_traverse(*ray, &mut hit, |r, id| {
                        triangles[cwbvh.primitive_indices[id] as usize].intersect(r)
                    }) {
                        sum += hit.t;
                    }
                }
                black_box(sum)
            })
        });
        group.finish();
    }
}

/// Building the scene: compiling the model and building the BVH in the plugin's init.
fn build(c: &mut Criterion) {
    let mesh = icosphere(DVec3::ZERO, RADIUS_M, 5);
    let mut group = c.benchmark_group("sensor/build");
    group.sample_size(10);
    group.bench_function("compile_scene_with_20k_triangle_bvh", |b| {
        b.iter(|| {
            black_box(
                free_floating_builder(ObjectSpec::new("sphere", mesh.clone()), &config(6))
                    .unwrap()
                    .build()
                    .unwrap(),
            )
        })
    });
    group.finish();
}

criterion_group! {
    name = benches;
    // Criterion's plot backend fails on this machine (no fonts for its PDF plots); numbers only.
    config = Criterion::default().without_plots();
    targets = sensor, build
}
criterion_main!(benches);
