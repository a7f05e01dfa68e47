//! The covering sensor plugin against analytic answers, in real MuJoCo scenes.

mod sensor_support;

use glam::DVec3;
use sensor_support::*;
use taction::tactile::SensorConfig;

#[test]
fn plane_parallel_at_distance_reads_uniform_fraction() {
    for config in [
        SensorConfig::default(),
        SensorConfig {
            psf_sigma_m: 0.0,
            rays_per_taxel: 1,
            ..SensorConfig::default()
        },
        SensorConfig {
            rows: 14,
            cols: 14,
            psf_sigma_m: 0.003,
            rays_per_taxel: 9,
            ..SensorConfig::default()
        },
    ] {
        let mut sensor = free_sensor_with("<geom name=\"floor\" type=\"plane\" size=\"1 1 0.1\"/>", &config);
        let t = config.thickness_m;
        let d = 0.35 * t;
        let image = sensor
            .read_at(&pad_looking_down(DVec3::new(0.01, -0.02, d)))
            .unwrap();
        let want = (t - d) / t;
        for v in image.values() {
            assert!((v - want).abs() < 1e-6, "{v} vs {want} ({config:?})");
        }
    }
}

/// Compiles a scene whose sensor has the raw `<config>` pairs given, returning MuJoCo's error text.
fn compile_error(pairs: &[(&str, &str)]) -> Option<String> {
    use taction::sim::SceneBuilder;
    use taction::sim::Section;
    taction::tactile::ensure_registered();
    let config: String = pairs
        .iter()
        .map(|(k, v)| format!("<config key=\"{k}\" value=\"{v}\"/>"))
        .collect();
    let builder = SceneBuilder::new()
        .table(false)
        .add(Section::Worldbody, "<geom type=\"plane\" size=\"1 1 0.1\"/><body name=\"b\" mocap=\"true\"><site name=\"pad\"/></body>")
        .add(Section::Extension, taction::tactile::extension_xml())
        .add(
            Section::Sensor,
            format!("<plugin name=\"c\" plugin=\"taction.covering\" objtype=\"site\" objname=\"pad\">{config}</plugin>"),
        );
    builder.build().err().map(|e| e.to_string())
}

#[test]
fn bad_config_fails_compilation_naming_the_key_and_range() {
    assert_eq!(compile_error(&[("rows", "14"), ("noise_fraction", "0.1")]), None);
    let cases = [
        ("rows", "0", "integer 1-256"),
        ("cols", "1000", "integer 1-256"),
        ("cols", "six", "integer 1-256"),
        ("pad_width_m", "0", "metres in (0, 1]"),
        ("pad_height_m", "-0.012", "metres in (0, 1]"),
        ("thickness_m", "abc", "metres in (0, 1]"),
        ("psf_sigma_m", "-0.001", "metres in [0, 1]"),
        ("rays_per_taxel", "3", "perfect square 1-64"),
        ("noise_fraction", "3", "fraction in [0, 2]"),
        ("noise_seed", "-5", "unsigned 64-bit integer"),
    ];
    for (key, value, range) in cases {
        let message = compile_error(&[(key, value)]).unwrap_or_else(|| panic!("{key}={value} compiled"));
        assert!(
            message.contains(&format!("{key}=")) && message.contains(range),
            "{key}={value}: {message}"
        );
    }
    let message = compile_error(&[("colour", "red")]).expect("unknown key compiled");
    assert!(message.contains("colour"), "{message}");
}

use glam::DQuat;
use taction::control::FreePad;
use taction::pose::PadPose;
use taction::pose::Pose;
use taction::sim::COLLISION_GROUP;
use taction::sim::{ObjectMount, ObjectSpec};
use taction::tactile::TactileImage;
use taction::valid::Valid;

/// The analytic depth of the ray through pad point (x, y) to the plane z = 0 (pad above it).
fn depth_to_floor(pose: &PadPose, x: f64, y: f64) -> f64 {
    let p = pose.center_m + pose.right() * x + pose.up * y;
    -p.z / pose.normal.z
}

