# SPDX-License-Identifier: Apache-2.0
"""The tests that judge one arm against its control (tools/arm.py --compare).

Three views of the same seeds, because a learner that finds rolling gaits sooner
shows in all three differently:
- Mann-Whitney U on the seeds' best distances (two-sided): does the arm do better?
- Fisher's exact test on the seeds at >= 28 m (the issue's threshold): do more seeds
  get there?
- the log-rank test on the episode of each seed's first team >= 32 m, a seed that
  never got there censored at the budget: do seeds get there sooner? It uses the
  timing the other two throw away.

Mann-Whitney and Fisher are SciPy's. The log-rank test is written here: SciPy has it
only from 1.11 (`scipy.stats.logrank`) and Debian 12 ships 1.10.
"""
import math


def have_scipy():
    try:
        import scipy.stats  # noqa: F401
        return True
    except ImportError:
        return False


def mann_whitney_p(a, b):
    from scipy.stats import mannwhitneyu
    return float(mannwhitneyu(a, b, alternative="two-sided").pvalue)


def fisher_p(hits_a, n_a, hits_b, n_b):
    from scipy.stats import fisher_exact
    return float(fisher_exact([[hits_a, n_a - hits_a], [hits_b, n_b - hits_b]])[1])


def logrank(times_a, times_b):
    """Two-sample log-rank test. Each list holds a seed's event episode, or None for a
    seed censored at the end of the run. Returns (events in a, expected in a, chi2,
    p); p is 1 when neither group has an event."""
    events = sorted({t for t in times_a + times_b if t is not None})
    observed = expected = variance = 0.0
    for t in events:
        at_risk_a = sum(1 for x in times_a if x is None or x >= t)
        at_risk_b = sum(1 for x in times_b if x is None or x >= t)
        d_a = sum(1 for x in times_a if x == t)
        d = d_a + sum(1 for x in times_b if x == t)
        n = at_risk_a + at_risk_b
        observed += d_a
        expected += d * at_risk_a / n
        if n > 1:
            variance += d * (at_risk_a / n) * (at_risk_b / n) * (n - d) / (n - 1)
    if variance == 0.0:
        return observed, expected, 0.0, 1.0
    chi2 = (observed - expected) ** 2 / variance
    # The chi-square survival function with one degree of freedom, erfc(sqrt(x/2)).
    return observed, expected, chi2, math.erfc(math.sqrt(chi2 / 2.0))


def against_control(arm_at, control_at, near_m):
    """p-values of one arm's budget summary against the control's at the same budget
    (both with their `per_seed` metrics)."""
    a, c = arm_at["per_seed"].values(), control_at["per_seed"].values()
    best_a, best_c = [m["best_m"] for m in a], [m["best_m"] for m in c]
    hits_a, hits_c = sum(b >= near_m for b in best_a), sum(b >= near_m for b in best_c)
    return {"p_mann_whitney": mann_whitney_p(best_a, best_c),
            "p_fisher_28": fisher_p(hits_a, len(best_a), hits_c, len(best_c)),
            "p_logrank_32": logrank([m["first_episode_32m"] for m in a], [m["first_episode_32m"] for m in c])[3]}
