//! One press whichever carrier: the arm's pad and the free-floating pad of the training sampler,
//! started over the same surface point from the same direction, settle to the same image.
//!
//! Training readings come from the free pad, test readings from the arm (Sec. V-A3 against
//! Sec. III-A): a model is only as good as the match between the two. Until both carriers had the
//! same rigid back the free pad pressed sharp features through it and read twice the arm's
//! pressure on the dragon. Here every object of `shapes` is touched at surface points the arm can
//! reach (area-weighted, the sampler's draw), by the arm with the planner's kinematic execution and
//! by the free pad placed at the arm's own start pose (its roll included), and the settled images
//! are compared.

use taction::control::{ArmPad, ContactOutcome, ControlConfig, FreePad, sensor_reader, settle};
use taction::dataset::ContactStatus;
use taction::explore::precise_kinematic_motion;
use taction::explore::{SurfaceSampler, carried};
use taction::mesh::ObjectSet;
use taction::sim::PAD_SITE;
use taction::sim::{InverseKinematics, ObjectSpec, PadTarget, Scene, SceneBuilder};
use taction::tactile::{CoveringSensor, SensorConfig, TactileImage, add_sensor};
use taction::valid::Valid;

/// Surface points per object at which the arm's start pose is reachable and free of collision.
const POINTS: usize = 50;
/// Distance of the start pose from the surface point, along its normal (the sampler's back-off).
const BACK_OFF_M: f64 = 0.006;

/// Pearson correlation of two images' taxels (1 when both are constant and equal).
fn correlation(a: &TactileImage, b: &TactileImage) -> f64 {
    let (x, y) = (a.values(), b.values());
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (u, v) in x.iter().zip(y) {
        sxy += (u - mx) * (v - my);
        sxx += (u - mx) * (u - mx);
        syy += (v - my) * (v - my);
    }
    if sxx == 0.0 && syy == 0.0 {
        return if x == y { 1.0 } else { 0.0 };
    }
    sxy / (sxx * syy).sqrt()
}

/// Whether two settled images agree: mean taxel within 5% and correlation at least 0.95.
fn agree(a: &TactileImage, b: &TactileImage) -> bool {
    (a.mean() - b.mean()).abs() <= 0.05 * b.mean() && correlation(a, b) >= 0.95
}

struct Pair {
    arm: ContactOutcome,
    free: ContactOutcome,
}

/// Settles both carriers over `POINTS` reachable surface points of `object`.
fn touch_both(object: &ObjectSpec, sensor: SensorConfig, seed: u64) -> (Vec<Pair>, usize) {
    let control = Valid::new(ControlConfig::default()).expect("defaults are valid");
    let builder = SceneBuilder::with_arm_and_table().object(object.clone());
    let valid_sensor = Valid::new(sensor).expect("a valid sensor");
    let mut scene: Scene = add_sensor(builder, &valid_sensor, PAD_SITE)
        .build()
        .expect("arm scene");
    let arm = scene.arm().cloned().expect("arm");
    let (ik_options, motion) = precise_kinematic_motion(0.125 * sensor.thickness_m);
    let mut ik = InverseKinematics::new(scene.model_arc(), arm.clone(), ik_options);
    let home = arm.q(scene.data());
    let arm_object = scene.object_pose().expect("object");
    let mut free = FreePad::new(object.clone(), &valid_sensor).expect("free pad scene");
    let free_object = free.scene().object_pose().expect("object");
    // The arm scene's object frame carried onto the free pad scene's.
    let to_free = free_object.compose(&arm_object.inverse());
    let surface = SurfaceSampler::new(&object.mesh, |_| true).expect("surface");
    let mut rng = taction::rng::rng(seed);
    let (mut pairs, mut draws) = (Vec::new(), 0);
    while pairs.len() < POINTS && draws < 40 * POINTS {
        draws += 1;
        let p = surface.sample(&object.mesh, &mut rng);
        let point = arm_object.transform_point(p.point_m);
        let outward = arm_object.transform_vector(p.normal);
        let target = PadTarget {
            center_m: point + outward * BACK_OFF_M,
            normal: -outward,
        };
        let Ok(q) = ik.solve(&target, &home) else {
            continue;
        };
        arm.teleport(&mut scene, &q);
        if arm.collision(&scene).is_some() {
            continue;
        }
        let start = arm.pad_pose(scene.data());
        let reader = sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE).expect("covering"));
        let mut pad = ArmPad::new(&mut scene, &mut ik, sensor, reader, motion).expect("arm pad");
        let arm_outcome = settle(&mut pad, &control).expect("arm settles");
        let free_start = carried(&start, &to_free);
        free.place(&free_start);
        let free_outcome = settle(&mut free, &control).expect("free pad settles");
        pairs.push(Pair {
            arm: arm_outcome,
            free: free_outcome,
        });
    }
    (pairs, draws)
}

#[test]
fn arm_and_free_pad_settle_to_the_same_image_on_every_shape() {
    let set = ObjectSet::shapes();
    let objects = ObjectSpec::all_of(&set).expect("the shapes (fetched by `cargo xtask setup`)");
    let sensor = SensorConfig::square(6, 6, 0.012, 0.0012);
    let mut failures = Vec::new();
    for (i, object) in objects.iter().enumerate() {
        let (pairs, draws) = touch_both(object, sensor, 100 + i as u64);
        assert_eq!(
            pairs.len(),
            POINTS,
            "{}: only {} reachable starts in {draws} draws",
            object.name,
            pairs.len()
        );
        let converged: Vec<&Pair> = pairs
            .iter()
            .filter(|p| p.arm.status == ContactStatus::Converged)
            .collect();
        let agreeing = converged
            .iter()
            .filter(|p| p.free.status == ContactStatus::Converged && agree(&p.arm.image, &p.free.image))
            .count();
        let (arm_mean, free_mean) = converged.iter().fold((0.0, 0.0), |(a, f), p| {
            (a + p.arm.image.mean(), f + p.free.image.mean())
        });
        let share = agreeing as f64 / converged.len().max(1) as f64;
        println!(
            "{:12} arm converged {:2}/{POINTS}, free pad agrees on {agreeing:2} ({:.0}%), mean taxel arm {:.3} free {:.3} (ratio {:.3})",
            object.name,
            converged.len(),
            100.0 * share,
            arm_mean / converged.len().max(1) as f64,
            free_mean / converged.len().max(1) as f64,
            arm_mean / free_mean,
        );
        if converged.len() < POINTS / 2 || share < 0.9 {
            failures.push(format!(
                "{} ({agreeing} of {} converged)",
                object.name,
                converged.len()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "the carriers disagree on: {}",
        failures.join(", ")
    );
}
