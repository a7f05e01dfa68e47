//! The covering sensor's cost per image at 6x6, 14x14 and 26x26 with 4 and 16 rays per taxel, on a
//! 20480-triangle mesh (an icosphere of 5 cm radius, pad pressed on it slightly tilted), against
//! the same rays cast by MuJoCo (`mj_multiRay` from a point 1 m behind the pad through the same
//! sample points, and `mj_ray` one by one), by plain `obvhs` closest-hit traversal, and against
//! MuJoCo's own `tactile` sensor with one point per taxel; then the cost per reading and the BVH
//! build time and memory on meshes of 1k to 1M triangles. Each resolution also times the reading's
//! stages alone (BVH query, rasterisation, image formation). The last step prints the tables
//! (means of this run, ratios within it).
//!
//! `plugin/read` is what a user pays: `mj_forward` (which runs the plugin) plus the copy out of
//! `sensordata`; `plugin/sensor_stage` is MuJoCo's position-sensor stage alone (`mj_sensorPos`,
//! where the plugin computes), the cost that compares with `mj_multiRay`;
//! `scene/forward_without_sensor` is the same scene's `mj_forward` with no sensor.
//!
//! MuJoCo's `tactile` sensor (`mjSENS_TACTILE`) reports, at each vertex of a mesh attached to a
//! geom, how deep the vertex lies inside the geoms in contact with that geom's body (their signed
//! distance field: the octree MuJoCo builds for a mesh used by an `sdf` geom). Its pad here is a
//! mesh whose vertices are the taxel centres on the covering's outer surface (pad plane + t along
//! the normal), on a body with a box the size of the covering that makes the contact; it is
//! computed at MuJoCo's velocity stage (`mj_sensorVel`), after the collision detection that finds
//! the contacts it needs, all in `mj_forward`.

#[path = "../tests/sensor_support/mod.rs"]
mod sensor_support;

use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::{DMat3, DVec3, Vec3A};
use mujoco_rs::mujoco_c::{mj_sensorPos, mj_sensorVel, mjData, mjModel};
use mujoco_rs::prelude::*;
use obvhs::BvhBuildParams;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use sensor_support::{geodesic_sphere, icosphere, taxel_centre};
use taction::control::FreePad;
use taction::mesh::TriMesh;
use taction::mesh::{BuildOptions, ObjectSet};
use taction::pose::PadPose;
use taction::sim::COLLISION_GROUP;
use taction::sim::numbers;
use taction::sim::{ObjectSpec, SceneBuilder};
use taction::tactile::pipeline::DepthBuffer;
use taction::tactile::pipeline::ImageFormation;
use taction::tactile::pipeline::MeshBvh;
use taction::tactile::pipeline::SampleGrid;
use taction::tactile::{SensorConfig, query_region};
use taction::tactile::{free_floating_builder, free_pad_body_xml};
use taction::valid::Valid;

const RADIUS_M: f64 = 0.05;
const RESOLUTIONS: [usize; 3] = [6, 14, 26];
const RAYS_PER_TAXEL: [usize; 2] = [4, 16];
/// Geodesic-sphere frequencies for the mesh-size series: 20 f^2 triangles = 980, 20480, 200000,
/// 1003520.
const FREQUENCIES: [u32; 4] = [7, 32, 100, 224];
const SERIES_TAXELS: usize = 14;

fn config(n: usize, rays_per_taxel: usize) -> SensorConfig {
    SensorConfig {
        rows: n,
        cols: n,
        rays_per_taxel,
        ..SensorConfig::default()
    }
}

/// The pad pressed on the top of the sphere, tilted 10°: the covering's outer surface 0.6 t inside
/// the sphere along the pad normal, the pad plane 0.4 t outside it, so the covering is partly
/// filled (taxel values from 0 to about 0.9) and the sensors' images differ where they should.
fn pad_pose(config: &SensorConfig) -> PadPose {
    let normal = DVec3::new(0.17, 0.05, -1.0).normalize();
    let center = -normal * (RADIUS_M + 0.4 * config.thickness_m);
    PadPose::new(center, normal, DVec3::Y).unwrap()
}

