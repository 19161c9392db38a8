#!/usr/bin/env python3
"""The CSV of `softtled run`, from Python: the same columns, rows and digits.

    python3 examples/python/torus_drop.py                       # the paper's torus drop, CSV to stdout
    python3 examples/python/torus_drop.py --scene S.toml --set time.duration=0.02 --csv out.csv

It steps the simulation exactly as app/cmd_run.cpp does (the same step counts per output
row, advanced in the same chunks with the watchdog checking after each, or the adaptive
step's output times), so the file equals `softtled run --scene S --csv out.csv` byte for
byte on the same machine and backend (tests/test_cli_parity.py checks it).
Needs PYTHONPATH=<build>/python.
"""
import argparse
import math
import os
import sys

import softtled

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_SCENE = os.path.join(HERE, "..", "..", "assets", "scenes", "torus_drop.toml")


def lround(x):
    """C's lround: halves away from zero (Python's round() rounds them to even)."""
    f = math.floor(abs(x))
    return int(math.copysign(f + 1 if abs(x) - f >= 0.5 else f, x))


def csv_header(sim):
    h = "t,cx,cy,cz,min_gap,ke,se,pe,n_contact,n_stick,max_u"
    if sim.nbody >= 2:
        h += "".join(f",b{b}_cx,b{b}_cy,b{b}_cz" for b in range(sim.nbody))
    h += "".join(f",n{j}_ux,n{j}_uy,n{j}_uz" for j in range(len(sim.tracked_nodes)))
    return h + "\n"


def csv_row(d, t_decimals):
    # printf's %.9g and %.*f: Python's %-formatting rounds the same way (correctly).
    row = "%.*f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%.9g" % (
        t_decimals, d["t"], *d["centroid"], d["min_gap"], d["ke"], d["se"], d["pe"], d["n_contact"], d["n_stick"],
        d["max_u"])
    row += "".join(",%.9g" % v for v in d["body_centroid"])
    row += "".join(",%.9g" % v for v in d["tracked"])
    return row + "\n"


def rows(sim):
    """The diagnostics of every output time, stepping as `softtled run` does.

    Yields (diagnostics, diverged_message): the message is None except for a last row
    after the watchdog stopped the run (then the state is the rolled-back healthy one).
    """
    dt = sim.dt
    total = softtled.step_count(sim.duration, dt)
    out_dt = max(sim.output_every, dt)  # output times at least a step apart
    if sim.adaptive:  # a changing step advances by output times, not step counts
        intervals = max(1, lround(math.ceil(sim.duration / out_dt - 1e-9)))
    else:
        intervals = total

    def interval_end(k):  # where output time k ends: the step nearest k out_dt, or output time k
        if sim.adaptive:
            return min(k, intervals)
        return min(total, max(k, lround(min(k * out_dt / dt, total))))

    yield sim.diagnostics(), None
    done = k = 0
    while done < intervals:
        k += 1
        n = interval_end(k) - done
        try:
            if sim.adaptive:
                sim.advance_to(min(sim.duration, (done + n) * out_dt))
            else:
                sim.step(n)  # chunks of softtled.CHUNK_STEPS, the watchdog after each, as `run`
        except softtled.SimulationDiverged as e:
            yield sim.diagnostics(), str(e)
            return
        done += n
        yield sim.diagnostics(), None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default=DEFAULT_SCENE)
    ap.add_argument("--set", action="append", default=[], help="section.key=value, as softtled run --set")
    ap.add_argument("--backend", default="auto", choices=["auto", "cpu", "cuda"])
    ap.add_argument("--csv", default="-", help="output file ('-': standard output)")
    a = ap.parse_args(argv)
    try:
        sim = softtled.Simulation(a.scene, backend=a.backend, set=a.set)
    except softtled.InputError as e:
        print(f"torus_drop.py: error: {e}", file=sys.stderr)
        return 2
    out = sys.stdout if a.csv == "-" else open(a.csv, "w")
    try:
        t_dec = softtled.time_decimals(sim.dt)
        out.write(csv_header(sim))
        last_t = None  # the time column of the last row written
        for d, diverged in rows(sim):
            row = csv_row(d, t_dec)
            t = row.split(",", 1)[0]
            if t != last_t:  # as `run`: the rolled-back state is no new row when it is the last one
                out.write(row)
                last_t = t
            if diverged:
                print(f"torus_drop.py: {diverged}", file=sys.stderr)
                return 4
    finally:
        if out is not sys.stdout:
            out.close()
    print(f"{sim!r}: final centroid ({', '.join('%.6g' % (c * 1e3) for c in d['centroid'])}) mm", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
