#!/usr/bin/env python3
"""Prints the Pareto-front tables of docs/benchmarks.md from docs/speed_accuracy.csv.

    python3 scripts/pareto_tables.py [docs/speed_accuracy.csv]

A configuration is on the front when no completed configuration is both cheaper (wall seconds
per simulated second) and at least as accurate. Standard library only.
"""
import csv
import sys


def fmt_dt(dt):
    return f"{dt:g}" if dt < 0.04 else f"{dt:.2g}"


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "docs/speed_accuracy.csv"
    rows = list(csv.DictReader(open(path)))
    problems = []
    for r in rows:
        if r["problem"] not in problems:
            problems.append(r["problem"])
    for p in problems:
        done = [r for r in rows if r["problem"] == p and r["completed"] == "true"]
        done.sort(key=lambda r: (float(r["wall_s_per_simulated_s"]), float(r["error_m"])))
        front, best = [], float("inf")
        for r in done:
            e = float(r["error_m"])
            if e < best:
                front.append(r)
                best = e
        print(f"**{p}**\n")
        print("| scheme | integrator | dt (s) | error (m) | s per simulated s | M particle-steps/s | history bytes/particle |")
        print("|---|---|---|---|---|---|---|")
        for r in front:
            print(
                f"| {r['scheme']} | {r['integrator']} | {fmt_dt(float(r['dt']))} | {float(r['error_m']):.2e} | "
                f"{float(r['wall_s_per_simulated_s']):.3g} | {float(r['particle_steps_per_s']) / 1e6:.2f} | "
                f"{r['history_bytes_per_particle']} |"
            )
        paper = [r for r in rows if r["problem"] == p and r["scheme"] == "paper u=3" and r["integrator"] == "explicit"]
        paper.sort(key=lambda r: float(r["dt"]))
        parts = []
        for r in paper:
            dt = fmt_dt(float(r["dt"]))
            if r["completed"] == "true":
                parts.append(
                    f"dt {dt} s: error {float(r['error_m']):.2e} m at "
                    f"{float(r['wall_s_per_simulated_s']):.3g} s per simulated s"
                )
            else:
                parts.append(f"dt {dt} s: unstable")
        print(f"\nThe paper's configuration (u = 3, explicit Euler) on {p}: " + "; ".join(parts) + ".\n")


if __name__ == "__main__":
    main()
