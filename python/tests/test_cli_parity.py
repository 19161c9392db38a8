"""Python and `softtled run` give bitwise-identical trajectories.

The CLI writes its CSV (`run --csv`); examples/python/torus_drop.py writes the same columns
from the module, stepping as the CLI does (the same step counts per row, the same chunks,
the same watchdog checks). Every value is printed with 9 significant digits, so the files
are compared byte for byte; and in-process, the module's state at every output time is
compared with a second run in full double precision (repeatability), both on the CPU backend.
"""
import os
import sys

import numpy as np
import pytest

import softtled
from conftest import EXAMPLES, run_cli, run_example, scene

sys.path.insert(0, EXAMPLES)
import torus_drop  # noqa: E402  (the example: csv_header, csv_row, rows)

SHORT = ["time.duration=0.03", "time.output_every=0.001"]
CASES = {
    # the paper's drop itself (torus_drop.toml, 1729-point torus), its first 5 ms
    "paper_drop": ("torus_drop.toml", ["time.duration=0.005", "time.output_every=0.0004"]),
    # the paper's drop on the coarse torus: floor contact from ~0.02 s
    "torus_double": ("torus_coarse.toml", SHORT),
    "torus_float": ("torus_coarse.toml", SHORT + ["solver.precision=float"]),
    # a changing step: advance_to output times
    "torus_adaptive": ("torus_coarse.toml", SHORT + ['time.dt="adaptive"']),
    # fixed nodes and a tracked tip; static friction on a slope
    "beam": ("beam_cantilever.toml", ["time.duration=0.02", "time.output_every=0.002"]),
    "slope_static": ("torus_slope_static.toml", ["body.segments=[45,9]", "time.duration=0.03"]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_example_csv_equals_cli_csv(exe, tmp_path, case):
    name, sets = CASES[case]
    set_args = [a for s in sets for a in ("--set", s)]
    cli_csv, py_csv = tmp_path / "cli.csv", tmp_path / "py.csv"
    run_cli(exe, "run", "--scene", scene(name), "--backend", "cpu", "--csv", str(cli_csv), *set_args)
    rc, _, err = run_example("torus_drop.py", "--scene", scene(name), "--backend", "cpu", "--csv", str(py_csv),
                             *set_args)
    assert rc == 0, err
    cli, py = cli_csv.read_text(), py_csv.read_text()
    assert len(cli.splitlines()) > 10
    if cli != py:  # name the first differing row
        for i, (a, b) in enumerate(zip(cli.splitlines(), py.splitlines())):
            assert a == b, f"row {i} differs:\n  cli {a}\n  py  {b}"
    assert cli == py


def test_a_run_the_watchdog_stops_writes_the_same_csv(exe, tmp_path):
    """Stopped by the watchdog (a forced step of 1.3 x dt_cr), both exit 4 and end on the
    rolled-back state, written only when it is not the last row already (the example wrote
    it again)."""
    sets = ["time.allow_unstable=true", "time.dt=4e-4", "time.duration=0.05"]
    set_args = [a for s in sets for a in ("--set", s)]
    cli_csv, py_csv = tmp_path / "cli.csv", tmp_path / "py.csv"
    rc_cli, _, _ = run_cli(exe, "run", "--scene", scene("torus_coarse.toml"), "--backend", "cpu", "--csv", str(cli_csv),
                           *set_args, check=False)
    rc_py, _, err = run_example("torus_drop.py", "--scene", scene("torus_coarse.toml"), "--backend", "cpu", "--csv",
                                str(py_csv), *set_args)
    assert rc_cli == 4 and rc_py == 4, err
    assert len(cli_csv.read_text().splitlines()) > 3
    assert py_csv.read_text() == cli_csv.read_text()


def test_rows_in_process_repeat_bit_for_bit():
    sets = SHORT + ["time.duration=0.01"]
    states = []
    for _ in range(2):
        sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=sets)
        run = []
        for d, diverged in torus_drop.rows(sim):
            assert diverged is None
            run.append(sim.displacements().copy())
        states.append(run)
    assert len(states[0]) == 11
    for a, b in zip(*states):
        assert np.array_equal(a, b)  # every double, not only the 9 printed digits


def test_example_header_matches_cli(exe, tmp_path):
    out = tmp_path / "cli.csv"
    run_cli(exe, "run", "--scene", scene("torus_coarse.toml"), "--backend", "cpu", "--csv", str(out),
            "--set", "time.duration=0.001")
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=["time.duration=0.001"])
    assert torus_drop.csv_header(sim) == out.read_text().splitlines(keepends=True)[0]
