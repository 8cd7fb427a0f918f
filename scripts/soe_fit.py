#!/usr/bin/env python3
"""Minimax-optimised exponential sum for the half-derivative kernel t^{-1/2}/sqrt(pi).

Prints the table `OPTIMISED` of src/history/soe_kernel.rs: K rates and weights approximating
1/sqrt(pi t) on [1, RATIO] (a kernel for [delta, horizon] is this one with rates / delta and
weights / sqrt(delta), since the kernel is a power law). Variable projection: for given
log-rates the weights are the weighted least-squares solution; the log-rates are fitted by
Levenberg-Marquardt; Lawson's reweighting drives the weighted least squares towards the
minimax (equi-oscillating) fit. The library re-measures the table's error at run time and
uses it only when it meets the requested tolerance with fewer modes than its own construction.

    pip install numpy scipy && python3 scripts/soe_fit.py 16      # about a minute
"""
import sys

import numpy as np
from scipy.optimize import least_squares

RATIO = 3600.0 / 1e-4  # the default horizon / min_dt
T = np.logspace(0, np.log10(RATIO), int(128 * np.log10(RATIO)) + 1)
EXACT = 1 / np.sqrt(np.pi * T)


def design(x):
    return np.exp(-np.outer(T, np.exp(x))) / EXACT[:, None]


def weights(x, lw):
    a = design(x)
    w, *_ = np.linalg.lstsq(a * lw[:, None], lw, rcond=None)
    return w, a


def resid(x, lw):
    w, a = weights(x, lw)
    return lw * (a @ w - 1)


def fit(k, iters=200):
    x = np.linspace(np.log(0.3 / RATIO), np.log(3.0), k)
    lw = np.ones_like(T)
    best = None
    for _ in range(iters):
        x = least_squares(resid, x, args=(lw,), method="lm", max_nfev=400).x
        w, a = weights(x, lw)
        e = np.abs(a @ w - 1)
        if best is None or e.max() < best[0]:
            best = (e.max(), x.copy(), w.copy())
        lw = lw * np.sqrt(e / e.max()) + 1e-12
        lw /= lw.mean()
    return best


def main():
    k = int(sys.argv[1]) if len(sys.argv) > 1 else 16
    _, x, w = fit(k)
    dense = np.logspace(0, np.log10(RATIO), int(512 * np.log10(RATIO)) + 1)
    err = np.abs(np.exp(-np.outer(dense, np.exp(x))) @ w * np.sqrt(np.pi * dense) - 1).max()
    assert (w > 0).all(), "a weight is not positive"
    print(f"// {k} modes, max relative error {err:.4e} on [1, {RATIO:.6g}] (512 points per decade)")
    for i in np.argsort(x):
        # Shortest decimal that reads back as the same f64.
        print(f"    ({float(np.exp(x[i]))!r}, {float(w[i])!r}),")


if __name__ == "__main__":
    main()
