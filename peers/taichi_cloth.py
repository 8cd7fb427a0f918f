"""A peer, side by side in one run: the paper's damped mass-spring cloth in Taichi against
fraccloth's `FC_PRESET_REGULAR_VISCOUS` (the same model) through the C ABI.

The model (paper, section 4; `src/topology/grid.rs`): a W x H grid at spacing s hanging in the
x-y plane, its top row pinned; the Choi & Ko springs, stretch (1, 0), (0, 1) at 10 N/m, shear
(1, +-1) at 2 N/m, bend (2, 0), (0, 2), (2, +-2) at 0.5 N/m, each
`f_i = -(k (|l| - r) + c (v_i - v_j) . l_hat) l_hat` with c = 0.015 N s/m; viscous drag
`-0.001 v`; gravity less buoyancy (cloth 1100 kg/m^3 in water); the cloth's mass (1 kg/m^2 over its cells) spread equally; explicit Euler
at a fixed step. The Taichi kernel is the usual form for a grid: one thread a particle gathering
its twelve neighbours (no atomics), double precision, both states kept so a step is one kernel.

`--check` steps both for 0.2 s from a swung start and prints the largest difference of the
positions (the two must be the same model: the figure is round-off, not physics); it fails
above 1e-12 m (CI runs it: `.ci/peer`). Without it,
it times both: steps a second and particle-steps a second, best of `--rounds`, after a warm-up
(Taichi's compile is not timed), each in the same process, alternately.

    python peers/taichi_cloth.py --size 201x201 --threads 2
    python peers/taichi_cloth.py --size 61x41 --check

Needs `pip install taichi numpy` and the fraccloth Python package (or FRACCLOTH_LIBRARY).
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bindings" / "python"))
import fraccloth  # noqa: E402

OFFSETS = (
    [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)]
    + [(1, 1, 1), (-1, -1, 1), (1, -1, 1), (-1, 1, 1)]
    + [(2, 0, 2), (-2, 0, 2), (0, 2, 2), (0, -2, 2), (2, 2, 2), (-2, -2, 2), (2, -2, 2), (-2, 2, 2)]
)


def fraccloth_cloth(w, h, threads, preset="REGULAR_VISCOUS"):
    d = fraccloth.preset_desc(getattr(fraccloth, "PRESET_" + preset))
    d.width, d.height = w, h
    cloth = fraccloth.Cloth.grid(d)
    cloth.set_pinned(range(w))
    cloth.threads = threads
    return cloth, d


def taichi_cloth(ti, d, x0, v0, w, h):
    """The Taichi cloth of description `d` starting at positions `x0`, velocities `v0`."""
    s = float(d.spacing)
    n = w * h
    mass = d.areal_density * (w - 1) * (h - 1) * s * s / n
    stiffness = (d.stretch_stiffness, d.shear_stiffness, d.bend_stiffness)
    c, drag = d.spring_damping, d.viscous_drag
    # Gravity less the water's buoyancy: the net weight in water, `(1 - rho_w / rho_c) g`.
    net = 1.0 - d.water_density / d.cloth_density
    g = ti.Vector([net * gk for gk in d.gravity], dt=ti.f64)
    states = [(ti.Vector.field(3, ti.f64, shape=(h, w)), ti.Vector.field(3, ti.f64, shape=(h, w))) for _ in range(2)]
    states[0][0].from_numpy(x0.reshape(h, w, 3))
    states[0][1].from_numpy(v0.reshape(h, w, 3))
    # Per neighbour, compile-time constants: offset, stiffness and rest length.
    springs = [(o[0], o[1], stiffness[o[2]], s * float(np.hypot(o[0], o[1]))) for o in OFFSETS]

    @ti.kernel
    def step(x: ti.template(), v: ti.template(), xn: ti.template(), vn: ti.template(), dt: ti.f64):
        for j, i in x:
            if j == 0:
                xn[j, i] = x[j, i]
                vn[j, i] = v[j, i]
            else:
                f = mass * g - drag * v[j, i]
                for q in ti.static(range(len(springs))):
                    di, dj, kq, rq = ti.static(springs[q])
                    jj = j + dj
                    ii = i + di
                    if 0 <= jj < h and 0 <= ii < w:
                        l = x[j, i] - x[jj, ii]
                        length = l.norm()
                        u = l / length
                        f -= (kq * (length - rq) + c * (v[j, i] - v[jj, ii]).dot(u)) * u
                xn[j, i] = x[j, i] + dt * v[j, i]
                vn[j, i] = v[j, i] + dt * f / mass

    class Cloth:
        def __init__(self):
            self.cur = 0

        def run(self, dt, steps):
            for _ in range(steps):
                a, b = states[self.cur], states[1 - self.cur]
                step(a[0], a[1], b[0], b[1], dt)
                self.cur = 1 - self.cur
            ti.sync()

        def positions(self):
            return states[self.cur][0].to_numpy().reshape(n, 3)

    return Cloth()


def swung_start(cloth, w):
    """A start that moves: the grid at rest, every free vertex given a velocity along z that
    grows down the cloth (as a swing would) and a ripple along x, so every spring and the
    damping act."""
    x = cloth.positions_f64()
    v = np.zeros_like(x)
    v[w:, 2] = 0.5 * (-x[w:, 1])  # 0.5 m/s per metre down
    v[w:, 0] = 0.1 * np.sin(40.0 * x[w:, 0])
    cloth.velocities = v
    return x, v


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--size", default="201x201")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--dt", type=float, default=5e-4)
    p.add_argument("--steps", type=int, default=400, help="steps a timed round")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--check", action="store_true")
    p.add_argument(
        "--preset",
        default="REGULAR_VISCOUS",
        help="fraccloth's side only: REGULAR_VISCOUS (the same model as the Taichi kernel), or "
        "FRACTIONAL_PAPER (the library's default, with the SOE history) to time the library's "
        "default against the simpler peer (a fixed step of --dt either way)",
    )
    a = p.parse_args()
    w, h = (int(t) for t in a.size.split("x"))
    import taichi as ti

    ti.init(arch=ti.cpu, default_fp=ti.f64, cpu_max_num_threads=a.threads, log_level=ti.WARN)
    if a.check and a.preset != "REGULAR_VISCOUS":
        sys.exit("--check compares the same model: leave --preset at REGULAR_VISCOUS")
    cloth, d = fraccloth_cloth(w, h, a.threads, a.preset)
    if a.preset != "REGULAR_VISCOUS":
        d = fraccloth_cloth(2, 2, 1)[1]  # the peer's model stays the same
        d.width, d.height = w, h
    x0, v0 = swung_start(cloth, w)
    v0 = cloth.velocities_f64()  # as the library holds them
    peer = taichi_cloth(ti, d, x0, v0, w, h)
    if a.check:
        steps = int(round(0.2 / a.dt))
        cloth.step_substeps(steps * a.dt, steps)
        peer.run(a.dt, steps)
        diff = np.abs(cloth.positions_f64() - peer.positions()).max()
        moved = np.abs(cloth.positions_f64() - x0).max()
        print(f"{w}x{h}, {steps} steps of {a.dt} s: largest position difference {diff:.3e} m (largest displacement {moved:.3e} m)")
        if not diff < 1e-12:
            sys.exit("not the same model: the positions differ by more than round-off")
        return
    peer.run(a.dt, 5)  # compile
    cloth.step_substeps(5 * a.dt, 5)
    best = {"fraccloth": float("inf"), "taichi": float("inf")}
    for _ in range(a.rounds):
        t0 = time.perf_counter()
        cloth.step_substeps(a.steps * a.dt, a.steps)
        best["fraccloth"] = min(best["fraccloth"], time.perf_counter() - t0)
        t0 = time.perf_counter()
        peer.run(a.dt, a.steps)
        best["taichi"] = min(best["taichi"], time.perf_counter() - t0)
    n = w * h
    rate = {k: a.steps * n / t for k, t in best.items()}
    print(
        f"{w}x{h}, {a.threads} thread(s), fraccloth {a.preset}, {a.steps} steps a round, best of {a.rounds}: "
        f"fraccloth {rate['fraccloth'] / 1e6:.1f}M particle-steps/s ({1e9 / rate['fraccloth']:.1f} ns), "
        f"taichi {rate['taichi'] / 1e6:.1f}M ({1e9 / rate['taichi']:.1f} ns), ratio {rate['fraccloth'] / rate['taichi']:.2f}x"
    )


if __name__ == "__main__":
    main()
