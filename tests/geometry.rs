//! The recogniser that knows where it touched (`locate`, `recognize::geometric`): contacts of the
//! toy readings placed on three real meshes at a pose the model is not told, so that appearance
//! alone cannot tell the objects apart and contact geometry must; its model file round-trips, and
//! nothing of a reading's `object_pose` reaches a posterior.

mod recognize_toy;

use glam::{DQuat, DVec3};
use taction::dataset::{Dataset, Perturbed, Reading};
use taction::locate::{GeometryModel, GeometryParams, ObjectSurface, Touch};
use taction::mesh::TriMesh;
use taction::pose::{PadPose, Pose};
use taction::recognize::{
    Appearance, CodebookKind, DescriptorChoice, Evidence, GeometricFusion, ReadingRange, Recognizer,
    TrainChoices, TrainData, TrainedModel, train_recognizer,
};
use taction::valid::Valid;

/// The three toy objects' shapes, resting on z = 0: a cube, a long slab, a tall post.
fn meshes() -> [TriMesh; 3] {
    let resting = |half: DVec3| TriMesh::cuboid(half).translated(DVec3::new(0.0, 0.0, half.z));
    [
        resting(DVec3::splat(0.04)),
        resting(DVec3::new(0.06, 0.03, 0.02)),
        resting(DVec3::new(0.02, 0.02, 0.06)),
    ]
}

/// `per_object` readings of each toy object, every image flat (appearance tells nothing), each
/// taken on the upper half of its object's surface, the object turned by `heading_rad` and moved
/// by `shift_m`; `object_pose` records that pose.
fn dataset(per_object: usize, seed: u64, heading_rad: f64, shift_m: DVec3) -> Dataset {
    let flat = recognize_toy::dataset(per_object, seed);
    let pose = Pose::new(shift_m, DQuat::from_rotation_z(heading_rad));
    let surfaces: Vec<ObjectSurface> = meshes()
        .iter()
        .map(|m| ObjectSurface::of_mesh(m).expect("a box"))
        .collect();
    let sensor = flat.header().sensor;
    let mut counts = [0usize; 3];
    let readings = flat
        .readings()
        .iter()
        .map(|r| {
            let j = recognize_toy::OBJECTS
                .iter()
                .position(|o| *o == r.object)
                .expect("a toy object");
            let mut rng = taction::rng::stream(seed, (1000 * j + counts[j]) as u64);
            counts[j] += 1;
            let s = &surfaces[j];
            let image = recognize_toy::image(2, &mut rng);
            // A point of the upper half, as an arm from above reaches.
            let top = s.points().iter().map(|p| p.z).fold(0.0, f64::max);
            let upper: Vec<usize> = (0..s.points().len())
                .filter(|&i| s.points()[i].z > 0.5 * top)
                .collect();
            let i = upper[(counts[j] * 7919 + seed as usize) % upper.len()];
            let (point, outward) = (
                pose.transform_point(s.points()[i]),
                pose.transform_vector(s.normals()[i]),
            );
            let depth = sensor.thickness_m * (1.0 - image.mean());
            let pad = PadPose::new(
                point + outward * depth,
                -outward,
                outward.any_orthonormal_vector(),
            )
            .expect("a pad pose");
            Reading {
                image: image.with_pose(pad),
                object_pose: pose,
                ..r.clone()
            }
        })
        .collect();
    Dataset::new(flat.header().clone(), readings).expect("the toy header")
}

/// The toy objects' surfaces, the contact half of the model.
fn geometry() -> GeometryModel {
    let meshes = meshes();
    GeometryModel::build(
        recognize_toy::OBJECTS.iter().map(|o| o.to_string()).zip(&meshes),
        Valid::new(GeometryParams::default()).expect("defaults"),
    )
    .expect("three boxes")
}

fn choices() -> Valid<TrainChoices> {
    Valid::new(TrainChoices {
        codebook: CodebookKind::Gmm,
        ks: Some(vec![4]),
        restarts: 1,
        seed: 5,
        calibration_trial_readings: Some(6),
        ..TrainChoices::of(DescriptorChoice::parse("mnti").expect("a descriptor"))
    })
    .expect("choices")
}

/// MNTI's appearance model of the toy readings fused with the toy objects' contacts, weighed and
/// calibrated on `calibration` in trials of 6: what `train --objects` builds.
fn model(calibration: &Dataset) -> Recognizer {
    let training = recognize_toy::dataset(30, 8);
    let geometry = geometry();
    let data = TrainData {
        training: &training,
        validation: None,
        calibration: &[calibration],
        contacts: Some(&geometry),
    };
    train_recognizer(&choices(), data, &mut ()).expect("trains")
}

