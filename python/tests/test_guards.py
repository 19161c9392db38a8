"""The binding's guards: methods reached through the class with an object that is not an
initialised Simulation raise (they crashed), every path argument takes os.PathLike, a live
parameter that cannot apply is refused, and a number's own conversion error is not hidden."""
import os
import pathlib
import subprocess
import sys
import textwrap

import pytest

import softtled
from conftest import scene


def run_isolated(code):
    """code in a fresh interpreter: a crash is a failed assertion here, not a dead test run."""
    p = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300,
                       env=dict(os.environ))
    assert p.returncode == 0, f"exit {p.returncode} (a negative code is a signal)\n{p.stdout}\n{p.stderr}"
    return p.stdout


def test_every_method_through_the_class_refuses_an_uninitialised_instance():
    """S.params(S.__new__(S)) crashed, and after a Simulation was freed it returned a dict read
    from the freed memory: params was bound to the C++ object directly, past the guard. Every
    method and property of the class, called so, raises the guard's TypeError."""
    out = run_isolated("""
        import softtled
        S = softtled.Simulation
        old = S(SCENE, backend="cpu")
        del old  # its freed memory is what an unguarded method read
        bare = S.__new__(S)
        args = {"advance": (0.1,), "advance_to": (0.1,), "write_vtu": ("x.vtu",), "render_png": ("x.png",)}
        refused, passed = [], []
        for name, attr in vars(softtled._softtled.Simulation).items():
            if name.startswith("__") or name == "_is_initialised":
                continue
            call = attr.__get__ if isinstance(attr, property) else attr
            try:
                call(bare, *args.get(name, ()))
                passed.append(name)
            except TypeError as e:
                (refused if "never initialised" in str(e) else passed).append(name)
        print(" ".join(sorted(refused)), "|", " ".join(sorted(passed)))
    """.replace("SCENE", repr(scene("torus_coarse.toml"))))
    refused, passed = (set(part.split()) for part in out.split("|"))
    assert not passed  # each raised the guard's TypeError
    assert {"params", "diagnostics", "step", "time", "write_vtu", "set_params", "displacements"} <= refused
    assert len(refused) >= 30  # every method and property the class has


def test_a_device_array_made_by_new_alone_is_refused():
    """DeviceArray's properties were bound to the C++ object directly: on DeviceArray.__new__
    alone they read garbage (rows crashed)."""
    out = run_isolated("""
        import softtled
        D = softtled._softtled.DeviceArray
        bare = D.__new__(D)
        for name in ("rows", "shape", "__cuda_array_interface__"):
            try:
                getattr(bare, name)
                print(name, "read")
            except TypeError as e:
                print(name, "refused" if "DeviceArray: not one made by" in str(e) else e)
    """)
    assert out.split() == ["rows", "refused", "shape", "refused", "__cuda_array_interface__", "refused"]


def test_is_initialised_and_getattribute_check_the_type_first():
    """_is_initialised(None) and __getattribute__ on another object read them as a pybind11
    instance (a crash)."""
    out = run_isolated("""
        import softtled
        cls = softtled._softtled.Simulation
        print(cls._is_initialised(None), cls._is_initialised(3), cls._is_initialised("x"))
        for obj in (None, 3):
            try:
                cls.__getattribute__(obj, "time")
            except TypeError as e:
                print("TypeError", "called on a" in str(e))
    """)
    assert out.split() == ["False", "False", "False", "TypeError", "True", "TypeError", "True"]
    assert softtled.Simulation._is_initialised(softtled.Simulation(scene("torus_coarse.toml"), backend="cpu"))
    assert not softtled.Simulation._is_initialised(softtled.Simulation.__new__(softtled.Simulation))


