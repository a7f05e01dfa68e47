//! Bag-of-features recognition (Sec. IV-A, V-B1): codebooks on known clusters, the decision rule
//! against brute force, the posterior, and a toy object set end to end.
#![allow(clippy::needless_range_loop)] // index loops mirror the sums of Eq. 4 and 16

mod recognize_toy;

use rand::RngExt;
use recognize_toy::{OBJECTS, normal};
use taction::describe::{DescriptorKind, Feature};
use taction::recognize::pipeline::{
    ClusterHistogram, CodebookModel, FeatureMatrix, GaussianMixture, GmmConfig, KMeans, KMeansConfig,
    ObjectModels, kmeans_plus_plus,
};
use taction::recognize::{
    CodebookKind, LabelledFeatures, PseudoCount, ReadingRange, TrainConfig, TrainProgress, cross_entropy,
    evaluate, make_trials, train,
};
use taction::rng::stream;
use taction::valid::Valid;

/// Three Gaussian clusters in 3-D with different covariances and weights.
const MEANS: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [6.0, 1.0, -2.0], [-3.0, 7.0, 4.0]];
const SCALES: [[f64; 3]; 3] = [[1.0, 0.5, 0.8], [0.4, 1.2, 0.6], [0.9, 0.9, 0.3]];
const COUNTS: [usize; 3] = [600, 900, 300];

fn clusters(seed: u64) -> FeatureMatrix {
    let mut rng = stream(seed, 0);
    let mut features: Vec<Feature> = Vec::new();
    for (c, &n) in COUNTS.iter().enumerate() {
        for _ in 0..n {
            features.push(
                (0..3)
                    .map(|d| MEANS[c][d] + SCALES[c][d] * normal(&mut rng))
                    .collect(),
            );
        }
    }
    FeatureMatrix::from_features(&features, "clusters").unwrap()
}

