#!/usr/bin/env python3
"""How far a ratio of two 10-run medians can be trusted.

Reads two files of one ATE per line (uniform BA's runs, then Salient BA's), as
scripts/salient_ba_ablation.sh writes them, and prints each arm's median and range, the ratio of
the medians, and a percentile bootstrap interval for that ratio: both arms are resampled with
replacement, each on its own, and the ratio of the resampled medians is collected. It also gives
the share of resamples in which the ratio meets a target (at most 1 unless --target says
otherwise; issue 7 asks 0.5 of the dynamic cases). With 10 runs an arm, the interval shows
how far a second set of the same code could land: `room`'s sets of the last two builds have
spanned 1.006x-1.128x (docs/RESULTS.md, "Session 24").

With --permutation it also asks whether the two arms differ at all: a two-sided permutation test
(the runs of both arms pooled, shuffled and split again at the arms' sizes) of the difference of
their medians and of their means. Its p-value counts the observed split among the shuffles,
(extreme + 1) / (shuffles + 1), so it is never 0. It is meant as well for two Salient BA arms
(two maps, two models) given in place of uniform and Salient BA, named with --labels: a median
ratio of 0.59 against 0.50 can be one draw of the same distribution.

    python3 python/ablation_stats.py WORK/room.none WORK/room.salient [--target T] [--resamples N] [--seed S]
        [--permutation] [--labels FIRST SECOND]
"""

import argparse
import random
import statistics
import sys


def read_values(path):
    try:
        with open(path, encoding="utf-8") as f:
            lines = [line.strip() for line in f]
    except OSError as e:
        sys.exit(f"ablation_stats: {path}: {e.strerror}")
    values = []
    for number, line in enumerate(lines, 1):
        if not line:
            continue
        try:
            value = float(line)
        except ValueError:
            sys.exit(f"ablation_stats: {path}:{number}: not a number: '{line}'")
        if not value > 0.0 or value == float("inf"):
            sys.exit(f"ablation_stats: {path}:{number}: an ATE must be positive and finite, got {line}")
        values.append(value)
    if not values:
        sys.exit(f"ablation_stats: {path}: no values")
    return values


def bootstrap_ratio(uniform, salient, resamples, seed, target=1.0, level=0.90):
    """(low, high, share of resampled ratios <= target) of median(salient) / median(uniform)."""
    rng = random.Random(seed)
    ratios = []
    for _ in range(resamples):
        u = statistics.median(rng.choices(uniform, k=len(uniform)))
        s = statistics.median(rng.choices(salient, k=len(salient)))
        ratios.append(s / u)
    ratios.sort()
    tail = (1.0 - level) / 2.0
    low = ratios[int(tail * (resamples - 1))]
    high = ratios[int((1.0 - tail) * (resamples - 1))]
    meeting = sum(r <= target for r in ratios) / resamples
    return low, high, meeting


def permutation_test(first, second, shuffles, seed):
    """Two-sided p-values of second's median and mean differing from first's: the share of random
    splits of the pooled runs, the observed one among them, whose difference is at least the
    observed one."""
    rng = random.Random(seed)
    observed = (statistics.median(second) - statistics.median(first),
                statistics.fmean(second) - statistics.fmean(first))
    pooled = list(first) + list(second)
    tolerance = 1e-12 * max(pooled)  # a shuffle that restores the observed split must count
    extreme = [0, 0]
    for _ in range(shuffles):
        rng.shuffle(pooled)
        a, b = pooled[:len(first)], pooled[len(first):]
        shuffled = (statistics.median(b) - statistics.median(a),
                    statistics.fmean(b) - statistics.fmean(a))
        for k in range(2):
            extreme[k] += abs(shuffled[k]) >= abs(observed[k]) - tolerance
    return {"median_difference": observed[0], "median_p": (extreme[0] + 1) / (shuffles + 1),
            "mean_difference": observed[1], "mean_p": (extreme[1] + 1) / (shuffles + 1)}


def p_text(p):
    return f"p {p:.3f}" if p >= 0.001 else "p < 0.001"


def summary(uniform, salient, resamples, seed, target=1.0):
    u, s = statistics.median(uniform), statistics.median(salient)
    low, high, meeting = bootstrap_ratio(uniform, salient, resamples, seed, target)
    return {
        "uniform_median": u,
        "uniform_range": (min(uniform), max(uniform)),
        "salient_median": s,
        "salient_range": (min(salient), max(salient)),
        "ratio": s / u,
        "interval_90": (low, high),
        "share_meeting_target": meeting,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("uniform", help="file of uniform BA's ATEs, one per line")
    parser.add_argument("salient", help="file of Salient BA's ATEs, one per line")
    parser.add_argument("--target", type=float, default=1.0, help="ratio to meet (default 1)")
    parser.add_argument("--resamples", type=int, default=10000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--permutation", action="store_true",
                        help="also test whether the arms differ (as many shuffles as resamples)")
    parser.add_argument("--labels", nargs=2, metavar=("FIRST", "SECOND"),
                        default=("uniform", "salient"),
                        help="the arms' names in the output (default: uniform salient)")
    args = parser.parse_args()
    if args.resamples < 100:
        parser.error("--resamples must be at least 100")
    if not args.target > 0.0:
        parser.error("--target must be positive")
    if any(not label.strip() for label in args.labels):
        parser.error("--labels must not be empty")
    uniform, salient = read_values(args.uniform), read_values(args.salient)
    r = summary(uniform, salient, args.resamples, args.seed, args.target)
    print(
        f"{args.labels[0]} {r['uniform_median']:.6g} ({r['uniform_range'][0]:.4g}-{r['uniform_range'][1]:.4g})  "
        f"{args.labels[1]} {r['salient_median']:.6g} ({r['salient_range'][0]:.4g}-{r['salient_range'][1]:.4g})  "
        f"ratio {r['ratio']:.3f}  90% bootstrap {r['interval_90'][0]:.3f}-{r['interval_90'][1]:.3f}  "
        f"P(ratio <= {args.target:g}) {r['share_meeting_target']:.2f}"
    )
    if args.permutation:
        t = permutation_test(uniform, salient, args.resamples, args.seed)
        print(f"permutation test: medians differ by {t['median_difference']:+.4g} ({p_text(t['median_p'])}), "
              f"means by {t['mean_difference']:+.4g} ({p_text(t['mean_p'])})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
