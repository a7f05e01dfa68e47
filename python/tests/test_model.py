"""Training and recognising from Python: the posterior after each reading, files, errors."""

import csv

import numpy as np
import pytest

import taction
from conftest import taction_cli


def test_the_posterior_moves_toward_the_touched_object(small_model, small_dataset):
    assert small_model.objects == ["pawn", "rook"]
    assert small_model.descriptor == "mnti"
    converged = small_dataset.status == "converged"
    images = small_dataset.images[converged]
    names = small_dataset.object[converged]
    right = 0
    for target in ("pawn", "rook"):
        posterior = small_model.posterior()
        assert np.allclose(posterior.probabilities, [0.5, 0.5])
        for image in images[names == target][:10]:
            p = posterior.observe(image)
        assert p.shape == (2,)
        assert abs(p.sum() - 1.0) < 1e-9
        assert posterior.readings == 10
        right += posterior.guess == target
    assert right == 2


def test_a_model_file_round_trips(small_model, small_dataset, tmp_path):
    path = tmp_path / "model.json"
    small_model.save(path)
    again = taction.Model.load(path)
    image = small_dataset.images[small_dataset.status == "converged"][0]
    a = small_model.posterior().observe(image)
    b = again.posterior().observe(image)
    assert np.array_equal(a, b)
    scores = again.evaluate(small_dataset, readings=5)
    assert scores["trials"] > 0 and len(scores["accuracy"]) == 5


def test_the_calibrated_posterior_keeps_the_guess_and_eq15_is_a_choice(small_model, small_dataset):
    calibration = small_model.calibration
    assert set(calibration) == {"tau", "beta", "floor", "confidence_map"}
    assert calibration["tau"] > 0 and 0 <= calibration["floor"] < 1
    eq15 = small_model.with_posterior("eq15")
    assert eq15.calibration == {"tau": 1.0, "beta": 1.0, "floor": 0.0, "confidence_map": None}
    images = small_dataset.images[small_dataset.status == "converged"][:5]
    calibrated, paper = small_model.posterior(), eq15.posterior()
    for image in images:
        p, q = calibrated.observe(image), paper.observe(image)
        assert np.argmax(p) == np.argmax(q)
    with pytest.raises(taction.TactionError, match="posterior"):
        small_model.with_posterior("bayes")


def tempering_in(node):
    """The posterior's tempering in a model file's JSON: the object holding tau and beta."""
    if isinstance(node, dict):
        if "tau" in node and "beta" in node:
            return node
        node = list(node.values())
    if isinstance(node, list):
        for value in node:
            found = tempering_in(value)
            if found is not None:
                return found
    return None


def test_a_confidence_map_in_the_model_file_moves_the_belief_and_keeps_the_guess(
    small_model, small_dataset, tmp_path
):
    import json

    path = tmp_path / "model.json"
    small_model.save(path)
    document = json.loads(path.read_text())
    tempering = tempering_in(document)
    assert tempering is not None and small_model.calibration["confidence_map"] is None
    # Beliefs above 0.95 were right 60% of the time: a sure posterior is moved to 0.6.
    points = [[0.6, 0.55], [0.95, 0.6]]
    tempering["confidence_map"] = points
    path.write_text(json.dumps(document))
    mapped = taction.Model.load(path)
    assert mapped.calibration["confidence_map"] == points
    converged = small_dataset.status == "converged"
    images, names = small_dataset.images[converged], small_dataset.object[converged]
    sure = 0
    for target in ("pawn", "rook"):
        plain, moved = small_model.posterior(), mapped.posterior()
        for image in images[names == target][:10]:
            p, q = plain.observe(image), moved.observe(image)
            assert np.argmax(p) == np.argmax(q)
            assert abs(q.sum() - 1.0) < 1e-9
            if p.max() > 0.95:
                sure += 1
                assert abs(q.max() - 0.6) < 1e-6
    assert sure > 0
    tempering["confidence_map"] = [[0.9, 0.6], [0.7, 0.8]]
    path.write_text(json.dumps(document))
    with pytest.raises(taction.TactionError, match="confidence map"):
        taction.Model.load(path)


def test_training_is_seeded(small_dataset):
    a = taction.train(small_dataset, descriptor="mnti", ks=[4], restarts=1, seed=3)
    b = taction.train(small_dataset, descriptor="mnti", ks=[4], restarts=1, seed=3)
    image = small_dataset.images[small_dataset.status == "converged"][0]
    assert np.array_equal(a.posterior().observe(image), b.posterior().observe(image))