#[test]
fn gmm_recovers_the_means_weights_and_variances_of_known_clusters() {
    let data = clusters(11);
    let (gmm, fit) = GaussianMixture::fit(&data, 3, &GmmConfig::default(), &mut stream(3, 0)).unwrap();
    assert!(fit.converged, "{fit:?}");
    let total = COUNTS.iter().sum::<usize>() as f64;
    for (c, mean) in MEANS.iter().enumerate() {
        // Match each true cluster to the nearest fitted component.
        let (i, _) = gmm
            .means()
            .iter()
            .map(|m| m.iter().zip(mean).map(|(a, b)| (a - b).powi(2)).sum::<f64>())
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        // Standard error of a mean is scale / sqrt(n) <= 1.2 / sqrt(300) = 0.07.
        for d in 0..3 {
            assert!(
                (gmm.means()[i][d] - mean[d]).abs() < 0.25,
                "cluster {c}: {:?}",
                gmm.means()[i]
            );
            let var = gmm.parameters().covariances[i][d * 3 + d];
            let expected = SCALES[c][d].powi(2);
            assert!(
                (var - expected).abs() < 0.25 * expected,
                "cluster {c} dim {d}: {var} vs {expected}"
            );
        }
        assert!(
            (gmm.weights()[i] - COUNTS[c] as f64 / total).abs() < 0.01,
            "{:?}",
            gmm.weights()
        );
    }
    // Responsibilities are a distribution and pick the right component far inside a cluster.
    let mut r = [0.0; 3];
    gmm.responsibilities(&MEANS[1], &mut r);
    assert!((r.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    assert!(r.iter().any(|&p| p > 0.999), "{r:?}");
}

#[test]
fn fits_are_seeded_and_deterministic_bit_for_bit() {
    let data = clusters(5);
    let seeds = |seed| kmeans_plus_plus(&data, 3, &mut stream(seed, 0));
    assert_eq!(seeds(1), seeds(1));
    assert!(
        (0..10).any(|s| seeds(s) != seeds(1)),
        "different seeds should give different seeds"
    );
    let km = |seed| {
        KMeans::fit(&data, 5, &KMeansConfig::default(), &mut stream(seed, 0))
            .unwrap()
            .0
    };
    let (a, b) = (km(7), km(7));
    let bits = |k: &KMeans| -> Vec<u64> { k.centers().iter().flatten().map(|v| v.to_bits()).collect() };
    assert_eq!(bits(&a), bits(&b));
    let gmm = |seed| {
        GaussianMixture::fit(&data, 4, &GmmConfig::default(), &mut stream(seed, 0))
            .unwrap()
            .0
    };
    let (g1, g2) = (gmm(9), gmm(9));
    let gbits = |g: &GaussianMixture| -> Vec<u64> {
        let p = g.parameters();
        p.weights
            .iter()
            .chain(p.means.iter().flatten())
            .chain(p.covariances.iter().flatten())
            .map(|v| v.to_bits())
            .collect()
    };
    assert_eq!(gbits(&g1), gbits(&g2));
}

#[test]
fn mixture_log_likelihood_matches_a_brute_force_density() {
    let data = clusters(2);
    let (gmm, fit) = GaussianMixture::fit(&data, 3, &GmmConfig::default(), &mut stream(1, 0)).unwrap();
    // ln sum_i pi_i N(x; mu_i, Sigma_i) with Sigma^-1 and det by Gaussian elimination (3x3 cofactors).
    let p = gmm.parameters();
    let brute = |x: &[f64]| -> f64 {
        let mut total = 0.0;
        for i in 0..3 {
            let s = &p.covariances[i];
            let m = |r: usize, c: usize| s[r * 3 + c];
            let det = m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1))
                - m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0))
                + m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
            let cof = |r: usize, c: usize| {
                let rows: Vec<usize> = (0..3).filter(|&k| k != r).collect();
                let cols: Vec<usize> = (0..3).filter(|&k| k != c).collect();
                let minor =
                    m(rows[0], cols[0]) * m(rows[1], cols[1]) - m(rows[0], cols[1]) * m(rows[1], cols[0]);
                if (r + c).is_multiple_of(2) { minor } else { -minor }
            };
            let d: Vec<f64> = (0..3).map(|k| x[k] - p.means[i][k]).collect();
            let mut q = 0.0;
            for r in 0..3 {
                for c in 0..3 {
                    q += d[r] * cof(c, r) / det * d[c];
                }
            }
            total += p.weights[i] * (-0.5 * q).exp() / ((2.0 * std::f64::consts::PI).powi(3) * det).sqrt();
        }
        total.ln()
    };
    let scores = gmm.score_samples(&data);
    for r in (0..data.rows()).step_by(97) {
        assert!((scores[r] - brute(data.row(r))).abs() < 1e-9, "row {r}");
    }
    let mean: f64 = (0..data.rows()).map(|r| brute(data.row(r))).sum::<f64>() / data.rows() as f64;
    assert!((fit.mean_log_likelihood - mean).abs() < 1e-9);
}

/// Random smoothed models over `k` clusters for `n` objects.
fn random_models(n: usize, k: usize, seed: u64) -> ObjectModels {
    let mut rng = stream(seed, 0);
    let histograms: Vec<ClusterHistogram> = (0..n)
        .map(|_| {
            let mut h = ClusterHistogram::new(k);
            for _ in 0..20 {
                let mut m: Vec<f64> = (0..k).map(|_| rng.random::<f64>().powi(4)).collect();
                let s: f64 = m.iter().sum();
                m.iter_mut().for_each(|v| *v /= s);
                h.add(&m);
            }
            h
        })
        .collect();
    ObjectModels::fit(
        (0..n).map(|j| format!("o{j}")).collect(),
        &histograms,
        PseudoCount::new(0.3).unwrap(),
    )
    .unwrap()
}

