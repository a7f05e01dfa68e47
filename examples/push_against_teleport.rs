//! Sec. V-B4's perturbation as a push against the paper's teleport (issue 74, item 4), per
//! object: the same draws of the paper's bounds (10 deg, 10% of the width), teleporting the fixed
//! object and pushing the free one (`Scene::push_object`), each from where it stands; a push that
//! tipped the object is counted and the object stood up again where it rested before it. Prints
//! per object the centre's shift along the table and the turn (mean and 95th percentile) of each,
//! the pushes that tipped it, and whether both means are the teleport's within 10%.
//!
//! `cargo run --release --example push_against_teleport -- [shapes|boxes] [draws] [seed] [object]`
//! (defaults shapes, 40, 31; `boxes`: an 8 x 6 x 5 cm box and a 3 x 3 x 10 cm post, standing on
//! their bases; an object's name prints each push's draw and motion)

use glam::DVec3;
use taction::mesh::TriMesh;
use taction::sim::{MotionSummary, ObjectSpec, PerturbationBounds, Scene};
use taction::tactile::SensorConfig;
use taction::valid::Valid;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let set = args.first().map(String::as_str).unwrap_or("shapes");
    let draws: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(40);
    let seed: u64 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(31);
    let only = args.get(3).map(String::as_str);
    let objects = match set {
        "shapes" => ObjectSpec::all_of(&taction::mesh::ObjectSet::shapes())?,
        "boxes" => boxes(),
        other => return Err(format!("set '{other}' is neither shapes nor boxes").into()),
    };
    let config = Valid::new(SensorConfig::paper())?;
    println!(
        "object,teleport_shift_mean_mm,teleport_shift_p95_mm,teleport_turn_mean_deg,push_shift_mean_mm,push_shift_p95_mm,push_turn_mean_deg,push_turn_p95_deg,tipped,within_10pct"
    );
    let (mut met, mut counted) = (0, 0);
    for object in objects {
        if only.is_some_and(|name| name != object.name) {
            continue;
        }
        let mut teleported: Scene = taction::tactile::arm_with_sensor(object.clone(), &config).build()?;
        let mut pushed: Scene =
            taction::tactile::arm_with_sensor(object.mounted(Some(taction::sim::FreeBody::DEFAULT)), &config)
                .build()?;
        pushed.settle_object()?;
        let rest = pushed.object_pose().ok_or("no object")?;
        let width = teleported.object_width_m().ok_or("no object")?;
        let mut rng = taction::rng::stream(seed, 0);
        let (mut by_push, mut by_teleport) = (Vec::new(), Vec::new());
        for _ in 0..draws {
            let draw = PerturbationBounds::PAPER.draw(width, &mut rng);
            let before = teleported.object_pose().ok_or("no object")?;
            teleported.perturb_object(&draw)?;
            by_teleport.push(teleported.object_motion_from(&before)?);
            teleported.set_object_pose(before)?;
            let motion = pushed.push_object(&draw)?;
            if only.is_some() {
                eprintln!("{draw:?} -> {motion:?}");
            }
            by_push.push(motion);
            if motion.outcome() != taction::sim::MotionOutcome::Standing {
                pushed.set_object_pose(rest)?;
                pushed.settle_object()?;
            }
        }
        let (push, teleport) = (MotionSummary::of(&by_push), MotionSummary::of(&by_teleport));
        let close = |a: f64, b: f64| (a - b).abs() <= 0.1 * b;
        let within = close(push.centre_shift_m.mean, teleport.centre_shift_m.mean)
            && close(push.turn_rad.mean, teleport.turn_rad.mean)
            && push.tipped + push.off_table == 0;
        counted += 1;
        met += usize::from(within);
        println!(
            "{},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{},{}",
            object.name,
            teleport.centre_shift_m.mean * 1e3,
            teleport.centre_shift_m.p95 * 1e3,
            teleport.turn_rad.mean.to_degrees(),
            push.centre_shift_m.mean * 1e3,
            push.centre_shift_m.p95 * 1e3,
            push.turn_rad.mean.to_degrees(),
            push.turn_rad.p95.to_degrees(),
            push.tipped + push.off_table,
            within
        );
    }
    eprintln!("{met} of {counted} objects pushed as far as the teleport within 10%, nothing tipped");
    Ok(())
}

/// A box and a post, each standing on its base at the origin.
fn boxes() -> Vec<ObjectSpec> {
    [
        ("box", DVec3::new(0.08, 0.06, 0.05)),
        ("post", DVec3::new(0.03, 0.03, 0.1)),
    ]
    .into_iter()
    .map(|(name, size)| {
        let mesh = TriMesh::cuboid(size / 2.0).translated(DVec3::Z * size.z / 2.0);
        ObjectSpec::new(name, mesh)
    })
    .collect()
}