def test_the_shape_index_trains_the_network_by_default(small_dataset):
    """Issue 73: `codebook` left out is the product's choice for the descriptor: the network (its
    candidate sizes are hidden units, 128 and 256) for the shape index, the neighbour codebook
    (neighbour counts below half an object's readings) for the others."""
    network = taction.train(small_dataset, descriptor="shape-index", restarts=1, seed=3)
    assert network.k[0] in (128, 256)
    neighbours = taction.train(small_dataset, descriptor="mnti", restarts=1, seed=3)
    assert neighbours.k[0] < 128
    image = small_dataset.images[small_dataset.status == "converged"][0]
    belief = network.posterior().observe(image)
    assert belief.shape == (len(network.objects),) and abs(belief.sum() - 1.0) < 1e-9


def test_bad_training_arguments_name_the_argument(small_dataset, small_model):
    with pytest.raises(taction.TactionError, match="descriptor"):
        taction.train(small_dataset, descriptor="nope")
    with pytest.raises(taction.TactionError, match="codebook"):
        taction.train(small_dataset, codebook="nope")
    with pytest.raises(taction.TactionError, match="image"):
        small_model.posterior().observe(np.zeros(6))
    with pytest.raises(taction.TactionError, match="image"):
        small_model.posterior().observe(np.zeros((14, 14)))


def test_models_objects_and_datasets_pickle(small_model, small_dataset, chess):
    import pickle

    model = pickle.loads(pickle.dumps(small_model))
    assert model.objects == small_model.objects and model.k == small_model.k
    image = small_dataset.images[small_dataset.status == "converged"][0]
    assert np.array_equal(model.posterior().observe(image), small_model.posterior().observe(image))
    dataset = pickle.loads(pickle.dumps(small_dataset))
    assert np.array_equal(dataset.images, small_dataset.images)
    assert list(dataset.cause) == list(small_dataset.cause)
    pawn = pickle.loads(pickle.dumps(chess[0]))
    assert pawn.name == "pawn" and np.array_equal(pawn.bounds_m, chess[0].bounds_m)
    pose = [0, 0, chess[0].bounds_m[1, 2] + 0.0006, 0, 0, -1, 0, 1, 0]
    assert np.array_equal(taction.Sensor().read(pawn, pose), taction.Sensor().read(chess[0], pose))
    with pytest.raises(taction.TactionError, match="the model's bytes"):
        taction.Model.from_json(b"{}")


def test_the_arm_calibration_is_the_recipes_exploration_and_calibrates_the_arm_model(chess):
    explorations = taction.collect_arm_calibration(chess, training_readings=600, seed=3)
    # A thirtieth of the training readings per object in fresh explorations of 10, each by the
    # planner at L = 0.5, the object fixed at a random start, on a stream of the seed of its own:
    # the planner collection of that stream's seed, bit for bit.
    assert len(explorations) == 2
    seeds = {exploration.header["seed"] for exploration in explorations}
    assert len(seeds) == 2 and 3 not in seeds
    for exploration in explorations:
        converged = exploration.status == "converged"
        for name in ("pawn", "rook"):
            assert (exploration.object[converged] == name).sum() == 10
        seed = exploration.header["seed"]
        planner = taction.collect(
            chess, mode="planner", readings=10, local_probability=0.5, seed=seed, start_pose="random"
        )
        assert np.array_equal(exploration.images, planner.images)
        assert list(exploration.object) == list(planner.object)
        canonical = taction.collect(chess, mode="planner", readings=10, local_probability=0.5, seed=seed)
        assert not np.array_equal(canonical.images, planner.images), "the start is drawn, not the canonical pose"
    again = taction.collect_arm_calibration(chess, training_readings=600, seed=3)
    assert all(np.array_equal(a.images, b.images) for a, b in zip(explorations, again))
    calibration = explorations[0]
    converged = calibration.status == "converged"
    # At least 10 readings per object, however little training.
    few = taction.collect_arm_calibration(chess, training_readings=60, seed=3)
    assert len(few) == 1
    assert ((few[0].object == "pawn") & (few[0].status == "converged")).sum() == 10

    # Calibrated on the arm's touches, the posterior is less sure of them than one calibrated on
    # readings held out of the sampler's training data (on both explorations' four trials: one
    # exploration of 10 per object is two trials, too few to fit a tempering on).
    training = taction.collect(chess, mode="sampler", readings=110, seed=3, reachable_by_arm=True)
    on_validation = taction.train_for_arm(training.converged(), seed=3)
    on_arm = taction.train_for_arm(training.converged(), seed=3, calibration=explorations)
    assert on_arm.calibration != on_validation.calibration

    def mean_top_probability(model):
        tops = []
        for name in ("pawn", "rook"):
            posterior = model.posterior()
            for image in calibration.images[converged & (calibration.object == name)][:10]:
                tops.append(posterior.observe(image).max())
        return np.mean(tops)

    assert mean_top_probability(on_arm) < mean_top_probability(on_validation)