#[test]
fn the_training_entry_builds_the_steps_in_order_and_refuses_contacts_it_cannot_weigh() {
    let training = recognize_toy::dataset(30, 8);
    let calibration = dataset(12, 41, 0.0, DVec3::ZERO);
    let geometry = geometry();
    let trained = model(&calibration);
    // The same steps by hand: an appearance model, fused with the contacts, weighed on the
    // calibration in trials of 6.
    let config = choices().config(&training, false).expect("a config");
    let descriptor = taction::describe::DescriptorKind::Mnti.build();
    let appearance =
        TrainedModel::fit(&config, &training, None, descriptor.as_ref(), &mut |_| {}).expect("trains");
    let fused = GeometricFusion::new(Appearance::Single(Box::new(appearance)), geometry.clone())
        .expect("same objects");
    let by_hand = Recognizer::Geometric(Box::new(fused))
        .calibrate_on_all(&[&calibration], 6)
        .expect("calibrates");
    assert_eq!(trained.to_json().expect("json"), by_hand.to_json().expect("json"));

    let unweighed = TrainData {
        training: &training,
        validation: None,
        calibration: &[],
        contacts: Some(&geometry),
    };
    let e = train_recognizer(&choices(), unweighed, &mut ()).expect_err("nothing to weigh the contacts on");
    assert!(
        e.to_string().contains("objects") && e.to_string().contains("give calibration"),
        "{e}"
    );
    let zero = TrainChoices {
        calibration_trial_readings: Some(0),
        ..choices().into_inner()
    };
    let e = Valid::new(zero).expect_err("trials of no reading");
    assert!(e.to_string().contains("calibration_trial_readings"), "{e}");
}

fn accuracy_at(model: &Recognizer, test: &Dataset, n: usize) -> f64 {
    let (evaluation, _) = model
        .evaluate(test, ReadingRange::new(1, 6).expect("a range"))
        .expect("evaluates");
    evaluation.accuracy_at(n).expect("a point")
}

#[test]
fn contacts_tell_apart_objects_that_feel_the_same() {
    let calibration = dataset(12, 21, 0.4, DVec3::new(0.003, 0.0, 0.0));
    let model = model(&calibration);
    let Recognizer::Geometric(g) = &model else {
        panic!("a geometric model");
    };
    assert!(g.geometry_weight() > 0.0, "the calibration weighed geometry at 0");
    let test = dataset(12, 22, 2.1, DVec3::new(-0.004, 0.005, 0.0));
    // Every image is flat: appearance alone is at chance (1/3).
    assert!(
        accuracy_at(&model, &test, 6) >= 0.9,
        "{}",
        accuracy_at(&model, &test, 6)
    );
}

/// The model weighing `evidence` alone.
fn weighing(model: &Recognizer, evidence: Evidence) -> Recognizer {
    let Recognizer::Geometric(g) = model else {
        panic!("a geometric model");
    };
    Recognizer::Geometric(Box::new((**g).clone().with_evidence(evidence)))
}

#[test]
fn each_part_of_the_evidence_weighs_alone() {
    let model = model(&dataset(12, 21, 0.4, DVec3::new(0.003, 0.0, 0.0)));
    let Recognizer::Geometric(g) = &model else {
        panic!("a geometric model");
    };
    let alone = g.alone().expect("calibration fits each part alone");
    let test = dataset(12, 22, 2.1, DVec3::new(-0.004, 0.005, 0.0));
    // The contacts alone name the boxes whose images are all flat.
    let contacts = weighing(&model, Evidence::Contacts);
    assert_eq!(contacts.tempering(), alone.contacts);
    assert!(
        accuracy_at(&contacts, &test, 6) >= 0.9,
        "{}",
        accuracy_at(&contacts, &test, 6)
    );
    // Appearance alone is the bag of features: its guesses are the appearance model's own, the
    // belief tempered as the calibration fitted it for appearance alone.
    let appearance = weighing(&model, Evidence::Appearance);
    assert_eq!(appearance.tempering(), alone.appearance);
    let single = Recognizer::Single(Box::new(g.appearance().parts()[0].clone()));
    let range = ReadingRange::new(1, 6).expect("a range");
    let outcomes = |m: &Recognizer| {
        let (evaluation, _) = m.evaluate(&test, range).expect("evaluates");
        evaluation.accuracy
    };
    let (a, s) = (outcomes(&appearance), outcomes(&single));
    assert_eq!(
        a.iter().map(|r| r.correct).collect::<Vec<_>>(),
        s.iter().map(|r| r.correct).collect::<Vec<_>>()
    );
    // Which evidence is weighed is a choice of use: the model file is the same.
    assert_eq!(
        appearance.to_json().expect("encodes"),
        model.to_json().expect("encodes")
    );
}

