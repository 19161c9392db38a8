"""Errors: the CLI's exit-2 messages become softtled.InputError (a ValueError) with the
same text as the CLI prints after "softtled: error: "."""
import math

import numpy as np
import pytest

import softtled
from conftest import run_cli, scene

CLI_PREFIX = "softtled: error: "


def cli_message(exe, *args):
    rc, _, err = run_cli(exe, "run", *args, check=False)
    assert rc == 2, err
    line = [ln for ln in err.splitlines() if ln.startswith(CLI_PREFIX)]
    assert len(line) == 1, err
    return line[0][len(CLI_PREFIX):]


def py_message(path, sets=()):
    with pytest.raises(softtled.InputError) as e:
        softtled.Simulation(path, backend="cpu", set=list(sets))
    assert isinstance(e.value, ValueError)
    return str(e.value)


@pytest.mark.parametrize("sets", [
    ["material.colour=red"],            # unknown key
    ["banana.E=1"],                     # unknown table
    ["material.E=nan"],                 # NaN parameter
    ["material.nu=0.7"],                # out of range
    ["time.dt=1.0"],                    # fixed dt above dt_cr (refused after meshing)
    ["body.0.velocity=[0,1]"],          # wrong shape
])
def test_bad_override_same_message_as_cli(exe, sets):
    path = scene("torus_coarse.toml")
    args = ["--scene", path, "--backend", "cpu"] + [a for s in sets for a in ("--set", s)]
    assert py_message(path, sets) == cli_message(exe, *args)


def test_missing_file_same_message_as_cli(exe, tmp_path):
    path = str(tmp_path / "no_such_scene.toml")
    msg = py_message(path)
    assert "No such file or directory" in msg
    assert msg == cli_message(exe, "--scene", path, "--backend", "cpu")


def test_bad_toml_in_a_dict_scene_names_the_key():
    with pytest.raises(softtled.InputError, match=r"<dict>: material\.E"):
        softtled.Simulation({"material": {"E": math.nan}}, backend="cpu")


def test_set_params_errors():
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    before = sim.params()
    with pytest.raises(softtled.InputError, match="E = nan"):
        sim.set_params(E=math.nan)
    with pytest.raises(softtled.InputError, match="nu"):
        sim.set_params(nu=0.6)
    with pytest.raises(softtled.InputError, match="contact_mode 'glue'"):
        sim.set_params(contact_mode="glue")
    with pytest.raises(TypeError, match="unexpected keyword argument 'rho'"):
        sim.set_params(rho=1200.0)  # rebuilds the body in the viewer: not a live parameter
    with pytest.raises(TypeError, match="g takes 3 numbers"):
        sim.set_params(g=[0, -9.81])
    with pytest.raises(TypeError, match="takes a number"):
        sim.set_params(E="stiff")
    # a vector's items are numbers, not sequences or bools; bytes are not a str
    with pytest.raises(TypeError, match=r"g: expected a flat sequence of numbers, got an item \[0\]"):
        sim.set_params(g=[[0], [-9.81], [0]])
    with pytest.raises(TypeError, match="g: expected a flat sequence of numbers, got an item True"):
        sim.set_params(g=[0, True, 0])
    with pytest.raises(TypeError, match="contact_mode: got bytes; give a str"):
        sim.set_params(contact_mode=b"static")
    for unordered in ({0.0, -9.81, 1.0}, (x for x in (0.0, -9.81, 0.0))):  # no order to read x, y, z in
        with pytest.raises(TypeError, match="g: "):
            sim.set_params(g=unordered)
    # nothing was applied by a refused call (all values are checked first)
    with pytest.raises(softtled.InputError):
        sim.set_params(mu=0.9, E=-1.0)
    assert sim.params() == before


def test_overrides_must_be_text():
    for bad in ([b"material.E=5000"], [5000], b"material.E=5000"):
        with pytest.raises(TypeError, match="set: "):
            softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=bad)


