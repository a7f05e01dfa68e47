//! Exploration: the planner with the arm and the training sampler, on real MuJoCo scenes.

mod common;

use glam::DVec3;
use taction::control::{ContactStatus, ControlConfig};
use taction::explore::collect::{CollectMode, CollectPlan};
use taction::explore::{PlannerConfig, SamplerConfig, Strategy};
use taction::sim::{ObjectSpec, PerturbationBounds};
use taction::tactile::SensorConfig;

fn box_object() -> ObjectSpec {
    ObjectSpec::new("box", common::box_mesh(DVec3::new(0.10, 0.08, 0.10)))
}

fn plan(mode: CollectMode, readings: usize, perturbation: PerturbationBounds) -> CollectPlan {
    CollectPlan {
        mode,
        sensor: SensorConfig::square(6, 6, 0.012, 0.0012),
        control: ControlConfig::default(),
        perturbation,
        readings_per_object: readings,
        seed: 17,
    }
}

#[test]
fn planner_collects_converged_readings_on_a_box() {
    for (perturbation, wanted) in [
        (PerturbationBounds::NONE, 20),
        (PerturbationBounds::new(10.0, 0.1).unwrap(), 10),
    ] {
        let t0 = std::time::Instant::now();
        let plan = plan(
            CollectMode::Planner(PlannerConfig::default()),
            wanted,
            perturbation,
        );
        let report = plan.collect_object(&box_object(), 0).unwrap();
        eprintln!(
            "planner: {} converged of {} attempts in {} iterations, {} collisions, {} unreachable, {:?} ({:?})",
            report.converged(),
            report.readings.len(),
            report.iterations,
            report.collisions,
            report.unreachable_steps,
            report.by_status(),
            t0.elapsed()
        );
        assert_eq!(report.converged(), wanted);

        for r in &report.readings {
            assert!(matches!(r.strategy, Strategy::Global | Strategy::Local));
            assert!(r.image.pose().is_some());
        }
        let moved = report
            .readings
            .windows(2)
            .any(|w| w[0].object_pose != w[1].object_pose);
        assert_eq!(moved, !perturbation.is_none());
    }
}

#[test]
fn sampler_readings_cover_every_face_of_a_box() {
    let plan = plan(
        CollectMode::Sampler(SamplerConfig::default()),
        60,
        PerturbationBounds::NONE,
    );
    let report = plan.collect_object(&box_object(), 0).unwrap();
    assert_eq!(report.converged(), 60);
    let mut faces = std::collections::BTreeSet::new();
    for r in report
        .readings
        .iter()
        .filter(|r| r.status == ContactStatus::Converged)
    {
        let n = r.image.pose().unwrap().normal;
        let axis = if n.x.abs() > 0.7 {
            0
        } else if n.y.abs() > 0.7 {
            1
        } else if n.z.abs() > 0.7 {
            2
        } else {
            9
        };
        faces.insert((axis, n.x + n.y + n.z > 0.0));
        assert_eq!(r.strategy, Strategy::Sampler);
    }
    assert_eq!(faces.len(), 6, "faces read: {faces:?}");
}
