"""The environment's baseline script (examples/python/active_touch_baselines.py): its statistics
against known answers, and its oracle bound's premise, that a copy of an episode tries a touch
without moving the episode itself."""

import copy
import importlib.util
import math

import gymnasium
import numpy as np
import pytest

from conftest import ROOT

SCRIPT = ROOT / "examples" / "python" / "active_touch_baselines.py"


@pytest.fixture(scope="module")
def baselines():
    spec = importlib.util.spec_from_file_location("active_touch_baselines", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_wilsons_interval_has_its_known_values(baselines):
    z = baselines.Z90
    low, high = baselines.wilson(10, 20)
    half = z * math.sqrt(0.25 / 20 + z * z / 1600) / (1 + z * z / 20)
    assert low == pytest.approx(0.5 - half) and high == pytest.approx(0.5 + half)
    # All right: the interval still reaches below 1, and by less with more episodes.
    low144, high144 = baselines.wilson(144, 144)
    assert high144 == pytest.approx(1.0) and 0.97 < low144 < 1.0
    assert baselines.wilson(12, 12)[0] < low144
    assert baselines.wilson(0, 30)[0] == pytest.approx(0.0, abs=1e-12)


def test_the_paired_difference_counts_episodes_where_the_policies_differ(baselines):
    # Two episodes won, one lost, seven the same: +0.1, and an interval around it.
    mine = [1, 1, 0, 1, 1, 1, 0, 0, 1, 1]
    theirs = [0, 0, 1, 1, 1, 1, 0, 0, 1, 1]
    mean, low, high = baselines.paired_difference(mine, theirs)
    d = np.array(mine) - np.array(theirs)
    half = baselines.Z90 * d.std(ddof=1) / math.sqrt(10)
    assert mean == pytest.approx(0.1) and low == pytest.approx(0.1 - half) and high == pytest.approx(0.1 + half)
    assert baselines.paired_difference(mine, mine) == (0.0, 0.0, 0.0)


def test_an_episode_cut_at_a_budget_declares_at_the_first_sure_touch_before_it(baselines):
    trace = [("rook", 0.6), ("pawn", 0.96), ("rook", 0.97), ("rook", 0.99)]
    # Declared after touch 2 (the wrong guess) whenever the budget leaves a touch after it.
    assert baselines.at_budget("rook", trace, 3, 0.95) == (False, True, 2)
    assert baselines.at_budget("rook", trace, 4, 0.95) == (False, True, 2)
    # At a budget of 2 the sure touch is the last: its guess is scored, undeclared.
    assert baselines.at_budget("rook", trace, 2, 0.95) == (False, False, None)
    assert baselines.at_budget("rook", trace, 1, 0.95) == (True, False, None)
    assert baselines.at_budget("rook", trace, 4, 0.999) == (True, False, None)


def test_the_oracle_touches_the_candidate_that_leaves_the_truth_most_probable(baselines, small_model):
    env = gymnasium.make("taction/ActiveTouch-v1", objects="chess", model=small_model, budget=4, candidates=4)
    env.reset(seed=3)
    env.step(1)
    episode = env.unwrapped.episode
    before = episode.probabilities.copy()
    truth = episode.object_index
    chosen = baselines.oracle_touch(env.unwrapped)
    # Trying every candidate on copies left the episode as it was.
    assert env.unwrapped.episode is episode
    assert before.tobytes() == episode.probabilities.tobytes()
    # Each candidate's outcome, found on copies of another kind (pickled and replayed in full).
    outcomes = []
    for index in range(env.unwrapped.k):
        trial = copy.deepcopy(episode)
        trial.touch(index % len(trial.candidates))
        outcomes.append(trial.probabilities[truth])
    assert chosen == int(np.argmax(outcomes))
    _, _, _, _, info = env.step(chosen)
    assert env.unwrapped.episode.probabilities[truth] == max(outcomes)
    env.close()