fn max_abs_diff(a: &TactileImage, b: &[f64]) -> f64 {
    a.values()
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn tilted_plane_follows_the_analytic_ramp() {
    let config = sharp(14, 14);
    let t = config.thickness_m;
    let tilt = 8f64.to_radians();
    let normal = DVec3::new(0.3 * tilt.sin(), tilt.sin(), -tilt.cos()).normalize();
    let pose = PadPose::new(
        DVec3::new(0.002, 0.001, 0.0009),
        normal,
        DVec3::new(0.2, 1.0, 0.0),
    )
    .unwrap();
    let want: Vec<f64> = (0..config.rows)
        .flat_map(|r| (0..config.cols).map(move |c| (r, c)))
        .map(|(r, c)| {
            let (x, y) = taxel_centre(&config, r, c);
            ((t - depth_to_floor(&pose, x, y)) / t).clamp(0.0, 1.0)
        })
        .collect();
    assert!(
        want.contains(&0.0) && want.iter().any(|&v| v > 0.5),
        "the ramp should cross the range"
    );
    // The same ramp from MuJoCo's plane (analytic path) and from a box mesh (BVH + raster path).
    let mut plane = free_sensor_with("<geom type=\"plane\" size=\"1 1 0.1\"/>", &config);
    assert!(max_abs_diff(&plane.read_at(&pose).unwrap(), &want) < 1e-4);
    let slab = box_between(DVec3::new(-0.04, -0.03, -0.02), DVec3::new(0.05, 0.04, 0.0));
    let mut mesh = FreePad::new(ObjectSpec::new("slab", slab), &Valid::new(config).unwrap()).unwrap();
    let image = mesh.read_at(&pose).unwrap();
    assert!(max_abs_diff(&image, &want) < 1e-4, "{image}");
}

/// The spherical cap of a sphere of radius `r` whose apex penetrates the covering by `h`, at
/// pad-plane distance `rho` from the apex axis, as a fraction of `t`.
fn cap(r: f64, h: f64, t: f64, rho: f64) -> f64 {
    if rho >= r {
        return 0.0;
    }
    ((h - r + (r * r - rho * rho).sqrt()) / t).clamp(0.0, 1.0)
}

#[test]
fn pressed_sphere_matches_the_spherical_cap() {
    let config = sharp(26, 26);
    let t = config.thickness_m;
    let (r, h) = (0.005, 0.8 * t);
    // Pad at the origin looking down; apex at depth t - h below the pad, axis through (x0, y0).
    let (x0, y0) = (0.0011, -0.0007);
    let centre = DVec3::new(x0, y0, -(t - h) - r);
    let want: Vec<f64> = (0..config.rows)
        .flat_map(|i| (0..config.cols).map(move |j| (i, j)))
        .map(|(i, j)| {
            let (x, y) = taxel_centre(&config, i, j);
            cap(r, h, t, ((x - x0).powi(2) + (y - y0).powi(2)).sqrt())
        })
        .collect();
    let pose = pad_looking_down(DVec3::ZERO);
    let sphere_xml = format!(
        "<geom type=\"sphere\" size=\"{r}\" pos=\"{} {} {}\"/>",
        centre.x, centre.y, centre.z
    );
    let exact = free_sensor_with(&sphere_xml, &config).read_at(&pose).unwrap();
    assert!(
        max_abs_diff(&exact, &want) < 1e-9,
        "{}\n{exact}",
        max_abs_diff(&exact, &want)
    );
    let mesh = icosphere(centre, r, 4);
    let mut sensor = FreePad::new(ObjectSpec::new("sphere", mesh), &Valid::new(config).unwrap()).unwrap();
    let image = sensor.read_at(&pose).unwrap();
    let err = max_abs_diff(&image, &want);
    assert!(
        err < 0.02,
        "mesh sphere off the cap by {err} of the range\n{image}"
    );
    assert!((image.max() - h / t).abs() < 0.02);
}

/// An asymmetric tetrahedron poking through the pad plane near the pad centre.
fn wedge() -> taction::mesh::TriMesh {
    taction::mesh::TriMesh {
        vertices: vec![
            DVec3::new(0.00913, 0.00217, -0.0041),
            DVec3::new(-0.00437, 0.00811, -0.0043),
            DVec3::new(-0.00291, -0.00733, -0.0039),
            DVec3::new(0.00123, -0.00071, 0.00043),
        ],
        triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
    }
}

#[test]
fn turning_the_object_about_the_normal_turns_the_image() {
    let config = sharp(26, 26);
    let pose = pad_looking_down(DVec3::ZERO);
    let spec = ObjectSpec {
        mount: ObjectMount::Free,
        ..ObjectSpec::new("wedge", wedge())
    };
    let mut sensor = FreePad::new(spec, &Valid::new(config).unwrap()).unwrap();
    sensor.place(&pose);
    let before = sensor.read().unwrap();
    assert!(
        before.max() == 1.0 && before.values().iter().filter(|&&v| v > 0.0 && v < 1.0).count() > 20,
        "{before}"
    );
    let turn = DQuat::from_axis_angle(pose.normal, std::f64::consts::FRAC_PI_2);
    sensor
        .scene_mut()
        .set_object_pose(Pose::new(DVec3::ZERO, turn))
        .unwrap();
    let after = sensor.read().unwrap();
    let n = config.rows;
    // A +90° turn about the normal n maps up to n x up = right and right to -up, so the image point
    // (x, y) (x along right, y along up) comes from (-y, x) before: after(i, j) = before(n-1-j, i).
    let mut worst = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            worst = worst.max((after.get(i, j) - before.get(n - 1 - j, i)).abs());
        }
    }
    assert!(worst < 1e-9, "{worst}\n{before}\n{after}");
}