def test_a_slope_that_cannot_tilt_is_refused_live():
    # z up: the slope turns the floor about z, so no angle would tilt it (README "Scene keys").
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu",
                              set=["gravity.g=[0, 0, -9.81]", "floor.normal=[0, 0, 1]", "body.position=[0, 0, 5]"])
    before = sim.params()
    with pytest.raises(softtled.InputError, match="slope_angle_deg: .*floor.normal is along z"):
        sim.set_params(slope=True, slope_angle_deg=20)
    assert sim.params() == before
    sim.set_params(slope=True, slope_angle_deg=0)  # a flat slope is a second floor: fine


def test_bad_backend_and_scene_type():
    with pytest.raises(ValueError, match="backend 'gpu'"):
        softtled.Simulation(scene("torus_coarse.toml"), backend="gpu")
    with pytest.raises(TypeError):
        softtled.Simulation(42)
    # TOML text as bytes: refused, not parsed as its repr "b'...'" (a TOML error).
    with pytest.raises(TypeError, match="text must be a str, got bytes"):
        softtled.Simulation.from_toml(b'units = "mm"', backend="cpu")


def test_watchdog_stop_raises_simulation_diverged():
    # A fixed step far above dt_cr, insisted on: the watchdog stops it and rolls back.
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu",
                              set=["time.allow_unstable=true", "time.dt=4e-4"])
    with pytest.raises(softtled.SimulationDiverged) as e:
        for _ in range(200):
            sim.step(25)
    assert isinstance(e.value, RuntimeError)
    assert isinstance(e.value.element, int)
    d = sim.diagnostics()
    assert math.isfinite(d["ke"])  # the rolled-back, healthy state


def test_ctrl_c_stops_between_chunks():
    import signal

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    old = signal.signal(signal.SIGALRM, interrupt)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.3)
        with pytest.raises(KeyboardInterrupt):
            sim.step(10**7)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert 0 < sim.steps < 10**7 and sim.steps % softtled.CHUNK_STEPS == 0  # at a chunk's end
    assert sim.diagnostics()["t"] == sim.time


def test_adaptive_advance_answers_ctrl_c_and_refuses_endless_runs():
    """With time.dt = "adaptive" (no step count known in advance) advance and advance_to
    stop on Ctrl-C within kStopCheckSteps steps, and a target beyond the fixed step's limit
    of 1e11 steps (at the step now) is refused, as step() and the fixed-step advance do."""
    import signal

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=["time.dt=adaptive"])
    for call in (lambda: sim.advance(1e12), lambda: sim.advance_to(1e300)):
        with pytest.raises(softtled.InputError, match="above the limit"):
            call()
    assert sim.steps == 0
    old = signal.signal(signal.SIGALRM, interrupt)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.3)
        with pytest.raises(KeyboardInterrupt):
            sim.advance(1000.0)  # some 2.5e7 steps
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert 0 < sim.time < 1000.0 and sim.diagnostics()["t"] == sim.time


def test_step_refuses_a_count_past_the_limit():
    """step(n) takes at most 1e11 steps, as advance and `softtled run`: 2**62 ran on until
    Ctrl-C, and 2**63 - 1 would overflow the step counter."""
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    for n in (2**62, 2**63 - 1):
        with pytest.raises(ValueError, match="above the limit of 1e11 steps"):
            sim.step(n)
    assert sim.steps == 0


def test_an_instance_never_initialised_is_refused_not_crashed():
    """Simulation.__new__ alone gives an object without its C++ state: every method and
    property is refused with a TypeError (it crashed the interpreter)."""
    sim = softtled.Simulation.__new__(softtled.Simulation)
    for name in ("time", "step", "displacements", "diagnostics", "write_vtu"):
        with pytest.raises(TypeError, match="never initialised"):
            getattr(sim, name)
    # ... also reached through the class, past the instance's attribute lookup (a crash)
    cls = softtled._softtled.Simulation
    for call in (lambda: cls.step(sim, 10), lambda: cls.time.__get__(sim), lambda: cls.diagnostics(sim),
                 lambda: cls.positions(sim), lambda: cls.set_params(sim, mu=0.1)):
        with pytest.raises(TypeError, match="never initialised"):
            call()
    with pytest.raises(TypeError, match="Simulation method called on a <class 'int'>"):
        cls.step(5, 10)


