#!/usr/bin/env python3
"""Reference solutions of the fractional oscillator m x'' + c D^{1/2}x + k x = F (Caputo),
m = 1, c = 0.8, k = 25, at t = 0.1, 0.2, ..., 5 s, to 30 digits (mpmath, fixed Talbot
inversion of the Laplace transform at 60 working digits):

  forced from rest (F = 1 N):      X(s) = F / (s (m s^2 + c s^(1/2) + k))
  free from x0 = 0.1 m, v0 = 0:    X(s) = x0 (m s + c s^(-1/2)) / (m s^2 + c s^(1/2) + k)

Writes tests/data/oscillator_reference.csv (t, forced, free). Run from the repository root:
    python3 scripts/oscillator_reference.py
"""
import mpmath as mp

mp.mp.dps = 60
M, C, K, F, X0 = mp.mpf(1), mp.mpf("0.8"), mp.mpf(25), mp.mpf(1), mp.mpf("0.1")


def forced(s):
    return F / (s * (M * s**2 + C * mp.sqrt(s) + K))


def free(s):
    return X0 * (M * s + C / mp.sqrt(s)) / (M * s**2 + C * mp.sqrt(s) + K)


rows = ["t,forced,free"]
for i in range(1, 51):
    t = mp.mpf(i) / 10
    a = mp.invertlaplace(forced, t, method="talbot")
    b = mp.invertlaplace(free, t, method="talbot")
    rows.append(f"{mp.nstr(t, 3)},{mp.nstr(a, 30)},{mp.nstr(b, 30)}")
with open("tests/data/oscillator_reference.csv", "w") as f:
    f.write("\n".join(rows) + "\n")