#[test]
fn moving_the_object_changes_the_reading_without_rebuilding() {
    let config = sharp(6, 6);
    let t = config.thickness_m;
    let r = 0.004;
    let spec = ObjectSpec {
        mount: ObjectMount::Free,
        ..ObjectSpec::new("ball", icosphere(DVec3::ZERO, r, 3))
    };
    let mut sensor = FreePad::new(spec, &Valid::new(config).unwrap()).unwrap();
    sensor.place(&pad_looking_down(DVec3::ZERO));
    let at = |x: f64| Pose::new(DVec3::new(x, -0.001, -(r + 0.3 * t)), DQuat::IDENTITY);
    sensor.scene_mut().set_object_pose(at(-0.001)).unwrap();
    let first = sensor.read().unwrap();
    let model = sensor.scene().model_arc();
    let stats = sensor.covering().stats(&model, sensor.scene().data()).unwrap();
    // One BVH: built by this instance, or by the one MuJoCo's compiler made to test the model.
    assert_eq!(stats.bvh_builds + stats.bvh_shared, 1);
    // One taxel (2 mm) to the right: the image shifts by one column.
    sensor.scene_mut().set_object_pose(at(0.001)).unwrap();
    let second = sensor.read().unwrap();
    assert_ne!(first, second);
    for i in 0..6 {
        for j in 1..6 {
            assert!(
                (second.get(i, j) - first.get(i, j - 1)).abs() < 1e-9,
                "{first}\n{second}"
            );
        }
    }
    let after = sensor.covering().stats(&model, sensor.scene().data()).unwrap();
    assert_eq!(
        (after.bvh_builds, after.bvh_shared),
        (stats.bvh_builds, stats.bvh_shared),
        "no BVH is rebuilt when the object moves"
    );
    assert!(after.readings > stats.readings);
}