/// A mesh as the flat vertex coordinates and vertex-index triples MuJoCo stores (what
/// [`MeshBvh::new`] takes).
fn mesh_arrays(mesh: &TriMesh) -> (Vec<f32>, Vec<i32>) {
    let vertex_xyz = mesh
        .vertices
        .iter()
        .flat_map(|v| v.as_vec3().to_array())
        .collect();
    let face_indices = mesh.triangles.iter().flatten().map(|&i| i as i32).collect();
    (vertex_xyz, face_indices)
}

/// The reading's stages outside MuJoCo, on the sphere mesh placed at the world origin: the BVH
/// query for the faces that can meet the pad's rays (the sensor's own [`query_region`]), the orthographic rasterisation of those faces with the
/// inside test, and image formation (folded point-spread and area average, clamp).
fn stages(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    mesh: &TriMesh,
    config: &SensorConfig,
    pose: &PadPose,
) {
    let (vertex_xyz, face_indices) = mesh_arrays(mesh);
    let bvh = MeshBvh::new(&vertex_xyz, &face_indices).unwrap();
    let grid = SampleGrid::new(config);
    let t = config.thickness_m;
    // Pad (site) frame: x = up x normal, y = up, z = normal; the mesh sits at the world origin.
    let to_pad = DMat3::from_cols(pose.up.cross(pose.normal), pose.up, pose.normal).transpose();
    let o = to_pad * -pose.center_m;
    let region = query_region(&grid, (&to_pad, o), RADIUS_M, t);
    let (mut stack, mut leaves) = (Vec::new(), Vec::new());
    bvh.leaves_near(&region, &mut stack, &mut leaves);
    group.bench_function(BenchmarkId::new("stage", "bvh_query"), |b| {
        b.iter(|| {
            leaves.clear();
            bvh.leaves_near(black_box(&region), &mut stack, &mut leaves);
            black_box(leaves.len())
        })
    });
    let mut depth = DepthBuffer::new(&grid);
    // The depths the form stage reads, also when a filter skips the rasterise stage.
    depth.draw_mesh(&grid, &bvh, &leaves, (&to_pad, o), t);
    group.bench_function(BenchmarkId::new("stage", "rasterise"), |b| {
        b.iter(|| {
            depth.nearest_m.fill(f64::INFINITY);
            depth.draw_mesh(&grid, &bvh, &leaves, (&to_pad, o), t);
            black_box(depth.nearest_m[0])
        })
    });
    let nearest_m = &depth.nearest_m;
    let penetration_m: Vec<f64> = nearest_m.iter().map(|z| (t - z).clamp(0.0, t)).collect();
    let mut formation = ImageFormation::new(config, &grid);
    let mut image = vec![0.0; config.taxel_count()];
    group.bench_function(BenchmarkId::new("stage", "form"), |b| {
        b.iter(|| {
            formation.form(black_box(&penetration_m), 0, 0, &mut image);
            black_box(image[0])
        })
    });
}

/// World points where the pad's rays pierce the pad plane.
fn sample_points(config: &SensorConfig, pose: &PadPose) -> Vec<DVec3> {
    let grid = SampleGrid::new(config);
    (0..grid.rows)
        .flat_map(|i| (0..grid.cols).map(move |j| (i, j)))
        .map(|(i, j)| pose.center_m + pose.right() * grid.x(j) + pose.up * grid.y(i))
        .collect()
}

/// Raw pointers to a scene's model and data, for the MuJoCo stage functions the safe API lacks.
struct RawScene {
    m: *const mjModel,
    d: *mut mjData,
}

impl RawScene {
    fn of(free: &mut FreePad) -> Self {
        let m: *const mjModel = free.scene().model().ffi();
        // SAFETY: the pointer is only used while `free` is alive and not moved, by one thread.
        let d: *mut mjData = unsafe { free.scene_mut().data_mut().ffi_mut() };
        Self { m, d }
    }

    /// MuJoCo's position-sensor stage, where the covering plugin computes.
    fn sensor_pos(&self) {
        // SAFETY: m and d belong together and stay valid for the benchmark (see `of`).
        unsafe { mj_sensorPos(self.m, self.d) }
    }
}