def test_set_params_refuses_what_would_be_ignored_and_names_values_as_given():
    """dt_max caps only the adaptive step: on a fixed-step run it is refused (as the scene's
    time.dt_max is), not stored and ignored. Range messages print the value given, not
    %f's rounding (-1e-9 is not -0.000000)."""
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    with pytest.raises(softtled.InputError, match="dt_max applies only with time.dt"):
        sim.set_params(dt_max=1e-9)
    assert sim.params()["dt_max"] == softtled.Simulation(scene("torus_coarse.toml"), backend="cpu").params()["dt_max"]
    with pytest.raises(softtled.InputError, match=r"E = -1e-09: must be finite and in \(0, 1e\+12\]"):
        sim.set_params(E=-1e-9)


def test_live_ranges_and_paths_as_the_scene_file_has_them(tmp_path):
    """The live parameters take the scene file's ranges (beta <= 1 s, E <= 1e12 Pa, ...);
    a path holding a NUL byte is refused (the OS would read another file: the part before
    it); time_decimals takes a positive finite step only."""
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    for kw, text in ((dict(beta=2.0), r"beta = 2: must be finite and in \[0, 1\]"),
                     (dict(E=1e13), r"E = 1e\+13"), (dict(alpha=1e7), "alpha = 10000000"),
                     (dict(mu=1e4), "mu = 10000"), (dict(g=(0, -1e7, 0)), "g: element 1 = -10000000")):
        with pytest.raises(softtled.InputError, match=text):
            sim.set_params(**kw)
    with pytest.raises(softtled.InputError, match="NUL byte"):
        softtled.Simulation(scene("torus_coarse.toml") + "\0junk", backend="cpu")
    with pytest.raises(softtled.InputError, match="NUL byte"):
        sim.write_vtu(str(tmp_path / "n.vtu") + "\0.junk")
    assert not (tmp_path / "n.vtu").exists()
    for dt in (float("nan"), float("inf"), -1e-5, 0.0):
        with pytest.raises(softtled.InputError, match="time_decimals"):
            softtled.time_decimals(dt)


def test_wrong_types_are_type_errors_and_init_runs_once():
    """Values of the wrong type are TypeErrors naming the key (they were RuntimeErrors from
    the binding's cast); a second __init__ is refused (the object kept its old state)."""
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    for kw in (dict(g=("0", "-1", "0")), dict(E=10**400)):
        with pytest.raises(TypeError, match="set_params: " + next(iter(kw))):
            sim.set_params(**kw)
    with pytest.raises(RuntimeError, match="already initialised"):
        sim.__init__(scene("cube_rest.toml"), backend="cpu")
    assert sim.source == scene("torus_coarse.toml")


def test_set_params_nu_has_the_scene_files_range():
    """nu live is refused or taken as in a scene file, (-1, 0.5) (it capped at 0.4999)."""
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    sim.set_params(nu=0.49995)
    assert sim.params()["nu"] == 0.49995
    softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=["material.nu=0.49995"])  # the file agrees
    for nu in (0.5, -1.0):
        with pytest.raises(softtled.InputError, match=r"nu = .*: must be finite and in \(-1, 0\.5\)"):
            sim.set_params(nu=nu)
        with pytest.raises(softtled.InputError, match="material.nu"):
            softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=[f"material.nu={nu}"])


@pytest.mark.parametrize("sets", [[], ["time.dt=adaptive"]])
def test_advance_to_an_earlier_time_is_refused(sets):
    """The simulation only goes forward: advance_to(t) with t behind the current time
    raises, naming t and the time (it returned having done nothing); the current time
    itself is reached already (no step, no error)."""
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=sets)
    sim.advance(0.002)
    now, steps = sim.time, sim.steps
    sim.advance_to(now)
    assert sim.steps == steps
    with pytest.raises(softtled.InputError, match=r"advance_to\(0\.001\): t = 0\.001 s is earlier than the current time 0\.00"):
        sim.advance_to(0.001)
    assert sim.time == now and sim.steps == steps
    sim.advance_to(now + 0.001)  # forward still works
    assert sim.time > now