#[test]
fn a_second_scene_of_a_mesh_reads_through_the_first_ones_bvh() {
    // While one scene of a mesh is alive, another scene of it takes its BVH instead of building
    // one, and reads what a BVH of its own gives: the same image, bit for bit.
    let config = Valid::new(sharp(6, 6)).unwrap();
    let r = 0.004;
    let spec = || ObjectSpec {
        mount: ObjectMount::Free,
        ..ObjectSpec::new("ball", icosphere(DVec3::ZERO, r, 4))
    };
    let read = |sensor: &mut FreePad| {
        sensor.place(&pad_looking_down(DVec3::ZERO));
        let pose = Pose::new(
            DVec3::new(0.0007, -0.0011, -(r + 0.4 * config.thickness_m)),
            DQuat::IDENTITY,
        );
        sensor.scene_mut().set_object_pose(pose).unwrap();
        let image = sensor.read().unwrap();
        let model = sensor.scene().model_arc();
        (
            image,
            sensor.covering().stats(&model, sensor.scene().data()).unwrap(),
        )
    };
    let mut first = FreePad::new(spec(), &config).unwrap();
    let (image, _) = read(&mut first);
    let mut second = FreePad::new(spec(), &config).unwrap();
    let (again, stats) = read(&mut second);
    assert_eq!((stats.bvh_builds, stats.bvh_shared), (0, 1));
    assert!(
        image.values().iter().any(|&v| v > 0.0),
        "the ball is pressed: {image}"
    );
    assert_eq!(image, again);
    // A ball 1 um larger is another mesh: its own BVH, its own image.
    let larger = ObjectSpec {
        mount: ObjectMount::Free,
        ..ObjectSpec::new("ball", icosphere(DVec3::ZERO, r + 1e-6, 4))
    };
    let mut third = FreePad::new(larger, &config).unwrap();
    let (other, _) = read(&mut third);
    assert_ne!(image, other);
}

#[test]
fn no_contact_reads_zero_and_pushed_through_reads_saturated() {
    let config = SensorConfig::default();
    let ball = icosphere(DVec3::ZERO, 0.01, 3);
    let mut sensor = FreePad::new(ObjectSpec::new("ball", ball), &Valid::new(config).unwrap()).unwrap();
    let far = sensor
        .read_at(&pad_looking_down(DVec3::new(
            0.0,
            0.0,
            0.0102 + config.thickness_m,
        )))
        .unwrap();
    assert!(far.values().iter().all(|&v| v == 0.0), "{far}");
    let beside = sensor
        .read_at(&PadPose::new(DVec3::new(0.03, 0.0, 0.0), DVec3::X, DVec3::Z).unwrap())
        .unwrap();
    assert!(beside.values().iter().all(|&v| v == 0.0), "{beside}");
    // Pad at the centre of the ball: every pad point is inside the solid.
    for normal in [DVec3::NEG_Z, DVec3::new(0.3, -0.5, 0.8)] {
        let inside = sensor
            .read_at(&PadPose::new(DVec3::new(0.001, 0.0, 0.0), normal, DVec3::X).unwrap())
            .unwrap();
        assert!(inside.values().iter().all(|&v| v == 1.0), "{inside}");
    }
    // Pad pushed 3 mm into the ball: centre saturated, every value finite and in range.
    let deep = sensor
        .read_at(&pad_looking_down(DVec3::new(0.0, 0.0, 0.007)))
        .unwrap();
    assert_eq!(deep.get(2, 2), 1.0);
    assert!(
        deep.values()
            .iter()
            .all(|v| v.is_finite() && (0.0..=1.0).contains(v))
    );
    // The same for primitives, the pad inside a box and a sphere.
    let mut boxed = free_sensor_with(
        "<geom type=\"box\" size=\"0.02 0.02 0.02\"/><geom type=\"sphere\" size=\"0.01\" pos=\"0.1 0 0\"/>",
        &config,
    );
    for center in [DVec3::ZERO, DVec3::new(0.1, 0.0, 0.002)] {
        let image = boxed.read_at(&pad_looking_down(center)).unwrap();
        assert!(image.values().iter().all(|&v| v == 1.0), "{image}");
    }
}

