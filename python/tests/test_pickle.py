"""Every public class pickles, and `copy.deepcopy` and `copy.copy` copy it, keeping what matters:
the same readings, images and probabilities, bit for bit, and the same behaviour after the copy."""

import copy
import pickle

import numpy as np
import pytest

import taction

COPIES = {
    "pickle": lambda value: pickle.loads(pickle.dumps(value)),
    "deepcopy": copy.deepcopy,
    # A shallow copy shares the arguments (an episode's model) and replays the state.
    "copy": copy.copy,
}


def same(a, b):
    """Equal arrays of the same dtype and shape, bit for bit (NaN equal to NaN)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.fixture(params=sorted(COPIES))
def copied(request):
    return COPIES[request.param]


def test_an_object_copies_with_its_mesh(chess, copied):
    pawn = chess[0]
    again = copied(pawn)
    assert again.name == pawn.name
    assert again.triangles == pawn.triangles
    assert same(again.bounds_m, pawn.bounds_m)


def test_a_sensor_copies_its_configuration_and_reads_the_same(chess, copied):
    pawn = chess[0]
    sensor = taction.Sensor(rows=5, cols=4, pad_m=0.01, noise=0.2, seed=7)
    again = copied(sensor)
    assert isinstance(again, taction.Sensor)
    assert again.config() == sensor.config()
    assert repr(again) == repr(sensor)
    pose = [0, 0, pawn.bounds_m[1, 2] + 0.0006, 0, 0, -1, 0, 1, 0]
    # The noise stream starts afresh in the copy: its first reading is the original's first.
    assert same(again.read(pawn, pose), sensor.read(pawn, pose))
    assert same(again.read(pawn, pose, dtype="float64"), sensor.read(pawn, pose, dtype="float64"))


def test_a_dataset_copies_its_readings(small_dataset, copied):
    again = copied(small_dataset)
    assert len(again) == len(small_dataset)
    assert again.header == small_dataset.header
    assert same(again.images, small_dataset.images)
    assert same(again.pad_pose, small_dataset.pad_pose)
    for column in ("object", "status", "strategy", "cause", "touched_bodies", "iterations"):
        assert same(getattr(again, column), getattr(small_dataset, column)), column


def test_a_model_copies_and_recognises_the_same(small_model, small_dataset, copied):
    again = copied(small_model)
    assert again.objects == small_model.objects
    assert again.k == small_model.k
    images = small_dataset.converged().images[:5]
    original, copy_ = small_model.posterior(), again.posterior()
    for image in images:
        assert same(copy_.observe(image), original.observe(image))


def test_a_posterior_copies_its_evidence_and_keeps_updating_identically(small_model, small_dataset, copied):
    converged = small_dataset.converged()
    images, poses = converged.images, converged.pad_pose
    posterior = small_model.posterior()
    assert same(copied(posterior).probabilities, posterior.probabilities)  # uniform, no reading
    posterior.observe(images[0])
    posterior.observe(images[50], pad_pose=poses[50])
    posterior.observe(images[1].astype(np.float64))
    again = copied(posterior)
    assert isinstance(again, taction.Posterior)
    assert again is not posterior
    assert again.readings == posterior.readings == 3
    assert again.objects == posterior.objects
    assert again.guess == posterior.guess
    assert same(again.probabilities, posterior.probabilities)
    for i in (2, 51, 3):
        assert same(again.observe(images[i], pad_pose=poses[i]), posterior.observe(images[i], pad_pose=poses[i]))
    assert again.readings == posterior.readings == 6
    # The copy is its own: observing on it leaves the original alone.
    before = posterior.probabilities
    again.observe(images[4])
    assert same(posterior.probabilities, before)


def episode_state(episode):
    return {
        "candidates": episode.candidates,
        "probabilities": episode.probabilities,
        "image": episode.image,
        "pad_pose": episode.pad_pose,
        "contact": episode.contact,
        "gains": episode.gains(),
        "readings": episode.readings,
        "attempts": episode.attempts,
        "last_status": episode.last_status,
        "last_cause": episode.last_cause,
        "object": episode.object,
        "object_index": episode.object_index,
        "object_pose": episode.object_pose,
    }


def assert_same_state(a, b):
    sa, sb = episode_state(a), episode_state(b)
    for key in sa:
        if isinstance(sa[key], np.ndarray):
            assert same(sa[key], sb[key]), key
        else:
            assert sa[key] == sb[key], key


@pytest.mark.parametrize("touch", ["guarded", "iteration"])
def test_a_touch_episode_copies_its_touches_and_goes_on_identically(small_model, chess, copied, touch):
    pawn, rook = chess
    episode = taction.TouchEpisode(
        small_model, rook, seed=4, candidates=6, workspace=chess, start_pose="random", touch=touch
    )
    assert_same_state(copied(episode), episode)  # before any touch
    converged = 0
    for index in (0, 3, 1, 5):
        converged += episode.touch(index)
    with pytest.raises(taction.TactionError):
        episode.touch(99)  # refused, touches nothing: not replayed
    again = copied(episode)
    assert isinstance(again, taction.TouchEpisode)
    assert_same_state(again, episode)
    if touch == "guarded":
        assert converged > 0  # the copy replayed readings, not only misses
    for index in (2, 4, 0, 1):
        assert again.touch(index) == episode.touch(index)
        assert_same_state(again, episode)


def test_a_pushed_free_object_episode_copies_where_its_object_went(small_model, chess, copied):
    pawn, rook = chess
    episode = taction.TouchEpisode(
        small_model, rook, seed=4, candidates=6, workspace=chess, free_object=True,
        object_density=800.0, object_friction=0.6, perturb_deg=10.0, perturb_frac=0.1, perturb_by="push",
    )
    start = episode.object_pose.copy()
    converged = sum(episode.touch(index) for index in (0, 3, 1))
    assert converged > 0
    # Pushed toward a new draw after every converged reading.
    assert np.linalg.norm(episode.object_pose[:2] - start[:2]) > 1e-3
    again = copied(episode)
    assert_same_state(again, episode)
    assert again.touch(2) == episode.touch(2)
    assert_same_state(again, episode)


def test_a_touch_episode_replays_only_on_a_fresh_episode(small_model, chess):
    episode = taction.TouchEpisode(small_model, chess[0], seed=2, workspace=chess)
    episode.touch(0)
    _, _, touched = episode.__reduce__()
    assert touched == [0]
    with pytest.raises(taction.TactionError, match="state"):
        episode.__setstate__(touched)


def test_a_taction_error_pickles_with_its_message(copied):
    with pytest.raises(taction.TactionError) as raised:
        taction.Sensor(rows=0)
    for err in (raised.value, taction.TactionError("objects: the set is empty")):
        again = copied(err)
        assert type(again) is taction.TactionError
        assert str(again) == str(err)
        assert again.args == err.args
        assert getattr(again, "__notes__", None) == getattr(err, "__notes__", None)
