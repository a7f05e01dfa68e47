//! Collect, train, recognise on the `chess` set (a pawn and a rook): training readings from the
//! free-floating sampler (Sec. V-A3), test readings from the arm's exploration planner (Sec. III-A,
//! L = 0.5), a bag-of-features model (Sec. IV-A) on the MNTI descriptor (Sec. IV-B6), the accuracy
//! after each number of readings (Sec. V-B), and the posterior of one exploration touch by touch
//! (Eq. 15-16). Small counts, so it runs in seconds.
//!
//! `cargo run --release --example recognize_chess`

use taction::describe::DescriptorKind;
use taction::explore::{Collect, PlannerConfig};
use taction::mesh::ObjectSet;
use taction::recognize::{ReadingRange, TrainConfig, TrainedModel};
use taction::sim::ObjectSpec;
use taction::tactile::SensorConfig;
use taction::valid::Valid;

/// Touches per test trial.
const READINGS: usize = 10;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let set = ObjectSet::chess();
    let objects = ObjectSpec::all_of(&set)?;
    let sensor = SensorConfig::paper();

    // Training: the sampler's touches at area-weighted surface points; test: the arm's exploration.
    let training = Collect::sampler(sensor)
        .per_object(300)
        .seed(1)
        .dataset(&set.id(), &objects)?;
    let planner = PlannerConfig {
        local_probability: 0.5,
        ..PlannerConfig::default()
    };
    let test = Collect::planner(sensor, planner.fitted_to(&objects))
        .per_object(3 * READINGS)
        .seed(2)
        .dataset(&set.id(), &objects)?;

    // Params -> check -> fit: the codebook size chosen on held-out training readings.
    let params = Valid::new(TrainConfig {
        ks: vec![5, 10, 20],
        seed: 1,
        ..TrainConfig::default()
    })?;
    let descriptor = DescriptorKind::Mnti.build();
    let model = TrainedModel::fit(&params, &training, None, descriptor.as_ref(), &mut |_| {})?;

    let evaluation = model.evaluate(&test, ReadingRange::new(1, READINGS)?)?;
    println!("readings  accuracy");
    for point in &evaluation.accuracy {
        println!("{:>8}  {:>8.3}", point.n_readings, point.accuracy());
    }

    // One exploration of the rook, touch by touch: the posterior takes the tactile images.
    let mut posterior = model.posterior()?;
    let rook = test.converged().filter(|r| r.object == "rook").take(READINGS);
    for reading in rook {
        let belief = posterior.observe(&reading.image)?;
        let shares: Vec<String> = (model.bag.objects().iter())
            .zip(belief.probabilities())
            .map(|(object, p)| format!("p({object}) = {p:.3}"))
            .collect();
        println!("touch {:>2}: {}", belief.readings, shares.join(", "));
    }

    let last = evaluation.accuracy.last().map_or(0.0, |p| p.accuracy());
    let chance = 1.0 / set.objects.len() as f64;
    if last <= chance {
        return Err(format!("accuracy {last} after {READINGS} readings is no better than chance").into());
    }
    Ok(())
}
