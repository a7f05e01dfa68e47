//! The library's side of the soak (`examples/python/soak_vector_env.py`): `TouchEpisode`s made,
//! touched and dropped one after another in one process, its resident memory every 50 episodes;
//! exits non-zero when the memory at the end is 5% or more above the first half's highest.
//! Flat here while the Python soak's grows says the growth is not in the episode's lifecycle.
//!
//! `cargo run --release --example episode_memory -- [episodes, 300] [touches per episode, 10]`

use std::sync::Arc;

use taction::active_touch::{EpisodeConfig, TouchEpisode};
use taction::describe::DescriptorKind;
use taction::explore::{Collect, PlannerConfig};
use taction::mesh::ObjectSet;
use taction::recognize::{Recognizer, TrainConfig, TrainedModel};
use taction::sim::{MaxHeading, ObjectSpec, StartPose};
use taction::tactile::SensorConfig;
use taction::valid::Valid;

/// The process's resident memory, KiB (Linux `/proc/self/statm`, 4 KiB pages).
fn resident_kib() -> Result<u64, Box<dyn std::error::Error>> {
    let statm = std::fs::read_to_string("/proc/self/statm")?;
    let pages: u64 = statm
        .split_whitespace()
        .nth(1)
        .ok_or("statm has no resident field")?
        .parse()?;
    Ok(pages * 4)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let episodes: usize = args.first().map(|s| s.parse()).transpose()?.unwrap_or(300);
    let touches: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(10);
    let objects = ObjectSpec::all_of(&ObjectSet::shapes())?;
    let sensor = SensorConfig::paper();
    let training = Collect::sampler(sensor)
        .per_object(16)
        .seed(3)
        .dataset("memory", &objects)?;
    let config = Valid::new(TrainConfig {
        ks: vec![4],
        restarts: 1,
        seed: 3,
        ..TrainConfig::default()
    })?;
    let descriptor = DescriptorKind::Mnti.build();
    let model = TrainedModel::fit(&config, &training, None, descriptor.as_ref(), &mut |_| {})?;
    let model = Arc::new(Recognizer::Single(Box::new(model)));
    let episode = Valid::new(EpisodeConfig {
        planner: Valid::new(PlannerConfig::default().fitted_to(&objects))?,
        start_pose: StartPose::random(MaxHeading::ANY),
        ..EpisodeConfig::new(sensor)
    })?;
    println!("episodes,touches,resident_kib");
    let mut resident = Vec::new();
    for e in 0..episodes {
        let object = &objects[e % objects.len()];
        let mut touching = TouchEpisode::new(Arc::clone(&model), object, &episode, e as u64)?;
        for t in 0..touches {
            touching.touch(t % episode.candidates)?;
        }
        if e % 50 == 49 {
            resident.push(resident_kib()?);
            println!("{},{},{}", e + 1, (e + 1) * touches, resident[resident.len() - 1]);
        }
    }
    // Warm-up: the first half of the run, at its highest (the allocator's arenas grow in steps).
    let (first_half, _) = resident.split_at(resident.len() / 2);
    let (Some(&warm), Some(&end)) = (first_half.iter().max(), resident.last()) else {
        return Err("fewer than 100 episodes: no warm-up and end to compare".into());
    };
    let growth = end as f64 / warm as f64 - 1.0;
    eprintln!(
        "resident memory: {warm} KiB at most in the first half, {end} KiB at the end ({:+.1}%)",
        100.0 * growth
    );
    if growth >= 0.05 {
        return Err(format!("resident memory grew {:.1}% after warm-up", 100.0 * growth).into());
    }
    Ok(())
}