/// MuJoCo's rays see the geom groups the covering senses: every group but the objects' collision
/// shells (`taction::sim::COLLISION_GROUP`), which would only add geoms for MuJoCo to test.
const SENSED_GROUPS: [u8; 6] = {
    let mut groups = [1; 6];
    groups[COLLISION_GROUP as usize] = 0;
    groups
};

/// `mj_multiRay` from 1 m behind the pad through each sample point, excluding the pad's body.
struct MultiRay {
    eye: [f64; 3],
    dirs: Vec<[f64; 3]>,
    pad_body: usize,
}

impl MultiRay {
    fn new(free: &FreePad, pose: &PadPose, points: &[DVec3]) -> Self {
        let eye = pose.center_m - pose.normal;
        Self {
            eye: eye.to_array(),
            dirs: points.iter().map(|p| (*p - eye).to_array()).collect(),
            pad_body: free.scene().model().site_bodyid()[free.covering().site_id()] as usize,
        }
    }

    fn cast(&self, free: &mut FreePad) -> f64 {
        let data = free.scene_mut().data_mut();
        let (_, dist) = data.multi_ray(
            &self.eye,
            &self.dirs,
            Some(&SENSED_GROUPS),
            true,
            Some(self.pad_body),
            2.0,
            None,
        );
        dist.iter().sum()
    }
}

/// The native-tactile scene: the object (static mesh geom, plus a non-colliding `sdf` geom on the
/// same mesh so that MuJoCo builds its octree), and a free pad body carrying a box the size of the
/// covering (it makes the contact) and the taxel mesh the `tactile` sensor samples.
fn native_scene(
    mesh: &TriMesh,
    config: &SensorConfig,
    pose: &PadPose,
    with_sensor: bool,
) -> MjData<Box<MjModel>> {
    let object_vertices = numbers(mesh.vertices.iter().flat_map(|v| v.to_array()));
    let object_faces = numbers(mesh.triangles.iter().flatten().map(|&i| i as f64));
    let t = config.thickness_m;
    // Pad (site) frame: x = up x normal = -right, y = up, z = normal; taxel centres on the
    // covering's outer surface, in the image's row-major order.
    let mut taxels = Vec::new();
    for r in 0..config.rows {
        for c in 0..config.cols {
            let (right, up) = taxel_centre(config, r, c);
            taxels.extend_from_slice(&[-right, up, t]);
        }
    }
    let mut faces = Vec::new();
    for r in 0..config.rows.saturating_sub(1) {
        for c in 0..config.cols.saturating_sub(1) {
            let a = (r * config.cols + c) as f64;
            let (b, d, e) = (a + 1.0, a + config.cols as f64, a + config.cols as f64 + 1.0);
            faces.extend_from_slice(&[a, b, d, b, e, d]);
        }
    }
    let q = pose.site_rotation();
    let sensor = if with_sensor {
        "<sensor><tactile name=\"native\" geom=\"pad_taxels\" mesh=\"taxels\"/></sensor>"
    } else {
        ""
    };
    let xml = format!(
        "<mujoco model=\"native_tactile\">\n\
         <asset>\n\
         <mesh name=\"object\" inertia=\"shell\" vertex=\"{object_vertices}\" face=\"{object_faces}\"/>\n\
         <mesh name=\"taxels\" inertia=\"shell\" vertex=\"{}\" face=\"{}\"/>\n\
         </asset>\n\
         <worldbody>\n\
         <geom name=\"object\" type=\"mesh\" mesh=\"object\"/>\n\
         <geom name=\"object_sdf\" type=\"sdf\" mesh=\"object\" contype=\"0\" conaffinity=\"0\"/>\n\
         <body name=\"pad\" pos=\"{}\" quat=\"{}\">\n<freejoint/>\n\
         <geom name=\"covering\" type=\"box\" size=\"{}\" pos=\"0 0 {}\" mass=\"0.01\"/>\n\
         <geom name=\"pad_taxels\" type=\"mesh\" mesh=\"taxels\" contype=\"0\" conaffinity=\"0\" mass=\"0\"/>\n\
         </body>\n\
         </worldbody>\n{sensor}\n</mujoco>",
        numbers(taxels),
        numbers(faces),
        numbers(pose.center_m.to_array()),
        numbers([q.w, q.x, q.y, q.z]),
        numbers([0.5 * config.pad_width_m, 0.5 * config.pad_height_m, 0.5 * t]),
        0.5 * t,
    );
    MjData::new(Box::new(MjModel::from_xml_string(&xml).unwrap()))
}

