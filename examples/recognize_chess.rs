//! Collect, train, recognise on the `chess` set (a pawn and a rook): training readings from the
//! free-floating sampler (Sec. V-A3), test readings from the arm's exploration planner (Sec. III-A,
//! L = 0.5), a bag-of-features model (Sec. IV-A) on the MNTI descriptor (Sec. IV-B6), and the
//! accuracy after each number of readings (Sec. V-B). Small counts, so it runs in seconds.
//!
//! `cargo run --release --example recognize_chess`

use taction::describe::DescriptorKind;
use taction::explore::collect::{CollectMode, CollectPlan};
use taction::explore::{PlannerConfig, SamplerConfig};
use taction::mesh::ObjectSet;
use taction::recognize::{ReadingRange, Recognizer, TrainConfig, TrainedModel};
use taction::sim::{ObjectSpec, PerturbationBounds};
use taction::tactile::SensorConfig;
use taction::valid::Valid;

/// Touches per test trial.
const READINGS: usize = 10;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let set = ObjectSet::chess();
    let objects = ObjectSpec::all_of(&set)?;
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());

    let sampler = CollectPlan {
        mode: CollectMode::Sampler(Valid::new(SamplerConfig::default())?),
        sensor: SensorConfig::default(),
        control: Valid::default(),
        perturbation: PerturbationBounds::NONE,
        readings_per_object: 300,
        seed: 1,
    };
    let training = sampler.collect_dataset(&set.id(), &objects, threads, &|| {})?;

    let planner = PlannerConfig {
        local_probability: 0.5,
        ..PlannerConfig::default()
    };
    let explorer = CollectPlan {
        mode: CollectMode::Planner(Valid::new(planner.fitted_to(&objects))?),
        readings_per_object: 3 * READINGS,
        seed: 2,
        ..sampler
    };
    let test = explorer.collect_dataset(&set.id(), &objects, threads, &|| {})?;

    let config = TrainConfig {
        ks: vec![5, 10, 20],
        seed: 1,
        ..TrainConfig::default()
    };
    let model = TrainedModel::fit(
        &training,
        None,
        DescriptorKind::Mnti.build().as_ref(),
        config,
        &mut |_| {},
    )?;
    let recognizer = Recognizer::Single(Box::new(model));
    let (evaluation, trials) = recognizer.evaluate(&test, ReadingRange::new(1, READINGS)?)?;

    println!(
        "{} objects, {trials} trials of the arm's touches",
        set.objects.len()
    );
    println!("readings  accuracy  reliability");
    for point in &evaluation.accuracy {
        println!(
            "{:>8}  {:>8.3}  {:>11.3}",
            point.n_readings,
            point.accuracy(),
            point.reliability
        );
    }
    let last = evaluation.accuracy.last().map_or(0.0, |p| p.accuracy());
    let chance = 1.0 / set.objects.len() as f64;
    if last <= chance {
        return Err(format!("accuracy {last} after {READINGS} readings is no better than chance").into());
    }
    Ok(())
}