#[test]
fn mesh_depths_agree_with_mj_ray() {
    let config = sharp(14, 14);
    let t = config.thickness_m;
    let ball = icosphere(DVec3::new(0.012, -0.004, 0.03), 0.006, 3);
    let spec = ObjectSpec {
        pose: Pose::new(
            DVec3::new(0.01, 0.02, -0.03),
            DQuat::from_euler(glam::EulerRot::XYZ, 0.4, -0.2, 0.9),
        ),
        ..ObjectSpec::new("ball", ball)
    };
    let mut sensor = FreePad::new(spec, &Valid::new(config).unwrap()).unwrap();
    let world_centre = sensor.scene().object_center().unwrap();
    let normal = DVec3::new(0.2, -0.3, -1.0).normalize();
    let pose = PadPose::new(world_centre - normal * (0.006 - 0.6 * t), normal, DVec3::Y).unwrap();
    let image = sensor.read_at(&pose).unwrap();
    let pad_body = sensor.scene().model().site_bodyid()[sensor.covering().site_id()] as usize;
    let mut checked = 0;
    for i in 0..config.rows {
        for j in 0..config.cols {
            let v = image.get(i, j);
            if v <= 0.0 || v >= 1.0 {
                continue;
            }
            let (x, y) = taxel_centre(&config, i, j);
            let p = pose.center_m + pose.right() * x + pose.up * y;
            // Every geom group but the collision shell's, which the covering does not sense.
            let mut groups = [1u8; 6];
            groups[COLLISION_GROUP as usize] = 0;
            let (geom, d) = sensor.scene_mut().data_mut().ray(
                &p.to_array(),
                &pose.normal.to_array(),
                Some(&groups),
                true,
                Some(pad_body),
                None,
            );
            assert!(geom.is_some(), "mj_ray missed taxel ({i}, {j}) = {v}\n{image}");
            assert!(
                (v - (t - d) / t).abs() < 1e-5,
                "taxel ({i}, {j}): {v} vs mj_ray {}",
                (t - d) / t
            );
            checked += 1;
        }
    }
    assert!(checked > 10, "{checked}");
}

#[test]
fn the_pads_own_tree_is_not_sensed() {
    let config = SensorConfig::default();
    let t = config.thickness_m;
    let in_front = format!("size=\"0.02 0.02 0.0002\" pos=\"0 0 {}\"", 0.5 * t);
    // A pad on an arm-like tree: a geom of the same tree in front of the pad is not sensed, one of
    // another body is.
    let tree = |other: bool| {
        format!(
            "<body name=\"arm\" pos=\"0 0 0.3\"><geom type=\"capsule\" size=\"0.01\" fromto=\"0 0 0 0 0 -0.2\"/>\
             <body name=\"wrist\" pos=\"0 0 -0.25\" quat=\"0 1 0 0\">\
             <site name=\"pad\"/><geom type=\"box\" {in_front}/></body></body>{}",
            if other {
                "<body name=\"other\" pos=\"0 0 0.05\"><geom type=\"box\" size=\"0.02 0.02 0.001\"/></body>"
            } else {
                ""
            }
        )
    };
    for (other, want) in [(false, 0.0), (true, 1.0)] {
        let builder = taction::sim::SceneBuilder::new()
            .table(false)
            .add(taction::sim::Section::Worldbody, tree(other));
        let builder = taction::tactile::add_sensor(builder, &Valid::new(config).unwrap(), "pad");
        let scene = builder.build().unwrap();
        let sensor = taction::tactile::CoveringSensor::on_site(scene.model(), "pad").unwrap();
        let image = sensor.read(scene.data()).unwrap();
        assert!(
            image.values().iter().all(|&v| v == want),
            "other={other}: {image}"
        );
    }
    // A pad on the world body: the world's geoms are its own, a body's geoms are sensed.
    for (body, want) in [(false, 0.0), (true, 1.0)] {
        let geom = "<geom type=\"box\" size=\"0.02 0.02 0.0002\"/>".to_string();
        let world = if body {
            format!("<body name=\"b\">{geom}</body>")
        } else {
            geom
        };
        let builder = taction::sim::SceneBuilder::new().table(false).add(
            taction::sim::Section::Worldbody,
            format!("<site name=\"pad\"/>{world}"),
        );
        let scene = taction::tactile::add_sensor(builder, &Valid::new(config).unwrap(), "pad")
            .build()
            .unwrap();
        let image = taction::tactile::CoveringSensor::first(scene.model())
            .unwrap()
            .read(scene.data())
            .unwrap();
        assert!(image.values().iter().all(|&v| v == want), "body={body}: {image}");
    }
}

