"""Three baseline policies on ``taction/ActiveTouch-v1`` (or ``-v0``), the README's "Python" table.

- ``random``: touch toward a candidate drawn uniformly;
- ``planner L=1``: the paper's planner with only local expansions (the environment's planner at
  ``local_probability=1``, its first candidate every time: the proposal its own rule made);
- ``information gain``: the candidate with the largest expected information gain
  (``env.unwrapped.gains()``, the scorer of ``taction demo --strategy active``), at L = 0.5.

Every policy declares its best guess once the belief reaches ``--declare-at`` (else the episode
runs to the budget, and the final best guess is scored). One core: the environment steps in this
process only. Writes one CSV row per episode and prints the table, with the converged readings per
touch action (v1's guarded touches land on most; v0's planner iterations on few).

    taskset -c 1 .venv/bin/python examples/python/active_touch_baselines.py --objects shapes --episodes 144

With ``--by-budget``, every episode runs to ``--budget`` without declaring, the belief after each
touch recorded, and the table is given for every budget from 1 to ``--budget``: an episode at
budget ``b`` is the longer one cut short (the environment's draws do not depend on the budget),
declaring at the first touch before ``b`` whose belief reaches ``--declare-at``.

    taskset -c 1 .venv/bin/python examples/python/active_touch_baselines.py --objects shapes --episodes 144 \
        --budget 16 --by-budget
"""

import argparse
import csv
import pathlib
import sys
import time

import gymnasium
import numpy as np

import taction
from taction.env import default_model


def touch_of(env, policy, rng):
    """The candidate ``policy`` touches next."""
    if policy == "random":
        return int(rng.integers(env.unwrapped.k))
    if policy == "information gain":
        return int(np.argmax(env.unwrapped.gains()))
    return 0


def run_episode(env, policy, seed, declare_at, rng):
    obs, info = env.reset(seed=seed)
    k = env.unwrapped.k
    steps = 0
    while True:
        belief = obs["belief"]
        if belief.max() >= declare_at:
            action = k + int(np.argmax(belief))
        else:
            action = touch_of(env, policy, rng)
        obs, reward, terminated, truncated, info = env.step(action)
        steps += 1
        if terminated or truncated:
            break
    declared = info.get("declared")
    guess = declared or env.unwrapped.objects[int(np.argmax(obs["belief"]))]
    return {
        "object": info["object"],
        "declared": declared or "",
        "guess": guess,
        "right": int(guess == info["object"]),
        "touches": int(obs["touches"]),
        "readings": info["readings"],
        "steps": steps,
    }


def run_trace(env, policy, seed, rng):
    """One episode to the budget without declaring: (guess, its belief) after each touch action."""
    env.reset(seed=seed)
    trace = []
    while True:
        obs, reward, terminated, truncated, info = env.step(touch_of(env, policy, rng))
        belief = obs["belief"]
        trace.append((env.unwrapped.objects[int(np.argmax(belief))], float(belief.max())))
        if terminated or truncated:
            return info["object"], trace


def at_budget(truth, trace, budget, declare_at):
    """The episode cut at ``budget`` touches: (right, declared, touches to the declaration)."""
    for t, (guess, p) in enumerate(trace[: budget - 1], start=1):
        if p >= declare_at:
            return guess == truth, True, t
    guess = trace[min(budget, len(trace)) - 1][0]
    return guess == truth, False, None