#[test]
fn decision_equals_brute_force_eq4_and_the_kl_argmin() {
    for seed in 0..20 {
        let models = random_models(5, 7, seed);
        let mut rng = stream(seed, 1);
        let mut u = ClusterHistogram::new(7);
        for _ in 0..(1 + seed as usize % 6) {
            let m: Vec<f64> = {
                let raw: Vec<f64> = (0..7).map(|_| rng.random::<f64>()).collect();
                let s: f64 = raw.iter().sum();
                raw.iter().map(|v| v / s).collect()
            };
            u.add(&m);
        }
        let decision = models.decide(&u);
        let p_u = u.distribution();
        // Eq. 4 by hand, and Eq. 1-2 (KL) by hand: same argmin.
        let h: Vec<f64> = (0..5)
            .map(|j| {
                -(0..7)
                    .map(|i| p_u[i] * models.probabilities(j)[i].ln())
                    .sum::<f64>()
            })
            .collect();
        let kl: Vec<f64> = (0..5)
            .map(|j| {
                (0..7)
                    .map(|i| p_u[i] * (p_u[i] / models.probabilities(j)[i]).ln())
                    .sum::<f64>()
            })
            .collect();
        let argmin = |v: &[f64]| (0..v.len()).min_by(|&a, &b| v[a].total_cmp(&v[b])).unwrap();
        assert_eq!(decision.guess, argmin(&h), "seed {seed}");
        assert_eq!(decision.guess, argmin(&kl), "seed {seed}");
        for j in 0..5 {
            assert!((decision.cross_entropy[j] - h[j]).abs() < 1e-12);
            assert!((cross_entropy(&p_u, models.log_probabilities(j)) - h[j]).abs() < 1e-12);
        }
        // Eq. 15: p(U | O_j) = prod_i p(c_i | O_j)^(n_U p(c_i | U)), normalised over j.
        let n_u = u.features() as f64;
        let likelihood: Vec<f64> = (0..5)
            .map(|j| {
                (0..7)
                    .map(|i| models.probabilities(j)[i].powf(n_u * p_u[i]))
                    .product::<f64>()
            })
            .collect();
        let z: f64 = likelihood.iter().sum();
        for j in 0..5 {
            assert!(
                (decision.probabilities[j] - likelihood[j] / z).abs() < 1e-12,
                "seed {seed} object {j}"
            );
        }
        assert!((decision.probabilities.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}

fn toy_features(per_object: usize, seed: u64) -> LabelledFeatures {
    let descriptor = DescriptorKind::PolarFourier.build();
    LabelledFeatures::from_dataset(&recognize_toy::dataset(per_object, seed), descriptor.as_ref())
}

fn toy_config(codebook: CodebookKind) -> Valid<TrainConfig> {
    Valid::new(TrainConfig {
        codebook,
        ks: vec![3, 6],
        restarts: 2,
        seed: 17,
        ..TrainConfig::default()
    })
    .unwrap()
}

#[test]
fn the_posterior_sharpens_as_consistent_readings_arrive() {
    let trained = train(
        &toy_config(CodebookKind::Gmm),
        &toy_features(40, 1),
        None,
        &mut |_| {},
    )
    .unwrap();
    let test = toy_features(12, 99);
    for j in 0..OBJECTS.len() {
        let mut posterior = trained.bag.posterior();
        let start = posterior.belief();
        assert!((start.entropy_nats() - (OBJECTS.len() as f64).ln()).abs() < 1e-12);
        let mut entropies = vec![start.entropy_nats()];
        for reading in test.readings(j) {
            let belief = posterior.observe(reading).unwrap();
            assert!((belief.probabilities().iter().sum::<f64>() - 1.0).abs() < 1e-12);
            entropies.push(belief.entropy_nats());
        }
        let last = posterior.belief();
        assert_eq!(
            last.guess(),
            j,
            "object {}: {:?}",
            OBJECTS[j],
            last.probabilities()
        );
        assert!(last.probabilities()[j] > 0.99, "{:?}", last.probabilities());
        // Entropy falls overall, and ends far below where it started.
        assert!(
            entropies[entropies.len() - 1] < 0.05 * entropies[0],
            "{entropies:?}"
        );
        let halves = entropies.len() / 2;
        assert!(entropies[halves..].iter().sum::<f64>() < entropies[..halves].iter().sum::<f64>());
    }
}

#[test]
fn toy_objects_are_recognised_at_100_percent_with_10_readings() {
    let training = toy_features(60, 1);
    let validation = toy_features(20, 2);
    let test = toy_features(30, 3);
    for kind in CodebookKind::ALL {
        let trained = train(&toy_config(kind), &training, Some(&validation), &mut |_| {}).unwrap();
        let chosen = trained.selection.chosen().unwrap();
        assert!([3, 6].contains(&trained.selection.chosen_k));
        // The neighbour codebook draws nothing at random: one candidate per k, not per restart.
        let restarts = if kind.is_random() { 2 } else { 1 };
        assert_eq!(trained.selection.candidates.len(), 2 * restarts);
        assert!(
            trained
                .selection
                .candidates
                .iter()
                .all(|c| !c.is_better_than(chosen)),
            "{:?}",
            trained.selection.candidates
        );
        let trials = make_trials(&test, trained.bag.objects(), 10).unwrap();
        assert_eq!(trials.len(), 9);
        let evaluation = evaluate(&trained.bag, &trials, ReadingRange::new(1, 10).unwrap()).unwrap();
        assert_eq!(
            evaluation.accuracy_at(10),
            Some(1.0),
            "{kind:?}: {:?}",
            evaluation.accuracy
        );
        assert_eq!(evaluation.confusion.total(), 9);
        assert_eq!(evaluation.confusion.accuracy(), 1.0);
        assert_eq!(evaluation.touches.len(), 90);
    }
}

#[test]
fn accuracy_counts_every_object_an_unread_one_as_a_miss() {
    let trained = train(
        &toy_config(CodebookKind::Gmm),
        &toy_features(60, 1),
        None,
        &mut |_| {},
    )
    .unwrap();
    let test = toy_features(30, 3);
    // Object 0 read 10 times, object 1 twice, object 2 never (the exploration failed on it).
    let readings = vec![
        test.readings(0)[..10].to_vec(),
        test.readings(1)[..2].to_vec(),
        Vec::new(),
    ];
    let partial = LabelledFeatures::new(test.objects().to_vec(), readings).unwrap();
    let trials = make_trials(&partial, trained.bag.objects(), 10).unwrap();
    assert_eq!(trials.len(), 3, "the unread object is a trial with no readings");
    assert!(trials[2].readings.is_empty());
    let evaluation = evaluate(&trained.bag, &trials, ReadingRange::new(1, 10).unwrap()).unwrap();
    let full = evaluate(
        &trained.bag,
        &make_trials(&test, trained.bag.objects(), 10).unwrap(),
        ReadingRange::new(1, 10).unwrap(),
    )
    .unwrap();
    // The toy objects are told apart after two readings: objects 0 and 1 are right from then on
    // (object 1 keeping its belief after its last reading), object 2 never is.
    for n in 2..=10 {
        let row = &evaluation.accuracy[n - 1];
        assert_eq!((row.n_readings, row.trials, row.correct), (n, 3, 2), "{row:?}");
        assert_eq!(full.accuracy_at(n), Some(1.0), "{:?}", full.accuracy);
    }
    // The unread object's p(true) is the uniform prior 1/3; the others' the belief they reached.
    let p_true = |t: usize, n: usize| {
        evaluation
            .touches
            .iter()
            .find(|r| r.trial == t && r.n_readings == n)
            .map(|r| r.p_true())
            .unwrap()
    };
    let expected = (p_true(0, 10) + p_true(1, 2) + 1.0 / 3.0) / 3.0;
    assert!((evaluation.accuracy[9].reliability - expected).abs() < 1e-12);
    // No row beyond the longest trial; the unread object has no touches and no confusion entry.
    assert_eq!(evaluation.accuracy.len(), 10);
    assert!(evaluation.touches.iter().all(|r| r.trial != 2));
    assert_eq!(evaluation.confusion.total(), 2);
}

#[test]
fn training_is_seeded_and_deterministic() {
    let training = toy_features(30, 4);
    let a = train(&toy_config(CodebookKind::Gmm), &training, None, &mut |_| {}).unwrap();
    let b = train(&toy_config(CodebookKind::Gmm), &training, None, &mut |_| {}).unwrap();
    assert_eq!(a, b);
    let json = |t: &taction::recognize::Trained| serde_json::to_string(&t.bag).unwrap();
    assert_eq!(json(&a), json(&b));
}

/// The neighbour codebook is a function of the data (the same model from 1 and 3 threads), holds
/// every training feature with one cluster per object, and (its training memberships taken with
/// each reading left out, unit-tested in `recognize::neighbours`) gives each toy object's own bin
/// more than chance and less than all.
#[test]
fn the_neighbour_codebook_is_deterministic_and_holds_the_training_features() {
    let training = toy_features(30, 4);
    let config = Valid::new(TrainConfig {
        ks: vec![5],
        ..toy_config(CodebookKind::Knn).into_inner()
    })
    .unwrap();
    let train_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| train(&config, &training, None, &mut |_| {}).unwrap())
    };
    let one = train_on(1);
    assert_eq!(one, train_on(3));
    let CodebookModel::Knn(nn) = one.bag.codebook() else {
        panic!("not a neighbour codebook")
    };
    assert_eq!((nn.neighbours(), nn.clusters()), (5, OBJECTS.len()));
    // The training part of the data (hold-out taken off) went in whole.
    assert_eq!(nn.len(), one.selection.training_features);
    let models = one.bag.models();
    let own: Vec<f64> = (0..OBJECTS.len()).map(|j| models.probabilities(j)[j]).collect();
    assert!(
        own.iter().all(|&p| p > 1.0 / OBJECTS.len() as f64 && p < 1.0),
        "{own:?}"
    );
}

#[test]
fn candidates_fitted_in_parallel_give_the_model_of_one_thread_and_report_each_once() {
    let training = toy_features(30, 4);
    let train_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut events = Vec::new();
        let trained = pool.install(|| {
            train(&toy_config(CodebookKind::Gmm), &training, None, &mut |e| {
                events.push(e)
            })
            .unwrap()
        });
        (trained, events)
    };
    let (one, one_events) = train_on(1);
    let (three, three_events) = train_on(3);
    assert_eq!(one, three);
    // The candidates are listed in grid order (k, then restart) whatever finished first.
    let order: Vec<(usize, usize)> = three
        .selection
        .candidates
        .iter()
        .map(|c| (c.k, c.restart))
        .collect();
    assert_eq!(order, vec![(3, 0), (3, 1), (6, 0), (6, 1)]);
    for events in [one_events, three_events] {
        let fitting = events
            .iter()
            .filter(|e| matches!(e, TrainProgress::Fitting { .. }))
            .count();
        let scored = events
            .iter()
            .filter(|e| matches!(e, TrainProgress::Scored(_)))
            .count();
        assert_eq!((fitting, scored), (4, 4));
    }
}

