//! One active-touch episode on a chess piece, stepped from outside as the Gymnasium environment
//! steps it (`active_touch::TouchEpisode`): a small MNTI model trained on sampler readings of the
//! `chess` set, then touches toward the candidate of the largest expected information gain, with
//! the mean wall time of one `touch` and of scoring the candidates (`gains`).
//!
//! `cargo run --release --example touch_episode`

use std::sync::Arc;
use std::time::{Duration, Instant};

use taction::active_touch::{EpisodeConfig, TouchEpisode};
use taction::describe::DescriptorKind;
use taction::explore::{Collect, PlannerConfig};
use taction::mesh::ObjectSet;
use taction::recognize::{Recognizer, TrainConfig, TrainedModel};
use taction::sim::ObjectSpec;
use taction::tactile::SensorConfig;
use taction::valid::Valid;

/// Touch actions the episode makes (guarded touches, the episode's default).
const TOUCHES: usize = 60;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let set = ObjectSet::chess();
    let objects = ObjectSpec::all_of(&set)?;
    let sensor = SensorConfig::paper();
    let training = Collect::sampler(sensor)
        .per_object(200)
        .seed(1)
        .dataset(&set.id(), &objects)?;
    let params = Valid::new(TrainConfig {
        ks: vec![10],
        restarts: 1,
        seed: 1,
        ..TrainConfig::default()
    })?;
    let descriptor = DescriptorKind::Mnti.build();
    let model = TrainedModel::fit(&params, &training, None, descriptor.as_ref(), &mut |_| {})?;
    let model = Arc::new(Recognizer::Single(Box::new(model)));

    let config = Valid::new(EpisodeConfig {
        planner: Valid::new(PlannerConfig::default().fitted_to(&objects))?,
        ..EpisodeConfig::new(sensor)
    })?;
    let rook = objects
        .iter()
        .find(|o| o.name == "rook")
        .ok_or("no rook in the chess set")?;
    let mut episode = TouchEpisode::new(model, rook, &config, 7)?;
    let (mut touching, mut scoring) = (Duration::ZERO, Duration::ZERO);
    for _ in 0..TOUCHES {
        let t0 = Instant::now();
        let choice = episode.most_informative()?.unwrap_or(0);
        scoring += t0.elapsed();
        let t1 = Instant::now();
        episode.touch(choice)?;
        touching += t1.elapsed();
    }
    let p = episode.belief().probabilities();
    println!(
        "{} touches of the rook: {} attempts, {} converged; p(rook) = {:.3}",
        TOUCHES,
        episode.attempts(),
        episode.touches(),
        p[episode.object_index()]
    );
    println!(
        "mean wall time: touch {:.2} ms, gains of {} candidates {:.3} ms",
        touching.as_secs_f64() * 1e3 / TOUCHES as f64,
        config.candidates,
        scoring.as_secs_f64() * 1e3 / TOUCHES as f64
    );
    Ok(())
}