#[test]
fn unsupported_attachments_and_geoms_fail_compilation() {
    taction::tactile::ensure_registered();
    let model = |world: &str, objtype: &str, objname: &str| {
        let xml = format!(
            "<mujoco><asset><hfield name=\"h\" nrow=\"2\" ncol=\"2\" size=\"1 1 0.1 0.1\" elevation=\"0 0 0 0\"/></asset>\
             <extension><plugin plugin=\"taction.covering\"/></extension>\
             <worldbody><body name=\"b\" mocap=\"true\"><site name=\"pad\"/></body>{world}</worldbody>\
             <sensor><plugin plugin=\"taction.covering\" objtype=\"{objtype}\" objname=\"{objname}\"/></sensor></mujoco>"
        );
        mujoco_rs::prelude::MjModel::from_xml_string(&xml)
            .err()
            .map(|e| format!("{e:?}"))
    };
    assert_eq!(model("", "site", "pad"), None);
    let e = model(
        "<geom name=\"terrain\" type=\"hfield\" hfield=\"h\"/>",
        "site",
        "pad",
    )
    .unwrap();
    assert!(e.contains("cannot sense geom 'terrain', a height field"), "{e}");
    let e = model("", "body", "b").unwrap();
    assert!(e.contains("must be on a site"), "{e}");
}

#[test]
fn row_zero_is_up_and_column_zero_is_left_seen_from_behind() {
    let config = sharp(6, 6);
    // Pad looking down at the origin, up = +y, so right = normal x up = +x. A box covering the
    // pad's upper-right quadrant (x > 0, y > 0) lights rows 0-2, columns 3-5.
    let mut sensor = free_sensor_with(
        "<geom type=\"box\" size=\"0.01 0.01 0.01\" pos=\"0.01 0.01 -0.01\"/>",
        &config,
    );
    let pose = pad_looking_down(DVec3::new(0.0, 0.0, 0.0005));
    assert!((pose.right() - DVec3::X).length() < 1e-12);
    let image = sensor.read_at(&pose).unwrap();
    for i in 0..6 {
        for j in 0..6 {
            let lit = i < 3 && j >= 3;
            assert_eq!(image.get(i, j) > 0.0, lit, "({i}, {j})\n{image}");
        }
    }
}

/// A mesh above the object's large-mesh limit reaches MuJoCo as a coarse copy, and the sensor reads
/// the exact surface the model carries beside it (issue 39): the images are the exact mesh's, not
/// the copy's.
#[test]
fn a_large_mesh_is_sensed_through_its_exact_surface_not_mujocos_coarse_copy() {
    let sphere = icosphere(DVec3::new(0.0, 0.0, 0.04), 0.04, 6);
    let config = Valid::new(SensorConfig::default()).unwrap();
    let exact = || ObjectSpec::new("sphere", sphere.clone());
    let mut whole = FreePad::new(exact(), &config).unwrap();
    let mut beside = FreePad::new(
        ObjectSpec {
            large_mesh_triangles: 10_000,
            ..exact()
        },
        &config,
    )
    .unwrap();
    let drawn = taction::mesh::cluster_vertices(&sphere, taction::sim::DRAWN_MESH_TRIANGLES);
    assert!(drawn.triangles.len() * 3 < sphere.triangles.len());
    let mut copy = FreePad::new(ObjectSpec::new("copy", drawn), &config).unwrap();
    let (mut largest, mut copy_largest) = (0.0f64, 0.0f64);
    for (k, normal) in [
        DVec3::NEG_Z,
        DVec3::new(0.3, 0.1, -1.0),
        DVec3::new(-1.0, 0.2, -0.4),
    ]
    .iter()
    .enumerate()
    {
        let normal = normal.normalize();
        // The pad's face 0.6 mm inside the sphere, a little off the pole each time.
        let centre =
            DVec3::new(0.0, 0.0, 0.04) - normal * (0.04 - 0.0006) + DVec3::new(0.0005 * k as f64, 0.0, 0.0);
        let up = (DVec3::Y - normal * normal.dot(DVec3::Y)).normalize();
        let pose = PadPose::new(centre, normal, up).unwrap();
        let (a, b, c) = (
            whole.read_at(&pose).unwrap(),
            beside.read_at(&pose).unwrap(),
            copy.read_at(&pose).unwrap(),
        );
        assert!(a.max() > 0.1, "the pad presses the sphere: {a}");
        for ((x, y), z) in a.values().iter().zip(b.values()).zip(c.values()) {
            largest = largest.max((x - y).abs());
            copy_largest = copy_largest.max((x - z).abs());
        }
    }
    assert!(
        largest < 1e-5,
        "exact surface beside the copy reads {largest} off the whole mesh"
    );
    assert!(
        copy_largest > 10.0 * largest.max(1e-4),
        "the copy alone reads {copy_largest} off"
    );
}

