"""The statistics of a perception study: the paper's tests and what a careful analysis adds.

The paper's analysis, for each question's answer counts:
- a chi-squared goodness-of-fit test against answers spread evenly over the options
  (df = options - 1);
- Pearson residuals ``(O - E) / sqrt(E)``, read as significant beyond +-1.96, only the
  positive ones interpreted;
- for Part A, a chi-squared test of independence between the expression shown and the
  state chosen.

Added here:
- adjusted residuals ``(O - E) / sqrt(E (1 - p))``, which are standard normal under the
  null hypothesis where Pearson's are not quite;
- Cohen's w, the effect size, ``sqrt(chi2 / n)``;
- an exact multinomial test where an expected count is under 5 (the chi-squared
  approximation is poor there), by Monte Carlo when exact enumeration is too slow;
- Holm's correction across a family of tests;
- Wilson confidence intervals for the share of each answer;
- the number of participants a given effect needs (power of the goodness-of-fit test).

SciPy and statsmodels are imported here only: ``import aou_dsl`` never loads them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["DOMINANT", "Fit", "Independence", "dominant", "goodness_of_fit", "holm",
           "independence", "multinomial_p", "participants_needed", "wilson"]

#: The residual beyond which an answer counts as chosen more than chance (the paper's).
DOMINANT = 1.96
#: Compositions of n into k parts beyond which the exact test samples instead.
EXACT_LIMIT = 50_000
#: Draws of the Monte Carlo multinomial test (its p is then within about 0.002).
MONTE_CARLO_DRAWS = 100_000


@dataclass(frozen=True)
class Fit:
    """A chi-squared goodness-of-fit test of one question's counts against even answers.

    ``residuals`` are Pearson's, ``adjusted`` the adjusted ones, one per option;
    ``exact_p`` is the multinomial test's p (None when every expected count is 5 or
    more), ``exact_method`` ``"exact"`` or ``"monte carlo"``."""

    counts: tuple[int, ...]
    n: int
    expected: float
    chi2: float
    df: int
    p: float
    residuals: tuple[float, ...]
    adjusted: tuple[float, ...]
    cohen_w: float
    exact_p: float | None
    exact_method: str | None

    @property
    def p_used(self) -> float:
        """The p that decides: the exact one where the approximation is poor."""
        return self.p if self.exact_p is None else self.exact_p


def goodness_of_fit(counts: Sequence[int], *, seed: int = 0) -> Fit:
    """The paper's test of ``counts`` (one per option) against a uniform spread.

    Args:
        counts: how many participants chose each option; at least two options.
        seed: the Monte Carlo test's seed, so a report is the same every run.
    """
    from scipy import stats

    obs = np.asarray(counts, dtype=float)
    k, n = len(obs), int(obs.sum())
    if k < 2 or n <= 0:
        raise ValueError("a goodness-of-fit test needs two options and one answer")
    e = n / k
    chi2 = float(((obs - e) ** 2 / e).sum())
    p = float(stats.chi2.sf(chi2, k - 1))
    resid = (obs - e) / math.sqrt(e)
    adj = (obs - e) / math.sqrt(e * (1 - 1 / k))
    exact = method = None
    if e < 5:
        exact, method = multinomial_p([int(c) for c in counts], seed=seed)
    return Fit(tuple(int(c) for c in counts), n, e, chi2, k - 1, p,
               tuple(float(r) for r in resid), tuple(float(a) for a in adj),
               math.sqrt(chi2 / n), exact, method)


def multinomial_p(counts: Sequence[int], *, seed: int = 0) -> tuple[float, str]:
    """The exact multinomial test against even answers: the probability, under the null
    hypothesis, of counts no more likely than these (Monte Carlo with ``seed`` past
    :data:`EXACT_LIMIT` compositions). Returns ``(p, method)``."""
    from scipy import stats

    n, k = int(sum(counts)), len(counts)
    probs = np.full(k, 1 / k)
    observed = stats.multinomial.logpmf(counts, n, probs)
    if math.comb(n + k - 1, k - 1) <= EXACT_LIMIT:
        table = _all_counts(n, k)
        logp = stats.multinomial.logpmf(table, n, probs)
        keep = logp <= observed + 1e-9
        return float(np.exp(logp[keep]).sum()), "exact"
    rng = np.random.default_rng(seed)
    draws = rng.multinomial(n, probs, size=MONTE_CARLO_DRAWS)
    logp = stats.multinomial.logpmf(draws, n, probs)
    return float((np.count_nonzero(logp <= observed + 1e-9) + 1) / (len(draws) + 1)), \
        "monte carlo"


def _all_counts(n: int, k: int) -> np.ndarray:
    """Every vector of ``k`` non-negative counts summing to ``n``, shape (m, k)."""
    if k == 1:
        return np.array([[n]])
    parts = [np.column_stack([np.full(len(rest), head), rest])
             for head in range(n + 1) for rest in [_all_counts(n - head, k - 1)]]
    return np.concatenate(parts)


def dominant(fit: Fit, threshold: float = DOMINANT) -> int | None:
    """The one option chosen more than chance (its Pearson residual above ``threshold``),
    or None when none is, or when more than one is (the paper's "inconclusive")."""
    above = [i for i, r in enumerate(fit.residuals) if r > threshold]
    return above[0] if len(above) == 1 else None


@dataclass(frozen=True)
class Independence:
    """The chi-squared test of independence of a contingency table (rows: expressions,
    columns: answers); columns no one chose are left out, as the test needs."""

    chi2: float
    df: int
    p: float
    cramer_v: float


def independence(table: Sequence[Sequence[int]]) -> Independence:
    from scipy import stats

    t = np.asarray(table, dtype=float)
    t = t[:, t.sum(axis=0) > 0]
    t = t[t.sum(axis=1) > 0]
    chi2, p, df, _ = stats.chi2_contingency(t, correction=False)
    n = t.sum()
    v = math.sqrt(chi2 / (n * max(1, min(t.shape) - 1))) if n else 0.0
    return Independence(float(chi2), int(df), float(p), v)


def holm(pvalues: Sequence[float]) -> list[float]:
    """Holm's step-down adjustment of a family of p-values (same order back)."""
    if not pvalues:
        return []
    from statsmodels.stats.multitest import multipletests

    return [float(p) for p in multipletests(list(pvalues), method="holm")[1]]


def wilson(count: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """The Wilson interval of a proportion ``count / n`` at confidence ``level``."""
    from statsmodels.stats.proportion import proportion_confint

    lo, hi = proportion_confint(count, n, alpha=1 - level, method="wilson")
    return float(lo), float(hi)


def participants_needed(w: float, options: int, *, alpha: float = 0.05,
                        power: float = 0.8) -> int:
    """How many participants a goodness-of-fit test over ``options`` needs to find an
    effect of size ``w`` (Cohen's w) at ``alpha`` with ``power``."""
    from statsmodels.stats.power import GofChisquarePower

    n = GofChisquarePower().solve_power(effect_size=w, nobs=None, alpha=alpha, power=power,
                                        n_bins=options)
    return int(math.ceil(float(np.atleast_1d(n)[0])))
