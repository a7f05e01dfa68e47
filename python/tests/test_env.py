"""taction/ActiveTouch-v0 and -v1: Gymnasium's own checks, vector envs, seeded determinism, rewards."""

import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import taction

ENV = "taction/ActiveTouch-v0"


@pytest.fixture
def make(small_model):
    def make(budget=4, **kwargs):
        return gymnasium.make(ENV, objects="chess", model=small_model, budget=budget, **kwargs)

    return make


def test_the_environment_is_registered_on_import():
    assert ENV in gymnasium.registry


def test_check_env_passes_without_a_warning(make):
    env = make()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=True)
    env.close()


def test_make_vec_steps_two_environments(small_model):
    envs = gymnasium.make_vec(
        ENV, num_envs=2, vectorization_mode="sync", objects="chess", model=small_model, budget=3
    )
    obs, info = envs.reset(seed=3)
    assert obs["image"].shape == (2, 6, 6)
    assert obs["belief"].shape == (2, 2)
    obs, reward, terminated, truncated, info = envs.step(np.array([0, 1]))
    assert reward.shape == (2,)
    assert np.allclose(reward, -0.01)
    envs.close()


def test_async_vector_environments_match_sync_ones(small_model):
    kwargs = dict(objects="chess", model=small_model, budget=3)
    actions = [np.array([0, 5]), np.array([2, 1])]
    runs = []
    for mode in ("async", "sync"):
        envs = gymnasium.make_vec(ENV, num_envs=2, vectorization_mode=mode, **kwargs)
        obs, _ = envs.reset(seed=4)
        steps = [obs] + [envs.step(a)[:2] for a in actions]
        envs.close()
        runs.append(steps)
    assert same(runs[0], runs[1])


def trace(env, seed, actions):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        out.append((obs, reward, terminated, truncated, info))
        if terminated or truncated:
            break
    return out


def same(a, b):
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    return a == b


def test_same_seed_same_episode(make):
    env = make()
    actions = [0, 3, 1, 2]
    first = trace(env, 11, actions)
    again = trace(env, 11, actions)
    assert same(first, again)
    other = trace(env, 12, actions)
    assert not same(first, other)
    env.close()


def test_a_declaration_ends_the_episode_and_pays_when_right(make):
    env = make()
    obs, _ = env.reset(seed=0, options={"object": "rook"})
    k = env.unwrapped.k
    rook = env.unwrapped.objects.index("rook")
    _, reward, terminated, truncated, info = env.step(k + rook)
    assert terminated and not truncated
    assert reward == 1.0 and info["object"] == "rook" and info["declared"] == "rook"
    env.reset(seed=0, options={"object": "rook"})
    _, reward, terminated, _, _ = env.step(k + (1 - rook))
    assert terminated and reward == -1.0


def test_the_budget_truncates_and_touches_read_the_object(make):
    env = make(budget=30)
    obs, _ = env.reset(seed=5)
    gains = env.unwrapped.gains()
    assert gains.shape == (env.unwrapped.k,) and np.all(np.isfinite(gains))
    steps = 0
    readings = 0
    while True:
        obs, reward, terminated, truncated, info = env.step(int(np.argmax(env.unwrapped.gains())))
        steps += 1
        readings = info["readings"]
        if terminated or truncated:
            break
    assert truncated and steps == 30 and obs["touches"] == 30
    assert abs(obs["belief"].sum() - 1.0) < 1e-5
    assert readings > 0 and obs["image"].max() > 0


def test_bad_arguments_raise(make, small_model):
    with pytest.raises(taction.TactionError, match="budget"):
        gymnasium.make(ENV, objects="chess", model=small_model, budget=0)
    env = make()
    env.reset(seed=0)
    with pytest.raises(taction.TactionError, match="action"):
        env.unwrapped.step(99)
    with pytest.raises(taction.TactionError, match="object"):
        env.reset(seed=0, options={"object": "queen"})
    with pytest.raises(taction.TactionError, match="candidates"):
        taction.TouchEpisode(small_model, env.unwrapped._episode_objects[0], candidates=10**9)
    with pytest.raises(taction.TactionError, match="objects"):
        taction.collect([])
    with pytest.raises(taction.TactionError, match="workspace"):
        taction.TouchEpisode(small_model, env.unwrapped._episode_objects[0], workspace=[])
    pawn, rook = env.unwrapped._episode_objects
    with pytest.raises(taction.TactionError, match="workspace"):
        taction.TouchEpisode(small_model, pawn, workspace=[rook])
    episode = taction.TouchEpisode(small_model, pawn, seed=3)
    with pytest.raises(taction.TactionError, match="indices below"):
        episode.touch(len(episode.candidates))
    for bad in [dict(seed=-1), dict(candidates=-2)]:
        with pytest.raises(taction.TactionError, match="whole number"):
            taction.TouchEpisode(small_model, pawn, **bad)
    with pytest.raises(taction.TactionError, match="start_pose: 'sideways' is none of canonical, random"):
        taction.TouchEpisode(small_model, pawn, start_pose="sideways")
    with pytest.raises(taction.TactionError, match=r"start_heading_deg: 200 is outside \[0, 180\]"):
        taction.TouchEpisode(small_model, pawn, start_pose="random", start_heading_deg=200.0)
    turned = taction.TouchEpisode(small_model, pawn, seed=3, start_pose="random", start_heading_deg=10.0)
    assert turned.candidates.shape == episode.candidates.shape