def test_the_arm_model_is_the_recipes_collections_and_fit_in_one_call(chess, tmp_path):
    # The demo's recipe in one call, bit for bit the model its steps give one at a time: the
    # sampler's reachable training readings, the arm's calibration explorations, the fit.
    whole = taction.arm_model(chess, training_readings=60, seed=4)
    training = taction.collect(chess, mode="sampler", readings=60, seed=4, reachable_by_arm=True)
    calibration = taction.collect_arm_calibration(chess, training_readings=60, seed=4)
    steps = taction.train_for_arm(training, seed=4, calibration=calibration, objects=chess)
    whole.save(tmp_path / "whole.json")
    steps.save(tmp_path / "steps.json")
    assert (tmp_path / "whole.json").read_bytes() == (tmp_path / "steps.json").read_bytes()
    assert whole.objects == ["pawn", "rook"]
    assert whole.descriptor == "mnti+sift"
    assert whole.contacts, "the demo's model weighs where each touch landed"
    appearance = taction.train_for_arm(training, seed=4, calibration=calibration)
    assert not appearance.contacts
    other = taction.arm_model(chess, training_readings=60, seed=5)
    other.save(tmp_path / "other.json")
    assert (tmp_path / "other.json").read_bytes() != (tmp_path / "whole.json").read_bytes()


def test_the_arm_calibration_rejects_no_objects():
    with pytest.raises(taction.TactionError, match="objects: no object to touch"):
        taction.collect_arm_calibration([])


def test_a_model_that_knows_where_it_touched_reads_each_pad_pose_and_round_trips(chess, small_dataset, tmp_path):
    explorations = taction.collect(chess, mode="planner", readings=8, local_probability=0.5, seed=11)
    with pytest.raises(taction.TactionError, match="objects: .*give calibration"):
        taction.train(small_dataset, descriptor="mnti", codebook="knn", ks=[5], objects=chess)
    with pytest.raises(taction.TactionError, match="start_heading_deg"):
        taction.train(small_dataset, objects=chess, calibration=[explorations], start_heading_deg=270.0)
    model = taction.train(
        small_dataset, descriptor="mnti", codebook="knn", ks=[5], restarts=1, seed=2,
        objects=chess, calibration=[explorations],
    )
    appearance = taction.train(small_dataset, descriptor="mnti", codebook="knn", ks=[5], restarts=1, seed=2)
    assert model.contacts and not appearance.contacts
    assert repr(model).startswith("Model(mnti with contacts, k=[5]")
    test = taction.collect(chess, mode="planner", readings=6, local_probability=0.5, seed=12)
    rook = (test.object == "rook") & (test.status == "converged")
    images, poses = test.images[rook], test.pad_pose[rook]
    model_path = tmp_path / "model.json"
    model.save(model_path)
    again = taction.Model.load(model_path)
    touched, read_back, unplaced, alone = (m.posterior() for m in (model, again, model, appearance))
    for image, pose in zip(images, poses):
        p = touched.observe(image, pad_pose=pose)
        p_again = read_back.observe(image, pad_pose=pose)
        q = unplaced.observe(image)
        r = alone.observe(image)
    # The model file holds the model: the same beliefs, bit for bit.
    assert np.array_equal(p, p_again)
    # Without its pad pose a touch is appearance alone; with it, the contacts move the belief.
    assert np.argmax(q) == np.argmax(r)
    assert not np.allclose(np.log(p), np.log(q))
    # The CLI recognises the same readings with the model file to the same guess (its images are
    # the dataset's float64 taxels, Python's float32, so the beliefs differ in the last digits and
    # the contacts' seeded noise with them).
    test_path, out = tmp_path / "test.csv", tmp_path / "run"
    test.save(test_path)
    taction_cli("recognize", "--model", str(model_path), "--dataset", str(test_path), "--readings", "6", "--out", str(out))
    rows = [r for r in csv.DictReader(open(out / "posterior_long.csv")) if r["object_true"] == "rook" and r["n_readings"] == "6"]
    cli = {r["object"]: float(r["probability"]) for r in rows}
    assert model.objects[int(np.argmax(p))] == max(cli, key=cli.get) == "rook"
    with pytest.raises(taction.TactionError, match="pad_pose"):
        model.posterior().observe(images[0], pad_pose=[0.0, 0.0, 0.1])
