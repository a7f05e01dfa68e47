//! Shapes and scenes shared by the sensor tests and the sensor benchmark.
#![allow(dead_code)]

use std::collections::HashMap;

use glam::DVec3;
use taction::control::FreePad;
use taction::mesh::TriMesh;
use taction::pose::PadPose;
use taction::sim::SceneBuilder;
use taction::sim::Section;
use taction::tactile::free_pad_body_xml;
use taction::tactile::{SensorConfig, add_sensor};
use taction::valid::Valid;

/// The unit icosahedron: 12 vertices, 20 outward faces.
fn icosahedron() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let p = (1.0 + 5f64.sqrt()) / 2.0;
    let vertices: Vec<DVec3> = [
        (-1.0, p, 0.0),
        (1.0, p, 0.0),
        (-1.0, -p, 0.0),
        (1.0, -p, 0.0),
        (0.0, -1.0, p),
        (0.0, 1.0, p),
        (0.0, -1.0, -p),
        (0.0, 1.0, -p),
        (p, 0.0, -1.0),
        (p, 0.0, 1.0),
        (-p, 0.0, -1.0),
        (-p, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    (vertices, faces)
}

/// An icosphere of radius `radius_m` about `center_m`: the icosahedron with every face split into
/// four `subdivisions` times, vertices pushed onto the sphere; 20 * 4^subdivisions outward faces.
pub fn icosphere(center_m: DVec3, radius_m: f64, subdivisions: u32) -> TriMesh {
    let (mut vertices, mut faces) = icosahedron();
    for _ in 0..subdivisions {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, vertices: &mut Vec<DVec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                vertices.push(((vertices[a as usize] + vertices[b as usize]) * 0.5).normalize());
                (vertices.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let ab = midpoint(a, b, &mut vertices);
            let bc = midpoint(b, c, &mut vertices);
            let ca = midpoint(c, a, &mut vertices);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    TriMesh {
        vertices: vertices.into_iter().map(|v| center_m + v * radius_m).collect(),
        triangles: faces,
    }
}

/// A geodesic sphere of radius `radius_m` about `center_m`: every icosahedron face cut into a
/// triangular lattice of `frequency^2` triangles, vertices pushed onto the sphere; exactly
/// `20 * frequency^2` outward faces (so any size near a target, unlike the 4x steps of
/// [`icosphere`]), closed: lattice points shared by two faces are one vertex.
pub fn geodesic_sphere(center_m: DVec3, radius_m: f64, frequency: u32) -> TriMesh {
    let (corners, base_faces) = icosahedron();
    let m = frequency.max(1);
    let mut vertices = Vec::new();
    let mut index: HashMap<[(u32, u32); 3], u32> = HashMap::new();
    // A lattice point is named by its (corner, weight) pairs in corner order, so the faces that
    // share it compute it identically and find the same vertex.
    let mut vertex = |weights: [(u32, u32); 3], vertices: &mut Vec<DVec3>| -> u32 {
        let mut key = weights.map(|(c, w)| if w == 0 { (u32::MAX, 0) } else { (c, w) });
        key.sort_unstable();
        *index.entry(key).or_insert_with(|| {
            let p: DVec3 = key
                .iter()
                .filter(|(c, _)| *c != u32::MAX)
                .map(|&(c, w)| corners[c as usize] * w as f64)
                .sum();
            vertices.push(center_m + p.normalize() * radius_m);
            (vertices.len() - 1) as u32
        })
    };
    let mut triangles = Vec::with_capacity(20 * (m * m) as usize);
    for [a, b, c] in base_faces {
        // Lattice point (i, j) = ((m - i - j) a + i b + j c) / m.
        let mut p =
            |i: u32, j: u32, vertices: &mut Vec<DVec3>| vertex([(a, m - i - j), (b, i), (c, j)], vertices);
        for i in 0..m {
            for j in 0..m - i {
                let t = [
                    p(i, j, &mut vertices),
                    p(i + 1, j, &mut vertices),
                    p(i, j + 1, &mut vertices),
                ];
                triangles.push(t);
                if i + j + 1 < m {
                    let t = [
                        p(i + 1, j, &mut vertices),
                        p(i + 1, j + 1, &mut vertices),
                        p(i, j + 1, &mut vertices),
                    ];
                    triangles.push(t);
                }
            }
        }
    }
    TriMesh { vertices, triangles }
}

/// A closed axis-aligned box mesh between `lo` and `hi`, outward faces.
pub fn box_between(lo: DVec3, hi: DVec3) -> TriMesh {
    let vertices = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    TriMesh { vertices, triangles }
}

/// A free-floating sensor scene around arbitrary world MJCF (primitive geoms etc.).
pub fn free_sensor_with(world_xml: &str, config: &SensorConfig) -> FreePad {
    let builder = SceneBuilder::new()
        .table(false)
        .add(Section::Worldbody, world_xml)
        .add(Section::Worldbody, free_pad_body_xml(config));
    let builder = add_sensor(builder, &Valid::new(*config).unwrap(), "pad");
    FreePad::from_scene(builder.build().unwrap()).unwrap()
}

/// A pad at `center` looking straight down (-z), image up along +y.
pub fn pad_looking_down(center_m: DVec3) -> PadPose {
    PadPose::new(center_m, DVec3::NEG_Z, DVec3::Y).unwrap()
}

/// Centre of taxel (`row`, `col`) in the pad frame: (right, up), metres.
pub fn taxel_centre(config: &SensorConfig, row: usize, col: usize) -> (f64, f64) {
    let x = ((col as f64 + 0.5) / config.cols as f64 - 0.5) * config.pad_width_m;
    let y = (0.5 - (row as f64 + 0.5) / config.rows as f64) * config.pad_height_m;
    (x, y)
}

/// A sharp config: one ray per taxel, no point-spread, no noise.
pub fn sharp(rows: usize, cols: usize) -> SensorConfig {
    SensorConfig {
        rows,
        cols,
        psf_sigma_m: 0.0,
        rays_per_taxel: 1,
        ..SensorConfig::default()
    }
}

/// `mjcf/scene.xml` (the arm with the paper's sensor on its pad) compiled, put at its keyframe
/// "touch" (the pad pressed onto the example object's cylinder rim), after `mj_forward`.
pub fn shipped_scene_at_touch() -> (taction::sim::Scene, taction::tactile::CoveringSensor) {
    use mujoco_rs::prelude::*;
    taction::tactile::ensure_registered();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("mjcf/scene.xml");
    let model = MjModel::from_xml(path).expect("mjcf/scene.xml compiles");
    let key = model
        .name_to_id(MjtObjBase::mjOBJ_KEY, "touch")
        .expect("mjcf/scene.xml has the keyframe 'touch'");
    let mut scene = taction::sim::Scene::new(model, None).expect("a scene of mjcf/scene.xml");
    scene.data_mut().reset_keyframe(key).expect("keyframe 'touch'");
    scene.forward();
    let sensor = taction::tactile::CoveringSensor::first(scene.model()).expect("its covering sensor");
    (scene, sensor)
}
