"""A soak of ``taction/ActiveTouch-v1`` as an RL user runs it: a vector env of two environments
(``sync`` or ``async``) stepped with random actions, resetting as episodes end, for ``--steps``
environment steps; the process's resident memory (with the async workers') and the wall time of
every block of ``--block`` steps. Prints the memory after warm-up and at the end, and the cost of
the last block against the first, measured and along the least-squares line through every block:
the host's speed wanders by 10-30% over minutes (other tenants: the same soak's blocks took
61.7-71.8 s one morning and 75.4-96.9 s at noon), which moves any one block but not a trend that a
process slowing with age would draw through all of them.

    .venv/bin/python examples/python/soak_vector_env.py --mode sync --steps 100000
"""

import argparse
import os
import pathlib
import sys
import time

import gymnasium
import numpy as np

import taction


def resident_kib(pids) -> int:
    """The summed resident set of `pids` (Linux `/proc`), KiB."""
    total = 0
    for pid in pids:
        status = pathlib.Path(f"/proc/{pid}/status")
        if not status.exists():
            continue
        for line in status.read_text().splitlines():
            if line.startswith("VmRSS:"):
                total += int(line.split()[1])
    return total


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mode", choices=["sync", "async"], default="sync")
    parser.add_argument("--steps", type=int, default=100_000, help="environment steps in all")
    parser.add_argument("--block", type=int, default=10_000, help="steps per timed block")
    parser.add_argument("--objects", default="shapes")
    parser.add_argument("--training-readings", type=int, default=100,
                        help="sampler readings per object of the soak's model")
    args = parser.parse_args(argv)
    if args.steps < 2 * args.block or args.block < 2:
        parser.error("--steps must be at least two blocks, a block at least 2 steps")

    objects = taction.objects(args.objects)
    training = taction.collect(objects, mode="sampler", readings=args.training_readings, seed=1,
                               reachable_by_arm=True)
    model = taction.train(training, descriptor="mnti+sift", codebook="knn")
    envs = gymnasium.make_vec("taction/ActiveTouch-v1", num_envs=2, vectorization_mode=args.mode,
                              objects=objects, model=model)
    pids = [os.getpid()] + [p.pid for p in getattr(envs, "processes", [])]
    rng = np.random.default_rng(11)
    k = 12
    envs.reset(seed=5)
    blocks = []
    memory = []
    steps = 0
    while steps < args.steps:
        start = time.perf_counter()
        for _ in range(args.block // 2):
            # Touches only: declarations would end episodes after a step or two.
            envs.step(rng.integers(k, size=2))
        blocks.append(time.perf_counter() - start)
        steps += 2 * (args.block // 2)
        memory.append(resident_kib(pids))
        print(f"{steps} steps: block {blocks[-1]:.1f} s, resident {memory[-1] / 1024:.1f} MiB",
              file=sys.stderr, flush=True)
    envs.close()
    growth = memory[-1] / memory[0] - 1
    drift = blocks[-1] / blocks[0]
    slope, intercept = np.polyfit(np.arange(len(blocks)), blocks, 1)
    trend = (intercept + slope * (len(blocks) - 1)) / intercept
    print(f"{args.mode}: {steps} steps of 2 environments; resident after the first block "
          f"{memory[0] / 1024:.1f} MiB, at the end {memory[-1] / 1024:.1f} MiB ({100 * growth:+.1f}%); "
          f"last block {blocks[-1]:.1f} s against the first {blocks[0]:.1f} s ({drift:.3f}x), "
          f"along the trend of all {len(blocks)} blocks {trend:.3f}x")


if __name__ == "__main__":
    main()