def test_advance_to_samples_finer_than_the_step():
    """advance_to times closer than a step apart (as `run --set time.output_every` below dt):
    each goes to the step nearest it, one within half a step ahead takes none (it raised
    "shorter than half the time step"), and time never lags t by more than half a step."""
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=["body.segments=[24,8]"])
    dt = sim.dt
    for k in range(1, 40):
        t = k * 0.35 * dt
        sim.advance_to(t)
        assert abs(sim.time - t) <= 0.5 * dt * (1 + 1e-9), (k, sim.time, t)
    assert sim.steps == round(39 * 0.35)


def test_toml_text_has_the_scene_files_size_limit(exe, tmp_path):
    """from_toml (and a dict scene) take at most kMaxSceneBytes (4 MiB), as a scene file,
    refused with the file's message (they took 5 MiB)."""
    text = "# padding\n" * ((4 << 20) // 10) + "[time]\nduration = 0.001\n"
    assert len(text) > 4 << 20
    limit = f": {len(text)} bytes, above the limit of {4 << 20} bytes for input files"
    with pytest.raises(softtled.InputError) as e:
        softtled.Simulation.from_toml(text, backend="cpu")
    assert str(e.value) == "scene <toml>" + limit
    path = tmp_path / "big.toml"
    path.write_text(text)
    assert py_message(str(path)) == cli_message(exe, "--scene", str(path)) == f"scene file {path}" + limit
    just_under = "#" * ((4 << 20) - 40) + "\n[time]\nduration = 0.001\n"
    assert len(just_under) <= 4 << 20
    softtled.Simulation.from_toml(just_under, backend="cpu")  # the limit itself is allowed


def test_a_collision_course_beyond_time_duration_is_refused():
    """`run` stops at time.duration, so its collision-course check lets through bodies that
    meet only later; advance() goes past it, so in Python every collision course that a step
    would cross counts: two plates 200 mm apart closing at 10 m/s (4 mm per step, the plates
    1.4 mm deep) met after a duration of 0.015 s and ended as a "numerical blow-up"."""
    plate = 'shape = "box"\nsize = [10, 2, 10]\ndivisions = [2, 1, 2]\n'
    text = (f'units = "mm"\n[[body]]\n{plate}position = [0, 0, 0]\n[[body]]\n{plate}position = [0, 200, 0]\n'
            'velocity = [0, -10, 0]\n[material]\nE = 3000.0\nnu = 0.3\n[damping]\nalpha = 0.0\n'
            '[gravity]\ng = [0, 0, 0]\n[floor]\nenabled = false\n[time]\nduration = 0.015\n')
    with pytest.raises(softtled.InputError, match=r"on a collision course at 10 m/s \(they meet after about 0\.0186 s\)"):
        softtled.Simulation.from_toml(text, backend="cpu")
    # Apart, the same plates are fine.
    softtled.Simulation.from_toml(text.replace("velocity = [0, -10, 0]", "velocity = [0, 10, 0]"), backend="cpu")


def test_numpy_values_are_what_they_hold():
    """A NumPy bool is a bool (floor=np.bool_(False) raised "takes a bool", mu=np.bool_(True)
    set mu = 1), a NumPy vector of the right length is a vector, and a (3, 1) array is refused
    rather than read as three numbers."""
    np = pytest.importorskip("numpy")
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    sim.set_params(floor=np.bool_(False))
    assert sim.params()["floor"] is False
    sim.set_params(floor=np.array(True))  # a 0-d bool array
    assert sim.params()["floor"] is True
    sim.set_params(mu=np.array(0.25))  # a 0-d number
    assert sim.params()["mu"] == 0.25
    with pytest.raises(TypeError, match="takes a number"):
        sim.set_params(mu=np.bool_(True))
    sim.set_params(g=np.array([0.0, -5.0, 0.0]))
    assert tuple(sim.params()["g"]) == (0.0, -5.0, 0.0)
    with pytest.raises(TypeError, match="flat sequence"):
        sim.set_params(g=np.zeros((3, 1)))


def test_advance_shorter_than_half_a_step_is_refused_with_either_step():
    """advance(h) with h below half the step in use takes no step: refused with the fixed
    step, and now with the adaptive one too, where it returned having done nothing (a loop
    `while sim.time < T: sim.advance(h)` never ended)."""
    for sets in ([], ['time.dt="adaptive"']):
        sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=["body.segments=[24,8]"] + sets)
        with pytest.raises(softtled.InputError, match="shorter than half the time step"):
            sim.advance(0.2 * sim.dt)
        assert sim.steps == 0
        sim.advance(0)  # nothing asked, nothing done
        sim.advance(2 * sim.dt)
        assert sim.steps >= 1