#[test]
fn no_object_pose_reaches_a_posterior_and_the_model_file_round_trips() {
    let model = model(&dataset(12, 21, 0.4, DVec3::ZERO));
    let test = dataset(6, 23, 1.0, DVec3::ZERO);
    let range = ReadingRange::new(1, 6).expect("a range");
    let (before, _) = model.evaluate(&test, range).expect("evaluates");
    let lied: Vec<Reading> = test
        .readings()
        .iter()
        .map(|r| Reading {
            object_pose: Pose::new(DVec3::new(1.0, 2.0, 3.0), DQuat::from_rotation_x(1.0)),
            ..r.clone()
        })
        .collect();
    let lied = Dataset::new(test.header().clone(), lied).expect("the same header");
    let (after, _) = model.evaluate(&lied, range).expect("evaluates");
    assert_eq!(before.posterior_long_csv(), after.posterior_long_csv());
    let bytes = model.to_json().expect("encodes");
    let back = Recognizer::from_json(&bytes, "memory").expect("decodes");
    assert_eq!(back, model);
    assert_eq!(back.to_json().expect("encodes"), bytes);
    let (again, _) = back.evaluate(&test, range).expect("evaluates");
    assert_eq!(again.posterior_long_csv(), before.posterior_long_csv());
}

#[test]
fn a_corrupt_geometric_model_file_is_named() {
    let model = model(&dataset(6, 21, 0.0, DVec3::ZERO));
    let mut value: serde_json::Value =
        serde_json::from_slice(&model.to_json().expect("encodes")).expect("json");
    value["geometry_weight"] = serde_json::json!(-1.0);
    let e = Recognizer::from_json(&serde_json::to_vec(&value).expect("json"), "m.json").expect_err("refused");
    assert!(
        e.to_string().contains("m.json") && e.to_string().contains("geometry_weight"),
        "{e}"
    );
    value["geometry_weight"] = serde_json::json!(0.5);
    value["geometry"]["surfaces"][0]["points"] = serde_json::json!([]);
    let e = Recognizer::from_json(&serde_json::to_vec(&value).expect("json"), "m.json").expect_err("refused");
    assert!(e.to_string().contains("m.json"), "{e}");
}

/// An attempt that gave no reading (it met nothing, collided, did not settle) still let a
/// perturbed object move (Sec. V-B4): online (`missed`), the next reading's touch is the attempt
/// after it, as a recorded exploration numbers its readings (`Touch::of_dataset`), so its pose
/// belief has widened by those moves; an object that stays put is unaffected.
#[test]
fn an_attempt_without_a_reading_counts_as_a_move_of_a_perturbed_object() {
    // The contacts alone: the toy model is weighed on a fixed object only, so its fused belief
    // gives a moving object's contacts no weight.
    let model = weighing(&model(&dataset(12, 21, 0.4, DVec3::ZERO)), Evidence::Contacts);
    let Recognizer::Geometric(g) = &model else {
        panic!("a geometric model");
    };
    let test = dataset(2, 29, 0.7, DVec3::ZERO);
    let images: Vec<_> = test
        .readings()
        .iter()
        .filter(|r| r.object == recognize_toy::OBJECTS[1])
        .map(|r| r.image.clone())
        .collect();
    let perturbed = Perturbed {
        max_rotation_deg: 10.0,
        max_translation_fraction: 0.1,
        ..Perturbed::FIXED
    };
    let online = |motion: Perturbed, missed: usize| {
        let mut posterior = model.posterior_for(motion).expect("a posterior");
        posterior.observe(&images[0]).expect("observes");
        (0..missed).for_each(|_| posterior.missed());
        posterior
            .observe(&images[1])
            .expect("observes")
            .probabilities()
            .to_vec()
    };
    // By hand: the second reading's touch is attempt 4 (readings at attempts 0 and 4).
    let describer = model.posterior_for(perturbed).expect("a posterior");
    let mut by_hand = g.posterior(perturbed);
    let first = by_hand.touch_of(&images[0]);
    assert_eq!(first.attempt, 0);
    by_hand
        .observe(&(describer.describe(&images[0]), first))
        .expect("observes");
    let second = Touch {
        attempt: 4,
        ..by_hand.touch_of(&images[1])
    };
    let expected = by_hand
        .observe(&(describer.describe(&images[1]), second))
        .expect("observes");
    assert_eq!(online(perturbed, 3), expected.probabilities());
    assert_ne!(
        online(perturbed, 3),
        online(perturbed, 0),
        "three moves more widen the pose belief"
    );
    assert_eq!(online(Perturbed::FIXED, 3), online(Perturbed::FIXED, 0));
}