#[test]
fn bad_inputs_get_named_errors() {
    let trained = train(
        &toy_config(CodebookKind::Kmeans),
        &toy_features(20, 5),
        None,
        &mut |_| {},
    )
    .unwrap();
    let mut posterior = trained.bag.posterior();
    let e = posterior.observe(&[vec![0.5; 3]]).unwrap_err().to_string();
    assert!(e.contains("reading 1") && e.contains("3 values"), "{e}");
    let dim = trained.bag.input_dim();
    let mut bad = vec![0.1; dim];
    bad[2] = f64::NAN;
    let e = posterior.observe(&[bad]).unwrap_err().to_string();
    assert!(e.contains("value 2 is NaN"), "{e}");
    assert_eq!(
        posterior.readings(),
        0,
        "a rejected reading leaves the posterior unchanged"
    );
    let unknown = LabelledFeatures::new(vec!["teapot".into()], vec![vec![vec![vec![0.0; dim]]]]).unwrap();
    let e = make_trials(&unknown, trained.bag.objects(), 10)
        .unwrap_err()
        .to_string();
    assert!(e.contains("'teapot'"), "{e}");
    let config = TrainConfig {
        ks: vec![],
        ..toy_config(CodebookKind::Gmm).into_inner()
    };
    assert!(Valid::new(config).is_err());
    assert!("0..5".parse::<ReadingRange>().is_err());
    assert_eq!(
        "3..=7".parse::<ReadingRange>().unwrap(),
        ReadingRange::new(3, 7).unwrap()
    );
    assert_eq!(
        "30".parse::<ReadingRange>().unwrap(),
        ReadingRange::new(1, 30).unwrap()
    );
}
