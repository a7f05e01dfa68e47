//! Converged readings per touch action, per object: the guarded touch (`Planner::guarded_touch`,
//! what `TouchEpisode` and `taction/ActiveTouch-v1` make of an action) against one planner
//! iteration toward the same kind of candidate (`Planner::touch_toward`, `ActiveTouch-v0`). Each
//! object starts at a random pose drawn from the seed (the letters within 10 degrees of upright),
//! each touch goes toward a candidate of the planner's local/global rule (L = 0.5) picked at
//! random, as a random policy picks; how each touch's last attempt ended is counted by status and
//! cause (a guarded touch makes another attempt only after one that met the object and failed,
//! `earns_a_retry`, three at most), and the wall time a touch takes (the scene's set-up not
//! counted).
//!
//! `cargo run --release --example touches_that_land -- <shapes|letters|flat> [touches] [seed]`
//! (`flat`: a 12 x 8 x 1 cm plate and a ring 12 cm across, 1 cm thick, 2.5 cm wide)

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use glam::DVec3;
use rand::{RngExt, SeedableRng};
use taction::dataset::Reading;
use taction::explore::{CollectMode, CollectPlan, ExplorationReport, PlannerConfig};
use taction::mesh::{ObjectSet, TriMesh};
use taction::sim::{MaxHeading, ObjectSpec, PerturbationBounds, StartPose};
use taction::tactile::SensorConfig;
use taction::valid::Valid;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let set = args.first().map(String::as_str).unwrap_or("shapes");
    let touches: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(40);
    let seed: u64 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(9);
    let (objects, heading) = match set {
        "shapes" => (ObjectSpec::all_of(&ObjectSet::shapes())?, MaxHeading::ANY),
        "letters" => (
            ObjectSpec::all_of(&ObjectSet::builtin("letters", None)?)?,
            MaxHeading::LETTERS,
        ),
        "flat" => (flat_objects(), MaxHeading::ANY),
        other => return Err(format!("set '{other}' is none of shapes, letters, flat").into()),
    };
    let planner = Valid::new(PlannerConfig::default().fitted_to(&objects))?;
    let plan = CollectPlan {
        mode: CollectMode::Planner(planner),
        sensor: SensorConfig::paper(),
        control: Valid::default(),
        perturbation: PerturbationBounds::NONE,
        readings_per_object: 0,
        seed,
        start_pose: StartPose::random(heading),
        free_object: None,
    };
    println!("object,touch,touches,converged,converged_per_touch,attempts,last_attempt_by_status");
    let mut totals: BTreeMap<&str, (usize, usize, Duration)> = BTreeMap::new();
    for (index, object) in objects.iter().enumerate() {
        for guarded in [true, false] {
            let (mut scene, mut explorer) = plan.planner_for(object, index, planner)?;
            let mut pick = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ index as u64);
            let mut statuses: BTreeMap<String, usize> = BTreeMap::new();
            let (mut converged, mut attempts) = (0, 0);
            let start = Instant::now();
            for _ in 0..touches {
                let candidates = explorer.propose_candidates(12);
                let candidate = candidates[pick.random_range(0..candidates.len())];
                let report: ExplorationReport = if guarded {
                    explorer.guarded_touch(&mut scene, &object.name, candidate)?
                } else {
                    explorer.touch_toward(&mut scene, &object.name, candidate)?
                };
                converged += report.converged();
                attempts += report.readings.len();
                *statuses.entry(outcome(report.readings.last())).or_insert(0) += 1;
            }
            let kind = if guarded { "guarded" } else { "iteration" };
            let total = totals.entry(kind).or_insert((0, 0, Duration::ZERO));
            *total = (total.0 + converged, total.1 + touches, total.2 + start.elapsed());
            let by_status: Vec<String> = statuses.iter().map(|(s, n)| format!("{s}={n}")).collect();
            println!(
                "{},{kind},{touches},{converged},{:.3},{attempts},{}",
                object.name,
                converged as f64 / touches as f64,
                by_status.join(" ")
            );
        }
    }
    for (kind, (converged, touches, spent)) in totals {
        eprintln!(
            "{set}, seed {seed}: {kind}: {converged} of {touches} touches converged ({:.3}), {:.2} ms a touch",
            converged as f64 / touches as f64,
            1e3 * spent.as_secs_f64() / touches as f64
        );
    }
    Ok(())
}

/// How a touch ended: its last attempt's status and cause, or `none` (an iteration that met
/// nothing makes no attempt).
fn outcome(last: Option<&Reading>) -> String {
    match last {
        None => "none".into(),
        Some(r) => match &r.cause {
            Some(cause) => format!("{}/{}", r.status.name(), cause.name()),
            None => r.status.name().into(),
        },
    }
}

/// A plate (12 x 8 x 1 cm) and a ring (12 cm across, 2.5 cm wide, 1 cm thick): flat objects lying
/// on the table.
fn flat_objects() -> Vec<ObjectSpec> {
    let (outer_m, inner_m, height_m, segments) = (0.06, 0.035, 0.01, 48u32);
    let mut vertices = Vec::new();
    for i in 0..segments {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(segments);
        let (c, s) = (a.cos(), a.sin());
        for r in [outer_m, inner_m] {
            vertices.extend([DVec3::new(r * c, r * s, 0.0), DVec3::new(r * c, r * s, height_m)]);
        }
    }
    let mut triangles = Vec::new();
    for i in 0..segments {
        let j = (i + 1) % segments;
        // Outer bottom, outer top, inner bottom, inner top of this segment and the next.
        let [ob, ot, ib, it] = [0, 1, 2, 3].map(|k| 4 * i + k);
        let [ob2, ot2, ib2, it2] = [0, 1, 2, 3].map(|k| 4 * j + k);
        triangles.extend([
            [ot, ot2, it2],
            [ot, it2, it],
            [ob, ib2, ob2],
            [ob, ib, ib2],
            [ob, ob2, ot2],
            [ob, ot2, ot],
            [ib, it2, ib2],
            [ib, it, it2],
        ]);
    }
    vec![
        ObjectSpec::new("plate", TriMesh::cuboid(DVec3::new(0.06, 0.04, 0.005))),
        ObjectSpec::new("ring", TriMesh { vertices, triangles }),
    ]
}
