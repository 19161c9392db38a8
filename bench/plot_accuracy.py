#!/usr/bin/python3
"""Pareto plot and markdown table of `softtled accuracy` output.

usage: bench/plot_accuracy.py DIR   (reads DIR/accuracy.csv, writes DIR/accuracy_pareto.png
                                      and DIR/accuracy.md)
Cost axis: wall time to simulate 0.2 s = us_per_step * 0.2 / dt (the backend that ran it).
Error axis: mean nodal displacement error against the reference at the later snapshot.
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

d = sys.argv[1] if len(sys.argv) > 1 else "bench/accuracy"
rows = [r for r in csv.DictReader(open(f"{d}/accuracy.csv")) if r["dt_us"] not in ("", "diverged")]
ref = rows[0]
for r in rows:
    r["dt_mode"] = r.get("dt_mode") or "auto"  # older tables: fixed steps only
    r["wall_02"] = float(r["us_per_step"]) * 1e-6 * 0.2 / (float(r["dt_us"]) * 1e-6)
    r["err"] = float(r["mean_err_mm_t2"])

curves = defaultdict(list)
for r in rows[2:]:
    curves[(r["level"], r["element"], r["precision"], r["dt_mode"])].append(r)

fig, axes = plt.subplots(1, 2, figsize=(14, 5.5))
markers = {"T4": "o", "T4ANP": "s"}  # adaptive step: a star, same colour
t4ref = rows[1]
for ax, col, when in ((axes[0], "mean_err_mm_t1", "t1 = 0.05 s (first compression)"),
                      (axes[1], "mean_err_mm_t2", "t2 = 0.1 s")):
    combos = sorted({(k[0], k[1]) for k in curves})
    colour = {c: plt.cm.tab10(i % 10) for i, c in enumerate(combos)}  # one colour per mesh x element
    for (level, element, prec, mode), rs in sorted(curves.items()):
        rs.sort(key=lambda r: r["wall_02"])
        ys = [max(float(r[col]), 1e-4) for r in rs]
        adaptive = mode == "adaptive"
        ax.plot([r["wall_02"] for r in rs], ys, marker="*" if adaptive else markers.get(element, "o"),
                markersize=11 if adaptive else 6, color=colour[(level, element)],
                linestyle="none" if adaptive else ("-" if prec == "double" else "--"),
                label=f"{level} {element} {prec}" + (" adaptive Δt" if adaptive else ""))
        for r, y in zip(rs, ys):
            ax.annotate(("adaptive " if adaptive else "") + f"λ={float(r['lambda']):g}", (r["wall_02"], y), fontsize=6,
                        textcoords="offset points", xytext=(3, 3))
    ax.axhline(float(t4ref[col]), color="gray", linestyle=":", label=f"T4 on the reference mesh ({t4ref['level']})")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time to simulate 0.2 s [s] (backend that ran the sweep)")
    ax.set_ylabel("mean nodal displacement error vs reference [mm]")
    ax.set_title(f"error at {when}")
    ax.grid(True, which="both", alpha=0.3)
axes[1].legend(fontsize=7, loc="best")
fig.suptitle(f"Torus drop: accuracy vs cost (reference {ref['level']} {ref['element']} {ref['precision']} λ={ref['lambda']})")
fig.tight_layout()
fig.savefig(f"{d}/accuracy_pareto.png", dpi=120)

with open(f"{d}/accuracy.md", "w") as f:
    f.write("| mesh | tets | element | precision | λ | Δt [µs] (adaptive: mean) | µs/step | wall to 0.2 s [s] | centroid RMS [mm] | "
            "max err t1 [mm] | mean err t1 [mm] | max err t2 [mm] | mean err t2 [mm] | rest height err [mm] |\n")
    f.write("|" + "---|" * 14 + "\n")
    for i, r in enumerate(rows):
        tag = " (reference)" if i == 0 else (" (T4 on ref. mesh)" if i == 1 else "")
        lam = ("adaptive " if r["dt_mode"] == "adaptive" else "") + f"{float(r['lambda']):g}"
        f.write(f"| {r['level']}{tag} | {r['ntet']} | {r['element']} | {r['precision']} | {lam} | "
                f"{float(r['dt_us']):.3g} | {float(r['us_per_step']):.3g} | {r['wall_02']:.3g} | "
                f"{float(r['centroid_rms_mm']):.3g} | {float(r['max_err_mm_t1']):.3g} | {float(r['mean_err_mm_t1']):.3g} | "
                f"{float(r['max_err_mm_t2']):.3g} | {float(r['mean_err_mm_t2']):.3g} | {float(r['rest_height_err_mm']):.3g} |\n")
print(f"wrote {d}/accuracy_pareto.png and {d}/accuracy.md")
