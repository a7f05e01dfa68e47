"""What a ``taction/ActiveTouch-v1`` step costs beside the episode's own touch, and at touch 30
against touch 1.

Side by side in one process: a ``TouchEpisode`` of the same object (the library's guarded touch and
the belief it keeps) and the environment's step (Python, observation and belief on top), the same
random candidate index for both, ``--episodes`` episodes of 30 touches on the 12 shapes; then the
environment's ``gains()`` after every step. The model: MNTI and SIFT over the neighbour codebook on
100 sampler readings per object.

    .venv/bin/python examples/python/step_cost.py --episodes 24
"""

import argparse
import time

import gymnasium
import numpy as np

import taction

BUDGET = 30


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=24)
    args = parser.parse_args(argv)
    if args.episodes < 1:
        parser.error("--episodes must be 1 or more")
    objects = taction.objects("shapes")
    training = taction.collect(objects, mode="sampler", readings=100, seed=1, reachable_by_arm=True)
    model = taction.train(training, descriptor="mnti+sift", codebook="knn")
    env = gymnasium.make("taction/ActiveTouch-v1", objects=objects, model=model, budget=BUDGET)
    rng = np.random.default_rng(3)
    shape = (args.episodes, BUDGET)
    touch, step, gains = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    for e in range(args.episodes):
        env.reset(seed=e)
        names = env.unwrapped.objects
        truth = env.unwrapped._episode.object
        twin = taction.TouchEpisode(model, env.unwrapped._episode_objects[names.index(truth)], seed=e,
                                    workspace=env.unwrapped._episode_objects, start_pose="random")
        for t in range(BUDGET):
            a = int(rng.integers(env.unwrapped.k))
            start = time.perf_counter()
            twin.touch(a % len(twin.candidates))
            touch[e, t] = time.perf_counter() - start
            start = time.perf_counter()
            env.step(a)
            step[e, t] = time.perf_counter() - start
            start = time.perf_counter()
            env.unwrapped.gains()
            gains[e, t] = time.perf_counter() - start
    env.close()
    ms = 1000.0
    print(f"{args.episodes} episodes x {BUDGET} touches, the 12 shapes, random candidates")
    print(f"the episode's touch {touch.mean() * ms:.2f} ms, the environment's step {step.mean() * ms:.2f} ms"
          f" ({step.mean() / touch.mean():.3f}x), gains() {gains.mean() * ms:.3f} ms")
    first, last = step[:, :5].mean(), step[:, -5:].mean()
    print(f"a step at touches 1-5 {first * ms:.2f} ms, at 26-30 {last * ms:.2f} ms ({last / first:.3f}x);"
          f" gains() {gains[:, :5].mean() * ms:.3f} -> {gains[:, -5:].mean() * ms:.3f} ms")


if __name__ == "__main__":
    main()