/// A model whose mesh carries half of an exact surface is refused at compile time, naming the mesh
/// and the missing field.
#[test]
fn half_an_exact_surface_is_refused_naming_the_mesh_and_the_missing_field() {
    let config = Valid::new(SensorConfig::default()).unwrap();
    let spec = ObjectSpec::new("box", taction::mesh::TriMesh::cuboid(DVec3::splat(0.02)));
    let (vertex_name, face_name) = taction::sim::sensed_surface_names("object");
    let error = taction::tactile::free_floating_builder(spec, &config)
        .add(
            taction::sim::Section::Custom,
            format!("<numeric name=\"{vertex_name}\" data=\"0 0 0\"/>"),
        )
        .build()
        .err()
        .expect("refused")
        .to_string();
    assert!(
        error.contains("mesh 'object'") && error.contains(&face_name),
        "{error}"
    );
}

/// The free pad's scene leaves out the object's collision shell (nothing there collides with the
/// object) and reads what the same scene with the shell reads, bit for bit, at 40 seeded poses
/// around an object whose shell has several pieces (a ball with a post beside it), the object
/// where it was built and moved.
#[test]
fn the_free_pad_reads_the_same_without_the_objects_collision_shell() {
    use rand::RngExt;
    use taction::control::FreePad;
    use taction::pose::{PadPose, Pose};
    use taction::sim::{COLLISION_GROUP, ObjectSpec, SceneBuilder, Section};
    use taction::tactile::{add_sensor, free_pad_body_xml};
    use taction::valid::Valid;
    let mut mesh = icosphere(DVec3::new(0.0, 0.0, 0.03), 0.03, 2);
    mesh.append(&box_between(
        DVec3::new(0.035, -0.01, 0.0),
        DVec3::new(0.06, 0.01, 0.05),
    ));
    let object = ObjectSpec::new("ball and post", mesh);
    let config = Valid::new(SensorConfig::default()).unwrap();
    let mut without = FreePad::new(object.clone(), &config).unwrap();
    let shell_geoms = |pad: &FreePad| {
        let model = pad.scene().model();
        model
            .geom_group()
            .iter()
            .filter(|&&g| g == COLLISION_GROUP)
            .count()
    };
    assert_eq!(
        shell_geoms(&without),
        0,
        "the free pad's object has a collision shell"
    );
    let builder = SceneBuilder::new()
        .table(false)
        .object(object)
        .add(Section::Worldbody, free_pad_body_xml(&config));
    let mut with = FreePad::from_scene(add_sensor(builder, &config, "pad").build().unwrap()).unwrap();
    assert!(shell_geoms(&with) > 1, "the comparison scene has no shell");
    let mut r = taction::rng::rng(3);
    let mut touched = 0;
    for k in 0..40 {
        if k == 20 {
            let moved = Pose::new(DVec3::new(0.01, -0.02, 0.0), glam::DQuat::from_rotation_z(0.4));
            without.scene_mut().set_object_pose(moved).unwrap();
            with.scene_mut().set_object_pose(moved).unwrap();
        }
        let direction = DVec3::new(
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
            r.random_range(0.1..1.0),
        )
        .normalize();
        let center = DVec3::new(0.01, 0.0, 0.03) + direction * r.random_range(0.025..0.04);
        let pose = PadPose::new(center, -direction, DVec3::Z.cross(direction).normalize()).unwrap();
        let (a, b) = (without.read_at(&pose).unwrap(), with.read_at(&pose).unwrap());
        let bits = |image: &taction::tactile::TactileImage| {
            image.values().iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        };
        assert_eq!(bits(&a), bits(&b), "pose {k}");
        touched += usize::from(a.values().iter().any(|&v| v > 0.0));
    }
    assert!(touched >= 10, "only {touched} of 40 poses touched the object");
}