/// The native sensor's image: depth at each taxel point as a fraction of the covering, in [0, 1].
fn native_image(data: &MjData<Box<MjModel>>, config: &SensorConfig) -> Vec<f64> {
    let n = config.taxel_count();
    data.sensordata()[..n]
        .iter()
        .map(|d| (d / config.thickness_m).clamp(0.0, 1.0))
        .collect()
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

fn group_settings(group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>) {
    group
        .sample_size(20)
        .measurement_time(Duration::from_millis(1500))
        .warm_up_time(Duration::from_millis(300));
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

    for n in RESOLUTIONS {
        for rays_per_taxel in RAYS_PER_TAXEL {
            let config = config(n, rays_per_taxel);
            let pose = pad_pose(&config);
            let points = sample_points(&config, &pose);
            let t = config.thickness_m;
            let mut group = c.benchmark_group(format!("sensor/{n}x{n}x{rays_per_taxel}rays"));
            group_settings(&mut group);

            let mut free = FreePad::new(
                ObjectSpec::new("sphere", mesh.clone()),
                &Valid::new(config).unwrap(),
            )
            .unwrap();
            free.place(&pose);
            let image = free.read().unwrap();
            assert!(image.max() > 0.3, "the pad should touch the sphere");
            let stats = free
                .covering()
                .stats(free.scene().model(), free.scene().data())
                .unwrap();
            eprintln!(
                "{n}x{n}x{rays_per_taxel}: {} rays, {} faces rasterised",
                points.len(),
                stats.last_faces
            );
            group.bench_function(BenchmarkId::new("plugin", "read"), |b| {
                b.iter(|| black_box(free.read().unwrap()))
            });
            let raw = RawScene::of(&mut free);
            // The stage alone recomputes the same image.
            raw.sensor_pos();
            assert_eq!(
                free.covering().read(free.scene().data()).unwrap().values(),
                image.values()
            );
            group.bench_function(BenchmarkId::new("plugin", "sensor_stage"), |b| {
                b.iter(|| raw.sensor_pos())
            });

            stages(&mut group, &mesh, &config, &pose);

            let mut bare = SceneBuilder::new()
                .table(false)
                .object(ObjectSpec::new("sphere", mesh.clone()))
                .add(taction::sim::Section::Worldbody, free_pad_body_xml(&config))
                .build()
                .unwrap();
            {
                let q = pose.site_rotation();
                let data = bare.data_mut();
                data.mocap_pos_mut()[1] = pose.center_m.to_array();
                data.mocap_quat_mut()[1] = [q.w, q.x, q.y, q.z];
            }
            group.bench_function(BenchmarkId::new("scene", "forward_without_sensor"), |b| {
                b.iter(|| bare.forward())
            });

            let rays = MultiRay::new(&free, &pose, &points);
            group.bench_function(BenchmarkId::new("mujoco", "mj_multiRay"), |b| {
                b.iter(|| black_box(rays.cast(&mut free)))
            });

            if rays_per_taxel == 4 {
                let pad_body = free.scene().model().site_bodyid()[free.covering().site_id()] as usize;
                let dir = pose.normal.to_array();
                group.bench_function(BenchmarkId::new("mujoco", "mj_ray_each"), |b| {
                    b.iter(|| {
                        let data = free.scene_mut().data_mut();
                        let mut sum = 0.0;
                        for p in &points {
                            let (_, d) = data.ray(
                                &p.to_array(),
                                &dir,
                                Some(&SENSED_GROUPS),
                                true,
                                Some(pad_body),
                                None,
                            );
                            sum += d.min(t);
                        }
                        black_box(sum)
                    })
                });
            }

            let obvhs_rays: Vec<Ray> = points
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
                    for ray in &obvhs_rays {
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

            // MuJoCo's native tactile sensor depends only on the taxel count: once per resolution.
            if rays_per_taxel == RAYS_PER_TAXEL[0] {
                let mut native = native_scene(&mesh, &config, &pose, true);
                native.forward();
                assert!(native.ncon() > 0, "the native pad should touch the sphere");
                let native_values = native_image(&native, &config);
                let mut sharp = FreePad::new(
                    ObjectSpec::new("sphere", mesh.clone()),
                    &Valid::new(SensorConfig {
                        rays_per_taxel: 1,
                        psf_sigma_m: 0.0,
                        ..config
                    })
                    .unwrap(),
                )
                .unwrap();
                let sharp_values = sharp.read_at(&pose).unwrap().values().to_vec();
                let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
                let touched = |v: &[f64]| v.iter().filter(|&&x| x > 0.0).count();
                eprintln!(
                    "{n}x{n} native tactile vs covering: max |diff| {:.3} against 1 ray/taxel without PSF, \
                     {:.3} against the default reading; mean value {:.3} (native) / {:.3} (1 ray) / {:.3} \
                     (default); taxels in contact {} / {} / {}",
                    max_abs_diff(&native_values, &sharp_values),
                    max_abs_diff(&native_values, image.values()),
                    mean(&native_values),
                    mean(&sharp_values),
                    mean(image.values()),
                    touched(&native_values),
                    touched(&sharp_values),
                    touched(image.values()),
                );
                let d: *mut mjData = unsafe { native.ffi_mut() };
                let m: *const mjModel = native.model().ffi();
                // SAFETY: m and d belong together and outlive the closure's use, on one thread.
                group.bench_function(BenchmarkId::new("native_tactile", "sensor_stage"), |b| {
                    b.iter(|| unsafe { mj_sensorVel(m, d) })
                });
                group.bench_function(BenchmarkId::new("native_tactile", "forward"), |b| {
                    b.iter(|| native.forward())
                });
                let mut without = native_scene(&mesh, &config, &pose, false);
                group.bench_function(
                    BenchmarkId::new("native_tactile", "forward_without_sensor"),
                    |b| b.iter(|| without.forward()),
                );
            }
            group.finish();
        }
    }
}

/// The cost per reading (14x14, 4 rays per taxel) and of building the BVH as the mesh grows.
fn mesh_size(c: &mut Criterion) {
    for frequency in FREQUENCIES {
        let mesh = geodesic_sphere(DVec3::ZERO, RADIUS_M, frequency);
        let triangles = mesh.triangles.len();
        assert_eq!(triangles, 20 * (frequency * frequency) as usize);
        let mut group = c.benchmark_group(format!("sensor/mesh_{triangles}_triangles"));
        group_settings(&mut group);
        if triangles > 100_000 {
            group.sample_size(10);
        }

        let (vertex_xyz, face_indices) = mesh_arrays(&mesh);
        let bvh = MeshBvh::new(&vertex_xyz, &face_indices).unwrap();
        eprintln!("{triangles} triangles: BVH {} bytes", bvh.heap_bytes());
        record_extra(&format!("mesh_{triangles}/bvh_bytes"), bvh.heap_bytes() as f64);
        group.bench_function(BenchmarkId::new("bvh", "build"), |b| {
            b.iter(|| black_box(MeshBvh::new(&vertex_xyz, &face_indices).unwrap()))
        });

        let config = config(SERIES_TAXELS, 4);
        let pose = pad_pose(&config);
        let start = Instant::now();
        let mut free = FreePad::new(
            ObjectSpec::new("sphere", mesh.clone()),
            &Valid::new(config).unwrap(),
        )
        .unwrap();
        let compile_s = start.elapsed().as_secs_f64();
        eprintln!("{triangles} triangles: MuJoCo scene compiled in {compile_s:.2} s");
        record_extra(&format!("mesh_{triangles}/compile_s"), compile_s);
        free.place(&pose);
        assert!(
            free.read().unwrap().max() > 0.3,
            "the pad should touch the sphere"
        );
        group.bench_function(BenchmarkId::new("plugin", "read"), |b| {
            b.iter(|| black_box(free.read().unwrap()))
        });
        let raw = RawScene::of(&mut free);
        group.bench_function(BenchmarkId::new("plugin", "sensor_stage"), |b| {
            b.iter(|| raw.sensor_pos())
        });
        let points = sample_points(&config, &pose);
        let rays = MultiRay::new(&free, &pose, &points);
        group.bench_function(BenchmarkId::new("mujoco", "mj_multiRay"), |b| {
            b.iter(|| black_box(rays.cast(&mut free)))
        });
        group.finish();
    }
}

/// Building the scene: compiling the model, whose plugin init takes the BVH the first iteration
/// built (`tactile::shared_bvh`), as every scene of a mesh after the first does.
fn build(c: &mut Criterion) {
    let mesh = icosphere(DVec3::ZERO, RADIUS_M, 5);
    let mut group = c.benchmark_group("sensor/build");
    group.sample_size(10);
    group.bench_function("compile_scene_of_a_20k_triangle_mesh", |b| {
        b.iter(|| {
            black_box(
                free_floating_builder(
                    ObjectSpec::new("sphere", mesh.clone()),
                    &Valid::new(config(6, 4)).unwrap(),
                )
                .build()
                .unwrap(),
            )
        })
    });
    group.finish();
}

fn criterion_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"))
        .join("criterion")
}

/// Numbers measured outside criterion (memory, one-off compile times), for the summary.
fn record_extra(key: &str, value: f64) {
    let path = criterion_dir().join("sensor_extra.json");
    let mut extra: BTreeMap<String, f64> = std::fs::read_to_string(&path)
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or_default();
    extra.insert(key.to_string(), value);
    let _ = std::fs::create_dir_all(criterion_dir());
    let _ = std::fs::write(&path, serde_json::to_string_pretty(&extra).unwrap_or_default());
}

/// Mean time (ns) of every benchmark criterion has recorded, by full id (`group/function/value`).
fn means() -> BTreeMap<String, f64> {
    fn walk(dir: &Path, out: &mut BTreeMap<String, f64>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                if path.file_name().is_some_and(|n| n == "new") {
                    let read = |name: &str| -> Option<serde_json::Value> {
                        serde_json::from_str(&std::fs::read_to_string(path.join(name)).ok()?).ok()
                    };
                    if let (Some(bench), Some(est)) = (read("benchmark.json"), read("estimates.json"))
                        && let (Some(id), Some(mean)) =
                            (bench["full_id"].as_str(), est["mean"]["point_estimate"].as_f64())
                    {
                        out.insert(id.to_string(), mean);
                    }
                } else {
                    walk(&path, out);
                }
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(&criterion_dir(), &mut out);
    out
}

fn format_ns(ns: f64) -> String {
    if ns >= 1e6 {
        format!("{:.2} ms", ns / 1e6)
    } else if ns >= 1e3 {
        format!("{:.1} us", ns / 1e3)
    } else {
        format!("{ns:.0} ns")
    }
}

/// Prints the tables of this run from criterion's records.
fn summary(_: &mut Criterion) {
    let means = means();
    let get = |id: String| means.get(&id).copied();
    let cell = |v: Option<f64>| v.map(format_ns).unwrap_or_else(|| "-".into());
    let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => format!("{:.1}x", a / b),
        _ => "-".into(),
    };
    println!("\nCovering sensor per reading, 20480-triangle sphere (means of this run):\n");
    println!(
        "| image | plugin read | sensor stage | mj_multiRay, same rays | multiRay / stage | obvhs traversal | obvhs / stage | native tactile stage | native forward (without) | native stage / stage |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for n in RESOLUTIONS {
        for rays in RAYS_PER_TAXEL {
            let g = format!("sensor/{n}x{n}x{rays}rays");
            let read = get(format!("{g}/plugin/read"));
            let stage = get(format!("{g}/plugin/sensor_stage"));
            let multi = get(format!("{g}/mujoco/mj_multiRay"));
            let obvhs = get(format!("{g}/obvhs/cwbvh_closest_hit"));
            let ng = format!("sensor/{n}x{n}x{}rays", RAYS_PER_TAXEL[0]);
            let native_stage = get(format!("{ng}/native_tactile/sensor_stage"));
            let native_forward = get(format!("{ng}/native_tactile/forward"));
            let native_without = get(format!("{ng}/native_tactile/forward_without_sensor"));
            println!(
                "| {n}x{n}, {rays} rays/taxel | {} | {} | {} | {} | {} | {} | {} | {} ({}) | {} |",
                cell(read),
                cell(stage),
                cell(multi),
                ratio(multi, stage),
                cell(obvhs),
                ratio(obvhs, stage),
                cell(native_stage),
                cell(native_forward),
                cell(native_without),
                ratio(native_stage, stage),
            );
        }
    }
    println!("\nWhere the sensor stage goes (means of this run):\n");
    println!(
        "| image | BVH query | rasterise | form image | rest: MuJoCo's loop, poses, rigid-back test (noisy difference) | sensor stage |"
    );
    println!("|---|---|---|---|---|---|");
    for n in RESOLUTIONS {
        for rays in RAYS_PER_TAXEL {
            let g = format!("sensor/{n}x{n}x{rays}rays");
            let stage = get(format!("{g}/plugin/sensor_stage"));
            let parts = ["bvh_query", "rasterise", "form"].map(|s| get(format!("{g}/stage/{s}")));
            let rest = match (stage, parts) {
                (Some(total), [Some(a), Some(b), Some(c)]) => Some(total - a - b - c),
                _ => None,
            };
            println!(
                "| {n}x{n}, {rays} rays/taxel | {} | {} | {} | {} | {} |",
                cell(parts[0]),
                cell(parts[1]),
                cell(parts[2]),
                cell(rest),
                cell(stage),
            );
        }
    }
    let extra: BTreeMap<String, f64> = std::fs::read_to_string(criterion_dir().join("sensor_extra.json"))
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or_default();
    println!("\nMesh size ({SERIES_TAXELS}x{SERIES_TAXELS}, 4 rays per taxel, geodesic spheres):\n");
    println!(
        "| triangles | plugin read | sensor stage | mj_multiRay | multiRay / stage | BVH build | BVH memory | MuJoCo compile of the scene |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for frequency in FREQUENCIES {
        let triangles = 20 * (frequency * frequency) as usize;
        let g = format!("sensor/mesh_{triangles}_triangles");
        let stage = get(format!("{g}/plugin/sensor_stage"));
        let multi = get(format!("{g}/mujoco/mj_multiRay"));
        let bytes = extra.get(&format!("mesh_{triangles}/bvh_bytes"));
        let compile = extra.get(&format!("mesh_{triangles}/compile_s"));
        println!(
            "| {triangles} | {} | {} | {} | {} | {} | {} | {} |",
            cell(get(format!("{g}/plugin/read"))),
            cell(stage),
            cell(multi),
            ratio(multi, stage),
            cell(get(format!("{g}/bvh/build"))),
            bytes
                .map(|b| format!("{:.1} MB", b / 1e6))
                .unwrap_or_else(|| "-".into()),
            compile.map(|s| format!("{s:.2} s")).unwrap_or_else(|| "-".into()),
        );
    }
}

/// The reading `taction.Sensor().read(pawn, pose)` makes from Python (`benches/python_reading.py`
/// times that call against this one): the paper's 6x6 sensor on the free pad, placed 0.6 mm into the
/// top of the chess pawn, then read.
fn python_parity(c: &mut Criterion) {
    let pawn = ObjectSet::chess()
        .build_object("pawn", &BuildOptions::default())
        .unwrap();
    let top_m = pawn.mesh.vertices.iter().map(|v| v.z).fold(f64::MIN, f64::max);
    let pose = PadPose::new(DVec3::new(0.0, 0.0, top_m + 0.0006), DVec3::NEG_Z, DVec3::Y).unwrap();
    let config = Valid::new(SensorConfig::paper()).unwrap();
    let mut pad = FreePad::new(ObjectSpec::from(pawn), &config).unwrap();
    assert!(
        pad.read_at(&pose).unwrap().max() > 0.0,
        "the pad should touch the pawn"
    );
    let mut group = c.benchmark_group("sensor/python_parity");
    group_settings(&mut group);
    group.bench_function("free_pad_read_at_6x6", |b| {
        b.iter(|| black_box(pad.read_at(&pose).unwrap()))
    });
    group.finish();
}

criterion_group! {
    name = benches;
    // Criterion's plot backend fails on this machine (no fonts for its PDF plots); numbers only.
    config = Criterion::default().without_plots().output_directory(&criterion_dir());
    targets = sensor, mesh_size, build, python_parity, summary
}
criterion_main!(benches);