def test_a_finished_episode_takes_no_more_steps(make):
    env = make(budget=2)
    env.reset(seed=0)
    k = env.unwrapped.k
    env.step(k)  # a declaration ends it
    with pytest.raises(taction.TactionError, match="reset"):
        env.step(k + 1)
    env.reset(seed=0)
    for _ in range(2):
        _, _, _, truncated, _ = env.step(0)
    assert truncated
    with pytest.raises(taction.TactionError, match="reset"):
        env.step(0)
    obs, _ = env.reset(seed=0)  # a reset starts the next episode
    assert env.observation_space.contains(obs)
    env.step(0)


def test_actions_and_options_are_what_the_spaces_say(make):
    env = make()
    with pytest.raises(taction.TactionError, match="reset"):
        env.unwrapped.gains()
    env.reset(seed=0)
    for action in [3.7, "13", True, None]:
        with pytest.raises(taction.TactionError, match="action"):
            env.unwrapped.step(action)
    env.unwrapped.step(np.int64(0))
    env.unwrapped.step(np.array(1))
    with pytest.raises(taction.TactionError, match="objekt"):
        env.reset(seed=0, options={"objekt": "rook"})
    with pytest.raises(taction.TactionError, match="object"):
        env.reset(seed=0, options={"object": True})


def test_the_model_must_know_every_object_of_the_set(chess):
    pawn = chess[0]
    training = taction.collect([pawn], readings=12, seed=1)
    pawn_only = taction.train(training, descriptor="mnti", codebook="knn")
    with pytest.raises(taction.TactionError, match="not trained on"):
        gymnasium.make(ENV, objects="chess", model=pawn_only)
    with pytest.raises(taction.TactionError, match="empty"):
        gymnasium.make(ENV, objects=[], model=pawn_only)
    with pytest.raises(taction.TactionError, match="more than once"):
        gymnasium.make(ENV, objects=[pawn, pawn], model=pawn_only)
    with pytest.raises(taction.TactionError, match="model"):
        gymnasium.make(ENV, objects=[pawn], model=42)
    env = gymnasium.make(ENV, objects=[pawn], model=pawn_only)
    assert env.unwrapped.objects == ["pawn"]


def test_the_default_recogniser_is_the_demos_calibrated_on_the_arm(chess):
    from taction.env import default_model

    model = default_model(chess, training_readings=110, seed=3)
    training = taction.collect(chess, mode="sampler", readings=110, seed=3, reachable_by_arm=True)
    calibration = taction.collect_arm_calibration(chess, training_readings=110, seed=3)
    demos = taction.train_for_arm(training.converged(), seed=3, calibration=calibration, objects=chess)
    assert model.contacts
    assert model.calibration == demos.calibration
    assert model.calibration != taction.train_for_arm(training.converged(), seed=3).calibration


V1 = "taction/ActiveTouch-v1"
STATUSES = {"converged", "no_contact", "saturated", "max_iterations", "collision", "unreachable", "aborted"}


def test_v1_passes_check_env_and_says_how_every_touch_ended(small_model):
    assert V1 in gymnasium.registry
    env = gymnasium.make(V1, objects="chess", model=small_model)
    assert env.unwrapped.budget == 30
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=True)
    obs, _ = env.reset(seed=7)
    assert "contact" in obs and not obs["contact"].any()
    converged, attempts = 0, 0
    for step in range(12):
        obs, reward, terminated, truncated, info = env.step(step % env.unwrapped.k)
        assert env.observation_space.contains(obs)
        assert info["reading"] in STATUSES, info
        assert info["converged"] == (info["reading"] == "converged")
        # One reading attempt every touch, and another (three at most) after one that met the
        # object and failed.
        assert info["attempts"] - attempts in (1, 2, 3), info
        attempts = info["attempts"]
        converged += info["converged"]
        if info["converged"]:
            # Where the touch met the surface, and its outward normal.
            assert abs(np.linalg.norm(obs["contact"][3:]) - 1.0) < 1e-5
            assert obs["image"].max() > 0
    # Planner iterations (v0) converge on about one in ten; guarded touches on most.
    assert converged >= 9, converged
    env.close()


def test_v1_starts_every_episode_at_a_pose_its_seed_draws(small_model):
    env = gymnasium.make(V1, objects="chess", model=small_model, budget=3)
    traces = [trace(env, seed, [0, 1, 2]) for seed in (5, 5, 6)]
    assert same(traces[0], traces[1])
    assert not same(traces[0], traces[2])
    env.close()
    with pytest.raises(taction.TactionError, match="touch: 'poke' is none of guarded, iteration"):
        taction.TouchEpisode(small_model, taction.objects("chess")[0], touch="poke")


def test_v1_takes_a_free_object_and_refuses_to_push_a_mocap_one(small_model, chess):
    pushed = dict(perturb_deg=10.0, perturb_frac=0.1, perturb_by="push")
    env = gymnasium.make(V1, objects="chess", model=small_model, budget=2, free_object=True, **pushed)
    env.reset(seed=5)
    for action in (0, 1):
        _, _, terminated, truncated, info = env.step(action)
    assert truncated and not terminated
    pose = info["object_pose"]
    assert pose.shape == (7,) and abs(np.linalg.norm(pose[3:]) - 1.0) < 1e-9
    env.close()
    env = gymnasium.make(V1, objects="chess", model=small_model, budget=2, **pushed)
    with pytest.raises(taction.TactionError, match="perturbation.*mocap"):
        env.reset(seed=5)
    env.close()
    with pytest.raises(taction.TactionError, match="object_density"):
        taction.TouchEpisode(small_model, chess[0], object_density=500.0)