@pytest.mark.parametrize("sets", [[], ['time.dt="adaptive"']])
def test_a_refused_set_params_changes_nothing(sets):
    """A set_params refused by a late check (E = 1e-20 is in E's range, but gives a step
    below 1e-15 s) leaves the run exactly as one never asked: the step bounds, and with the
    adaptive step its ladder and the estimate in flight (dt_cr had kept the refused E's
    value and the adaptive run went on differently)."""
    make = lambda: softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=["body.segments=[24,8]"] + sets)
    asked, never = make(), make()
    asked.advance(0.01)
    never.advance(0.01)
    with pytest.raises(softtled.InputError, match="outside"):
        asked.set_params(E=1e-20)
    assert asked.time_step() == never.time_step()
    asked.advance(0.03)
    never.advance(0.03)
    assert asked.steps == never.steps and asked.dt == never.dt
    assert (asked.positions() == never.positions()).all()


def test_adaptive_set_params_before_the_first_step_is_the_scene_with_those_values():
    """Before the first step, set_params(E=...) on an adaptive run rebuilds the start as a
    scene with that E starts (warm-up estimate, first step, start increment): the two runs
    are the same bit for bit (the start had been rescaled from the old E's step instead)."""
    base = ["body.segments=[24,8]", 'time.dt="adaptive"']
    for key, value in (("E", 6000.0), ("nu", 0.45)):
        scene_run = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=base + [f"material.{key}={value}"])
        live_run = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=base)
        live_run.set_params(**{key: value})
        assert live_run.dt == scene_run.dt
        for sim in (scene_run, live_run):
            sim.advance(0.03)
        assert live_run.steps == scene_run.steps
        assert (live_run.positions() == scene_run.positions()).all()


def test_adaptive_advance_checks_each_output_interval_as_run_does(capfd):
    """A long adaptive advance is checked by the watchdog at every output time, as `run` is,
    so a trip early in the call rolls back there and the halved lambda compounds: one
    advance(0.02) trips, halves and ends as twenty advance_to(k ms) do. (Checked only at
    t_end, the one call rolled back to t = 0 and retried three times at lambda x 0.5, where
    the twenty went to x 0.25 and x 0.125: a probe's crush at g = 1e6.)"""
    import re

    sets = ["time.dt=adaptive", "gravity.g=[0,-1e6,0]"]

    def outcome(advance):
        sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=sets)
        capfd.readouterr()
        try:
            advance(sim)
            end = "ran"
        except softtled.SimulationDiverged:
            end = "diverged"
        lambdas = re.findall(r"continuing with lambda x (\S+)", capfd.readouterr().err)
        return end, sim.time, lambdas, sim.positions().copy()

    def in_steps(sim):
        for k in range(1, 21):
            sim.advance_to(k * 1e-3)

    one = outcome(lambda sim: sim.advance(0.02))
    twenty = outcome(in_steps)
    assert one[2] == ["0.5", "0.25", "0.125"], one[2]
    assert one[:3] == twenty[:3]
    assert np.array_equal(one[3], twenty[3])
