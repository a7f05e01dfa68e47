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

Every figure of ``--by-budget`` comes with its 90% interval (Wilson's), and every policy's accuracy
beside the random policy's on the same episodes (the same object at the same pose) as a paired
difference with its 90% interval: at 144 episodes one episode is 0.7 points, and two policies'
accuracies differ by a few episodes by chance alone. ``--balanced`` gives every object the same
number of episodes (episode ``i`` explores object ``i`` modulo the set) and ``--first-seed`` moves
the episodes' seeds, so a claim can be checked on seeds it was not developed on; the per-object
accuracies go to ``<out>_per_object.csv``.

``--policies`` may add ``oracle``, a bound and never a policy: before every touch it copies the
episode once per candidate (``copy.copy`` replays its touches), touches each copy, and touches the
candidate whose copy gives the true object the largest probability. It shows what choosing among
the planner's K candidates could buy a recogniser that knew which touch would help; it costs K
replays of the episode so far per touch.

    taskset -c 1 .venv/bin/python examples/python/active_touch_baselines.py --objects shapes --episodes 144 \
        --budget 10 --by-budget --balanced --first-seed 7000 --policies gain,oracle
"""

import argparse
import copy
import csv
import math
import pathlib
import sys
import time

import gymnasium
import numpy as np

import taction
from taction.env import default_model


#: The policies by ``--policies`` name: the table's name and the candidates' local probability L.
POLICIES = {
    "planner": ("planner L=1", 1.0),
    "random": ("random", 0.5),
    "gain": ("information gain", 0.5),
    "oracle": ("oracle (a bound)", 0.5),
}

#: Two-sided 90% normal quantile.
Z90 = 1.6448536269514722


def touch_of(env, policy, rng):
    """The candidate ``policy`` touches next."""
    if policy == "random":
        return int(rng.integers(env.unwrapped.k))
    if policy == "information gain":
        return int(np.argmax(env.unwrapped.gains()))
    if policy == "oracle (a bound)":
        return oracle_touch(env.unwrapped)
    return 0


def oracle_touch(env):
    """The candidate whose touch leaves the true object most probable, found by touching a copy of
    the episode toward every candidate: it reads the truth, so it is a bound, never a policy."""
    episode = env.episode
    truth = episode.object_index
    chances = []
    for index in range(env.k):
        trial = copy.copy(episode)
        trial.touch(index % len(trial.candidates))
        chances.append(trial.probabilities[truth])
    return int(np.argmax(chances))


def wilson(right, n, z=Z90):
    """Wilson's interval for ``right`` successes of ``n``: (low, high)."""
    if n == 0:
        return float("nan"), float("nan")
    p = right / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


def paired_difference(rights, baseline, z=Z90):
    """The mean of ``rights - baseline`` (two 0/1 lists over the same episodes) and its normal
    interval: (mean, low, high)."""
    d = np.asarray(rights, dtype=float) - np.asarray(baseline, dtype=float)
    if len(d) < 2:
        return float(d.mean()), float("nan"), float("nan")
    half = z * d.std(ddof=1) / math.sqrt(len(d))
    return float(d.mean()), float(d.mean() - half), float(d.mean() + half)


def episode_seeds(args):
    """Each episode's seed and the object it explores (``None``: drawn from the seed)."""
    return [(args.first_seed + i, i if args.balanced else None) for i in range(args.episodes)]


def reset(env, seed, episode):
    options = None if episode is None else {"object": episode % len(env.unwrapped.objects)}
    return env.reset(seed=seed, options=options)


def run_episode(env, policy, seed, episode, declare_at, rng):
    obs, info = reset(env, seed, episode)
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


def run_trace(env, policy, seed, episode, rng):
    """One episode to the budget without declaring: (guess, its belief) after each touch action."""
    reset(env, seed, episode)
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


def by_budget(args, model, settings, seeds):
    """``--by-budget``: every budget from 1 to ``--budget`` from one run per episode of ``seeds``."""
    rows = []
    rates = {}
    traces_of = {}  # per policy, every episode's (truth, trace)
    for policy, local_probability in settings.items():
        env = gymnasium.make(f"taction/ActiveTouch-{args.env}", objects=args.objects, model=model,
                             budget=args.budget, local_probability=local_probability)
        rng = np.random.default_rng(7)
        start = time.perf_counter()
        traces_of[policy] = [run_trace(env, policy, seed, episode, rng) for seed, episode in seeds]
        rates[policy] = sum(len(t) for _, t in traces_of[policy]) / (time.perf_counter() - start)
        env.close()

    def ends_at(policy, budget):
        return [at_budget(truth, trace, budget, args.declare_at) for truth, trace in traces_of[policy]]

    baseline = "random" if "random" in settings else None
    for policy in settings:
        for budget in range(1, args.budget + 1):
            ends = ends_at(policy, budget)
            rights = [int(e[0]) for e in ends]
            declared = [e for e in ends if e[1]]
            low, high = wilson(sum(rights), len(rights))
            if baseline is None:
                diff = (float("nan"),) * 3
            else:
                diff = paired_difference(rights, [int(e[0]) for e in ends_at(baseline, budget)])
            rows.append({
                "policy": policy, "budget": budget, "episodes": len(ends),
                "first_seed": args.first_seed, "balanced": int(args.balanced),
                "accuracy": np.mean(rights), "accuracy_low": low, "accuracy_high": high,
                "declared": len(declared) / len(ends),
                "right_when_declared": np.mean([e[0] for e in declared]) if declared else float("nan"),
                "touches_to_declaration": np.mean([e[2] for e in declared]) if declared else float("nan"),
                "minus_random": diff[0], "minus_random_low": diff[1], "minus_random_high": diff[2],
            })
    write_csv(args.out, rows)
    per_object = []
    for policy in settings:
        truths = [truth for truth, _ in traces_of[policy]]
        for budget in sorted({min(b, args.budget) for b in (6, 10, args.budget)}):
            ends = ends_at(policy, budget)
            for name in sorted(set(truths)):
                mine = [int(e[0]) for e, t in zip(ends, truths) if t == name]
                per_object.append({"policy": policy, "budget": budget, "object": name,
                                   "episodes": len(mine), "right": sum(mine)})
    per_object_path = args.out.with_name(args.out.stem + "_per_object.csv")
    write_csv(per_object_path, per_object)
    policies = list(settings)
    print(f"taction/ActiveTouch-{args.env}, objects: {args.objects} ({len(model.objects)}), {args.episodes} episodes "
          f"per policy (seeds {args.first_seed}-{args.first_seed + args.episodes - 1}"
          f"{', objects in turn' if args.balanced else ''}), declare at {args.declare_at}, model "
          f"{model.descriptor} k={model.k}; accuracy at the budget [90% interval] (right when declared, "
          f"declared){'; minus random, paired [90% interval]' if baseline else ''}")
    print("| budget | " + " | ".join(policies) + " |")
    print("|---|" + "---|" * len(policies))
    for budget in range(1, args.budget + 1):
        cells = []
        for policy in policies:
            r = next(r for r in rows if r["policy"] == policy and r["budget"] == budget)
            cell = (f"{r['accuracy']:.3f} [{r['accuracy_low']:.3f}, {r['accuracy_high']:.3f}] "
                    f"({r['right_when_declared']:.2f}, {r['declared']:.2f})")
            if baseline and policy != baseline:
                cell += (f"; {r['minus_random']:+.3f} [{r['minus_random_low']:+.3f}, "
                         f"{r['minus_random_high']:+.3f}]")
            cells.append(cell)
        print(f"| {budget} | " + " | ".join(cells) + " |")
    print("steps/s (one core): " + ", ".join(f"{p} {rates[p]:.1f}" for p in policies))
    for policy in policies:
        at = max(r["budget"] for r in per_object if r["policy"] == policy)
        print(f"per object at {at}, {policy}: " + ", ".join(
            f"{r['object']} {r['right']}/{r['episodes']}" for r in per_object
            if r["policy"] == policy and r["budget"] == at))
    print(f"budgets written to {args.out}, per object to {per_object_path}", file=sys.stderr)


def write_csv(path, rows):
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


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
    parser.add_argument("--policies", default="planner,random,gain",
                        help=f"comma-separated, of {', '.join(POLICIES)} (default planner,random,gain)")
    parser.add_argument("--first-seed", type=int, default=0, help="the first episode's seed (default 0)")
    parser.add_argument("--balanced", action="store_true",
                        help="episode i explores object i modulo the set, not one its seed draws")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("baselines.csv"))
    args = parser.parse_args(argv)
    if args.budget is None:
        args.budget = 30 if args.env == "v1" else 100
    if args.episodes < 1 or args.budget < 1 or not 0 < args.declare_at <= 1:
        parser.error("--episodes and --budget must be 1 or more, --declare-at in (0, 1]")
    names = [n.strip() for n in args.policies.split(",") if n.strip()]
    unknown = [n for n in names if n not in POLICIES]
    if unknown or not names or len(set(names)) != len(names):
        parser.error(f"--policies: {args.policies!r} is not a list of distinct names of {', '.join(POLICIES)}")
    if args.first_seed < 0:
        parser.error(f"--first-seed: {args.first_seed} is negative")

    model = default_model(args.objects, args.training_readings, seed=1)
    settings = dict(POLICIES[n] for n in names)
    seeds = episode_seeds(args)
    if args.by_budget:
        by_budget(args, model, settings, seeds)
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
            run_episode(env, policy, seed, episode, args.declare_at, rng) for seed, episode in seeds
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
        rows += [{"policy": policy, "episode": i, "seed": seed, **r}
                 for i, ((seed, _), r) in enumerate(zip(seeds, results))]
        env.close()

    write_csv(args.out, rows)
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
