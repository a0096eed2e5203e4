"""The study's statistics against the paper's published figures and against arithmetic
done here from the definitions (not read back from aou's own output)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy import stats as sps

from aou_dsl.study.stats import dominant, goodness_of_fit, holm, multinomial_p, wilson

N = 55  # the paper's participants


def chi2_of(counts) -> float:
    e = sum(counts) / len(counts)
    return sum((c - e) ** 2 / e for c in counts)


def top_residual(counts) -> float:
    e = sum(counts) / len(counts)
    return (max(counts) - e) / math.sqrt(e)


def tables(n: int, k: int, chi2: float, r: float, tol: float = 0.005):
    """Every table of ``k`` counts summing to ``n`` whose chi-squared and largest Pearson
    residual round to the published two-decimal figures: the dominant count follows from
    the residual, the rest are enumerated."""
    e = n / k
    top = round(e + r * math.sqrt(e))
    found = []
    for rest in itertools.product(range(top + 1), repeat=k - 2):
        last = n - top - sum(rest)
        if 0 <= last <= top:
            t = (top, *rest, last)
            if abs(chi2_of(t) - chi2) <= tol and abs(top_residual(t) - r) <= tol:
                found.append(t)
    return found


def test_the_paper_confident_pause_pair_exactly():
    """Part B's confident pause-duration pair: 46, 4, 4 and 1 of 55 give chi2 = 101.29
    and a residual of 8.70, the paper's two-decimal figures."""
    fit = goodness_of_fit([46, 4, 4, 1])
    assert f"{fit.chi2:.2f}" == "101.29" and f"{fit.residuals[0]:.2f}" == "8.70"
    assert fit.df == 3 and fit.p < 0.001 and dominant(fit) == 0


# (published chi2, published dominant residual): Part B (four options) and Part A (six).
# Not every published pair rebuilds at n = 55 (fearful PDur's chi2 56.06 with r = 6.27
# has no table: the reported residual and chi2 cannot both be of one table of 55); the
# ones listed each have at least one.
PART_B = {"confident AAcc": (120.64, 9.51), "curious GAH": (53.29, 6.00),
          "hesitant RD": (79.18, 7.62), "hesitant RC": (157.15, 10.85),
          "hesitant AAcc": (58.67, 6.27), "hesitant TA": (34.09, 4.65),
          "fearful RC": (95.04, 8.43),
          "fearful PC": (37.29, 4.92), "fearful SA": (29.44, 4.38)}
PART_A = {"A confident": (191.44, 12.50), "B curious": (60.75, 6.55),
          "C hesitant": (94.78, 8.20), "D fearful": (118.35, 9.52)}


@pytest.mark.parametrize(("k", "name", "published"),
                         [(4, n, v) for n, v in PART_B.items()]
                         + [(6, n, v) for n, v in PART_A.items()])
def test_tables_rebuilt_from_the_paper_give_its_figures(k, name, published):
    """A count table of 55 answers rebuilt from a published chi2 and residual (searched
    here by plain arithmetic) gives the same figures through aou's test, within 0.01,
    with df = options - 1 and p < .001 as the paper reports."""
    chi2, r = published
    found = tables(N, k, chi2, r)
    assert found, f"no table of {N} answers has chi2 {chi2} and residual {r}"
    for t in found:
        fit = goodness_of_fit(t)
        assert abs(fit.chi2 - chi2) <= 0.01 and abs(max(fit.residuals) - r) <= 0.01
        assert fit.df == k - 1 and fit.p < 0.001
        assert fit.p == pytest.approx(sps.chisquare(t).pvalue, rel=1e-9)


def test_part_a_effect_sizes_are_the_papers_range():
    """Cohen's w of the rebuilt Part A tables spans the paper's 1.05-1.87."""
    ws = [goodness_of_fit(tables(N, 6, *v)[0]).cohen_w for v in PART_A.values()]
    assert f"{min(ws):.2f}" == "1.05" and f"{max(ws):.2f}" == "1.87"


def test_adjusted_residuals_and_wilson_from_their_formulas():
    counts = [30, 12, 8, 5]
    fit = goodness_of_fit(counts)
    n, k = 55, 4
    for c, adj in zip(counts, fit.adjusted, strict=True):
        assert adj == pytest.approx((c - n / k) / math.sqrt(n / k * (1 - 1 / k)))
    c, z = 30, sps.norm.ppf(0.975)
    p = c / n
    mid = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    assert wilson(c, n) == pytest.approx((mid - half, mid + half))


def test_holm_from_its_definition():
    ps = [0.01, 0.04, 0.03, 0.2, 0.001]
    order = np.argsort(ps)
    mine, running = [0.0] * len(ps), 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (len(ps) - rank) * ps[i]))
        mine[i] = running
    assert holm(ps) == pytest.approx(mine)


def test_exact_multinomial_against_enumeration_and_monte_carlo():
    """Small counts: the exact p sums the probabilities of every table no more likely
    than the one seen (computed here with math.comb); a large table takes the Monte Carlo
    path and lands within its error of the exact value."""
    counts = [4, 1, 0, 0]
    n, k = 5, 4

    def prob(t):
        return math.factorial(n) / math.prod(math.factorial(c) for c in t) / k ** n

    tables_ = [t for t in itertools.product(range(n + 1), repeat=k) if sum(t) == n]
    exact = sum(prob(t) for t in tables_ if prob(t) <= prob(counts) * (1 + 1e-9))
    p, how = multinomial_p(counts)
    assert how == "exact" and p == pytest.approx(exact)
    fit = goodness_of_fit(counts)
    assert fit.exact_p == pytest.approx(exact) and fit.p_used == fit.exact_p
    big = [9, 3, 2, 1, 1, 0, 0, 2, 1, 1, 0, 0]  # 20 answers over 12 options
    p_mc, how = multinomial_p(big, seed=3)
    assert how == "monte carlo" and 0 <= p_mc <= 1
    assert multinomial_p(big, seed=3) == (p_mc, how)  # seeded: the same every run


def test_a_uniform_policy_is_significant_at_about_alpha():
    """Answers drawn evenly: the goodness-of-fit test rejects at 0.05 about 5 % of the
    time (a binomial 99.9 % band over 2,000 studies of 55)."""
    rng = np.random.default_rng(7)
    rejected = sum(goodness_of_fit(rng.multinomial(55, [0.25] * 4)).p < 0.05
                   for _ in range(2000))
    lo, hi = sps.binom.ppf([0.0005, 0.9995], 2000, 0.05)
    assert lo <= rejected <= hi
