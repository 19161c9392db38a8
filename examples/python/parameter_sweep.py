#!/usr/bin/env python3
"""Sweep E and the Coulomb friction coefficient mu of a ring rolling down a slope, and plot
how much it rolls rather than slides.

    python3 examples/python/parameter_sweep.py --out sweep.png [--duration 0.15]

The scene is a dict (the coarse torus of assets/scenes/torus_coarse.toml on a 20 degree
slope with Coulomb friction), meshed once; each (E, mu) is a set_params() followed by
reset(), which drops the ring again from the start with the new parameters (and the dt
they give). The rolling measure: the ring's rotation about its axis theta (the
mass-weighted best-fit rotation of the nodes about the centroid, in the x-y plane) times
its outer radius R, over the distance s its centroid travelled along the slope:
R theta / s = 1 for rolling without slip, 0 for pure sliding.
Needs PYTHONPATH=<build>/python and matplotlib.
"""
import argparse
import math
import sys

import numpy as np

import softtled

SLOPE_DEG = 20.0
R_OUTER = 10e-3  # m: major radius 7.5 mm + tube 2.5 mm

SCENE = {
    "units": "mm",
    "body": {"shape": "torus", "major_radius": 7.5, "tube_radius": 2.5, "segments": [45, 9]},
    "mesh": {"radius_edge": 2.0},
    "material": {"E": 3000.0, "nu": 0.49, "rho": 1000.0},
    "damping": {"alpha": 10.0},
    "floor": {"enabled": False},
    # the lowest point 1 mm above the slope: (10 + 1) mm / cos(20 deg) below the centre
    "slope": {"enabled": True, "angle_deg": SLOPE_DEG, "point": [0, -11.0 / math.cos(math.radians(SLOPE_DEG)), 0]},
    "contact": {"mode": "coulomb", "mu": 0.5},
    "time": {"dt": "auto", "lambda": 0.5},
}


def rotation_about_z(X, x, m):
    """Mass-weighted best-fit rotation angle (x-y plane) taking rest offsets X to x."""
    X = X[:, :2] - np.average(X[:, :2], axis=0, weights=m)
    x = x[:, :2] - np.average(x[:, :2], axis=0, weights=m)
    cross = np.sum(m * (X[:, 0] * x[:, 1] - X[:, 1] * x[:, 0]))
    dot = np.sum(m * (X[:, 0] * x[:, 0] + X[:, 1] * x[:, 1]))
    return math.atan2(cross, dot)


def run(sim, E, mu, duration, every):
    sim.set_params(E=E, mu=mu)
    sim.reset()  # from the start, with the new dt
    X, m = sim.rest_positions(), sim.lumped_mass()
    c0 = np.array(sim.diagnostics()["centroid"])
    params = sim.params()
    n, g = np.array(params["planes"][-1]["normal"]), np.array(params["g"])
    down = g - np.dot(g, n) * n  # gravity along the slope
    down /= np.linalg.norm(down)
    t, s, roll = [], [], []
    theta, last = 0.0, 0.0
    while sim.time < duration - 0.5 * sim.dt:
        sim.advance(every)
        a = rotation_about_z(X, sim.positions(), m)
        theta += math.remainder(a - last, 2 * math.pi)  # unwrapped (less than half a turn per sample)
        last = a
        travel = float(np.dot(np.array(sim.diagnostics()["centroid"]) - c0, down))
        t.append(sim.time)
        s.append(travel)
        roll.append(abs(theta) * R_OUTER / travel if travel > 1e-4 else float("nan"))
    return np.array(t), np.array(s), np.array(roll)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="parameter_sweep.png")
    ap.add_argument("--duration", type=float, default=0.15, help="simulated seconds per run")
    ap.add_argument("--E", type=float, nargs="+", default=[1500.0, 3000.0, 6000.0])
    ap.add_argument("--mu", type=float, nargs="+", default=[0.1, 0.3, 1.0])
    ap.add_argument("--backend", default="auto")
    a = ap.parse_args(argv)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sim = softtled.Simulation(SCENE, backend=a.backend)
    print(sim, file=sys.stderr)
    fig, (ax_s, ax_r) = plt.subplots(1, 2, figsize=(11, 4.2))
    styles = ["-", "--", ":", "-."]
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, E in enumerate(a.E):
        for j, mu in enumerate(a.mu):
            t, s, roll = run(sim, E, mu, a.duration, every=0.002)
            label = f"E = {E:g} Pa, mu = {mu:g}"
            kw = dict(color=colors[j % len(colors)], linestyle=styles[i % len(styles)], label=label)
            ax_s.plot(t, s * 1e3, **kw)
            ax_r.plot(t, roll, **kw)
            print(f"{label}: travelled {s[-1] * 1e3:.2f} mm, R theta / s = {roll[-1]:.3f}", file=sys.stderr)
    ax_s.set(xlabel="t [s]", ylabel="centroid travel along the slope [mm]", title=f"{SLOPE_DEG:g} deg slope, Coulomb")
    ax_r.set(xlabel="t [s]", ylabel="R theta / s  (1: rolls, 0: slides)", ylim=(-0.05, 1.25), title="rolling measure")
    ax_s.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
