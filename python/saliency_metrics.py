"""Saliency metrics with the standard definitions of the MIT saliency benchmark (Bylinskii et al.,
"What do different evaluation metrics tell us about saliency models?", TPAMI 2019).

pred and gt are non-negative float maps of one size; fixations is a boolean map.
"""

import numpy as np

EPS = np.finfo(np.float64).eps


def _standardise(m):
    m = m.astype(np.float64)
    s = m.std()
    return (m - m.mean()) / s if s > 0 else m - m.mean()


def cc(pred, gt):
    """Pearson's linear correlation coefficient between the two maps."""
    a, b = _standardise(pred), _standardise(gt)
    return float((a * b).mean())


def kld(pred, gt):
    """KL divergence of the prediction from the ground truth, both normalised to sum to 1."""
    p = pred.astype(np.float64)
    q = gt.astype(np.float64)
    p = p / max(p.sum(), EPS)
    q = q / max(q.sum(), EPS)
    return float((q * np.log(EPS + q / (p + EPS))).sum())


def nss(pred, fixations):
    """Mean of the standardised prediction at the fixated pixels."""
    if not fixations.any():
        return float("nan")
    return float(_standardise(pred)[fixations].mean())


def auc_judd(pred, fixations, rng=None):
    """AUC-Judd: thresholds at the prediction's values at fixations; true positives are fixations
    above the threshold, false positives the other pixels above it. A tiny seeded jitter breaks
    ties, as in the reference code."""
    if not fixations.any():
        return float("nan")
    s = pred.astype(np.float64).ravel()
    if rng is not None:
        s = s + rng.random(s.size) * 1e-7
    rng_span = s.max() - s.min()
    s = (s - s.min()) / rng_span if rng_span > 0 else np.zeros_like(s)
    f = fixations.ravel()
    thresholds = np.sort(s[f])[::-1]
    n_fix, n_pix = thresholds.size, s.size
    sorted_all = np.sort(s)
    above = n_pix - np.searchsorted(sorted_all, thresholds, side="left")  # count of s >= t
    tp = np.concatenate([[0.0], np.arange(1, n_fix + 1) / n_fix, [1.0]])
    fp = np.concatenate([[0.0], (above - np.arange(1, n_fix + 1)) / (n_pix - n_fix), [1.0]])
    return float(np.trapz(tp, fp))
