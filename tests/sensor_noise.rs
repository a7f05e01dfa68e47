//! The covering sensor's noise (Sec. V-B7) and its determinism across readings, copies and resets.

mod sensor_support;

use glam::DVec3;
use sensor_support::*;
use taction::tactile::{CoveringSensor, SensorConfig, TactileImage};

fn noisy(seed: u64) -> SensorConfig {
    SensorConfig {
        rows: 26,
        cols: 26,
        noise_fraction: 0.4,
        noise_seed: seed,
        ..SensorConfig::default()
    }
}

/// A plane at half the covering thickness: the noise-free image is 0.5 everywhere.
fn reading(config: &SensorConfig, readings: usize) -> Vec<TactileImage> {
    let mut sensor = free_sensor_with("<geom type=\"plane\" size=\"1 1 0.1\"/>", config);
    sensor.place(&pad_looking_down(DVec3::new(0.0, 0.0, 0.5 * config.thickness_m)));
    (0..readings).map(|_| sensor.read().unwrap()).collect()
}

#[test]
fn noise_is_zero_mean_uniform_of_the_configured_width() {
    let images = reading(&noisy(3), 4);
    let values: Vec<f64> = images.iter().flat_map(|i| i.values().to_vec()).collect();
    assert!(
        values.iter().all(|v| (0.3..=0.7).contains(v)),
        "40% noise on 0.5 stays in [0.3, 0.7]"
    );
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    // U(-0.2, 0.2): mean 0, variance 0.4^2 / 12; 2704 draws.
    assert!((mean - 0.5).abs() < 0.01, "{mean}");
    assert!((var - 0.16 / 12.0).abs() < 0.0015, "{var}");
    assert!(values.iter().any(|&v| v < 0.32) && values.iter().any(|&v| v > 0.68));
}

#[test]
fn noise_clamps_to_the_range() {
    let config = SensorConfig {
        noise_fraction: 2.0,
        ..noisy(5)
    };
    for image in reading(&config, 2) {
        assert!(image.values().iter().all(|v| (0.0..=1.0).contains(v)));
        assert!(image.values().contains(&0.0) && image.values().contains(&1.0));
    }
}

#[test]
fn same_seed_same_images_other_seed_other_images() {
    let a = reading(&noisy(11), 3);
    assert!(a == reading(&noisy(11), 3), "same seed, same images");
    assert!(a[0] != a[1], "successive readings draw fresh noise");
    assert!(a[0] != reading(&noisy(12), 1)[0], "another seed, other noise");
}

#[test]
fn copied_data_continues_and_reset_data_restarts_the_noise() {
    let config = noisy(21);
    let mut sensor = free_sensor_with("<geom type=\"plane\" size=\"1 1 0.1\"/>", &config);
    sensor.place(&pad_looking_down(DVec3::new(0.0, 0.0, 0.5 * config.thickness_m)));
    let first = sensor.read().unwrap();
    let model = sensor.scene().model_arc();
    let handle = CoveringSensor::first(&model).unwrap();
    let mut copy = sensor.scene().data().clone();
    let second = sensor.read().unwrap();
    copy.forward();
    assert!(
        handle.read(&copy).unwrap() == second,
        "a copy continues the noise sequence"
    );
    let data = sensor.scene_mut().data_mut();
    let (pos, quat) = (data.mocap_pos()[0], data.mocap_quat()[0]);
    data.reset();
    data.mocap_pos_mut()[0] = pos;
    data.mocap_quat_mut()[0] = quat;
    // Building the scene ran mj_forward once (reading 0); `first` was reading 1.
    data.forward();
    data.forward();
    assert!(
        handle.read(sensor.scene().data()).unwrap() == first,
        "a reset restarts the noise sequence"
    );
}