def test_every_path_argument_takes_os_pathlike(tmp_path):
    """write_vtu and render_png refused pathlib.Path (TypeError) while the constructor took it;
    a dict scene's source (the path relative files resolve against) takes one too."""
    sim = softtled.Simulation(pathlib.Path(scene("torus_coarse.toml")), backend="cpu")
    sim.write_vtu(tmp_path / "state.vtu")
    assert f'NumberOfPoints="{sim.nnode}"' in (tmp_path / "state.vtu").read_text()
    sim.write_vtu(str(tmp_path / "same.vtu"))
    assert (tmp_path / "state.vtu").read_bytes() == (tmp_path / "same.vtu").read_bytes()
    sim.write_vtu(bytes(tmp_path / "bytes.vtu"))  # bytes, as the str-only binding took
    assert (tmp_path / "state.vtu").read_bytes() == (tmp_path / "bytes.vtu").read_bytes()
    with pytest.raises(softtled.InputError, match="write_vtu"):  # the path's own checks still apply
        sim.write_vtu(tmp_path / "no_such_dir" / "x.vtu")
    for call in (lambda: sim.write_vtu(3), lambda: sim.render_png(3.5)):
        with pytest.raises(TypeError, match="path must be a str, bytes or os.PathLike"):
            call()
    # render_png: the path is taken (its checks run) whether or not EGL is there
    with pytest.raises(softtled.InputError, match="render_png"):
        sim.render_png(tmp_path / "no_such_dir" / "x.png", width=64, height=64)
    # it writes a PNG, so its name says so (x.jpg was written as a PNG), as plot --out's
    with pytest.raises(softtled.InputError, match="ending in .png"):
        sim.render_png(tmp_path / "x.jpg", width=64, height=64)
    assert not (tmp_path / "x.jpg").exists()
    if softtled.HAVE_RENDER:
        try:
            sim.render_png(tmp_path / "s.png", width=64, height=64)
        except softtled.ResourceError as e:  # no EGL here: the machine, not the path
            pytest.skip(f"no EGL context on this machine: {e}")
        assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = pathlib.Path(scene("torus_coarse.toml")).read_text()
    named = softtled.Simulation.from_toml(text, backend="cpu", source=pathlib.Path(tmp_path / "x.toml"))
    assert named.source == str(tmp_path / "x.toml")


def test_body_contact_on_one_body_is_refused_not_ignored():
    """set_params(body_contact=True) on one body returned '' and params() stayed False; it is
    refused as dt_max on a fixed step is (InputError), changing nothing. With two bodies it
    applies, and False on one body (what it is) is accepted."""
    one = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    with pytest.raises(softtled.InputError, match="body_contact applies only to a scene of two or more bodies"):
        one.set_params(body_contact=True, E=6000)
    assert one.params()["body_contact"] is False and one.params()["E"] != 6000
    assert one.set_params(body_contact=False) == "" and one.params()["body_contact"] is False
    two = softtled.Simulation(scene("two_ring_collision.toml"), backend="cpu", set=["contact.bodies=false"])
    assert two.params()["body_contact"] is False
    two.set_params(body_contact=True)
    assert two.params()["body_contact"] is True


class Raises:
    """A number whose conversion raises the caller's own error."""

    def __init__(self, exc):
        self.exc = exc

    def __float__(self):
        raise self.exc

    def __index__(self):
        raise self.exc


def test_a_numbers_own_conversion_error_propagates():
    """A __float__ raising RuntimeError was reported as a generic TypeError that hid it, in
    set_params and in every number argument."""
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    bad = Raises(RuntimeError("my float failed"))
    calls = [lambda: sim.set_params(E=bad), lambda: sim.set_params(g=(0.0, bad, 0.0)), lambda: sim.advance(bad),
             lambda: sim.advance_to(bad), lambda: sim.step(bad), lambda: softtled.time_decimals(bad),
             lambda: softtled.step_count(bad, 1e-5), lambda: sim.render_png("x.png", zoom=bad),
             lambda: sim.render_png("x.png", width=bad)]
    for call in calls:
        with pytest.raises(RuntimeError, match="my float failed"):
            call()
    with pytest.raises(ValueError, match="mine"):
        sim.advance(Raises(ValueError("mine")))
    assert sim.steps == 0 and sim.params()["E"] == softtled.Simulation(scene("torus_coarse.toml"), backend="cpu").params()["E"]
    # plain mismatches stay the TypeErrors they were
    for call in (lambda: sim.advance("0.5"), lambda: sim.step(1.5), lambda: sim.set_params(E="1"),
                 lambda: sim.set_params(E=10**400), lambda: sim.advance(10**400)):
        with pytest.raises(TypeError):
            call()
    sim.advance(0.001)  # numbers still convert as before
    sim.step(True)
    assert sim.steps > 1