def by_budget(args, model, settings):
    """``--by-budget``: every budget from 1 to ``--budget`` from one run per episode."""
    rows = []
    rates = {}
    for policy, local_probability in settings.items():
        env = gymnasium.make(f"taction/ActiveTouch-{args.env}", objects=args.objects, model=model,
                             budget=args.budget, local_probability=local_probability)
        rng = np.random.default_rng(7)
        start = time.perf_counter()
        traces = [run_trace(env, policy, seed, rng) for seed in range(args.episodes)]
        rates[policy] = sum(len(t) for _, t in traces) / (time.perf_counter() - start)
        env.close()
        for budget in range(1, args.budget + 1):
            ends = [at_budget(truth, trace, budget, args.declare_at) for truth, trace in traces]
            declared = [e for e in ends if e[1]]
            rows.append({
                "policy": policy, "budget": budget, "episodes": len(ends),
                "accuracy": np.mean([e[0] for e in ends]),
                "declared": len(declared) / len(ends),
                "right_when_declared": np.mean([e[0] for e in declared]) if declared else float("nan"),
                "touches_to_declaration": np.mean([e[2] for e in declared]) if declared else float("nan"),
            })
    with args.out.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    policies = list(settings)
    print(f"taction/ActiveTouch-{args.env}, objects: {args.objects} ({len(model.objects)}), {args.episodes} episodes "
          f"per policy, declare at {args.declare_at}, model {model.descriptor} k={model.k}; accuracy at the budget "
          f"(right when declared, declared)")
    print("| budget | " + " | ".join(policies) + " |")
    print("|---|" + "---|" * len(policies))
    for budget in range(1, args.budget + 1):
        cells = []
        for policy in policies:
            r = next(r for r in rows if r["policy"] == policy and r["budget"] == budget)
            cells.append(f"{r['accuracy']:.2f} ({r['right_when_declared']:.2f}, {r['declared']:.2f})")
        print(f"| {budget} | " + " | ".join(cells) + " |")
    print("steps/s (one core): " + ", ".join(f"{p} {rates[p]:.1f}" for p in policies))
    print(f"budgets written to {args.out}", file=sys.stderr)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="chess", help="set name (default chess)")
    parser.add_argument("--episodes", type=int, default=12, help="episodes per policy")
    parser.add_argument("--env", choices=["v1", "v0"], default="v1", help="taction/ActiveTouch-<env>")
    parser.add_argument("--budget", type=int, default=None,
                        help="touches per episode at most (default: the environment's, v1 30, v0 100)")
    parser.add_argument("--declare-at", type=float, default=0.95, help="belief that declares")
    parser.add_argument("--training-readings", type=int, default=1000)
    parser.add_argument("--by-budget", action="store_true",
                        help="report every budget from 1 to --budget from one run per episode")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("baselines.csv"))
    args = parser.parse_args(argv)
    if args.budget is None:
        args.budget = 30 if args.env == "v1" else 100
    if args.episodes < 1 or args.budget < 1 or not 0 < args.declare_at <= 1:
        parser.error("--episodes and --budget must be 1 or more, --declare-at in (0, 1]")

    model = default_model(args.objects, args.training_readings, seed=1)
    settings = {"planner L=1": 1.0, "random": 0.5, "information gain": 0.5}
    if args.by_budget:
        by_budget(args, model, settings)
        return
    rows = []
    table = []
    for policy, local_probability in settings.items():
        env = gymnasium.make(
            f"taction/ActiveTouch-{args.env}",
            objects=args.objects,
            model=model,
            budget=args.budget,
            local_probability=local_probability,
        )
        rng = np.random.default_rng(7)
        start = time.perf_counter()
        results = [
            run_episode(env, policy, seed, args.declare_at, rng) for seed in range(args.episodes)
        ]
        seconds = time.perf_counter() - start
        steps = sum(r["steps"] for r in results)
        declared = [r for r in results if r["declared"]]
        table.append(
            (
                policy,
                len(results),
                np.mean([r["right"] for r in results]),
                len(declared) / len(results),
                np.mean([r["right"] for r in declared]) if declared else float("nan"),
                np.mean([r["touches"] for r in declared]) if declared else float("nan"),
                sum(r["readings"] for r in results) / max(1, sum(r["touches"] for r in results)),
                steps / seconds,
            )
        )
        rows += [{"policy": policy, "episode": i, **r} for i, r in enumerate(results)]
        env.close()

    with args.out.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"taction/ActiveTouch-{args.env}, objects: {args.objects} ({len(model.objects)}), budget {args.budget} touches, "
          f"declare at {args.declare_at}, model {model.descriptor} k={model.k}")
    print(
        "| policy | episodes | accuracy at the budget | declared | right when declared "
        "| mean touches to a declaration | readings per touch | steps/s (one core) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for policy, n, accuracy, declared, right, touches, per_touch, rate in table:
        print(f"| {policy} | {n} | {accuracy:.2f} | {declared:.2f} | {right:.2f} | {touches:.1f} "
              f"| {per_touch:.2f} | {rate:.1f} |")
    print(f"episodes written to {args.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
