"""write_vtu and render_png: the files `softtled run --vtu` and `softtled render` write."""
import os
import re

import pytest

import softtled
from conftest import run_cli, scene


def test_write_vtu_writes_the_state(tmp_path):
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    sim.advance(0.005)
    path = tmp_path / "state.vtu"
    sim.write_vtu(str(path))
    text = path.read_text()
    assert f'NumberOfPoints="{sim.nnode}"' in text and f'NumberOfCells="{sim.ntet}"' in text
    for name in ("displacement", "velocity", "contact", "J", "von_mises"):
        assert re.search(f'Name="{name}', text), name
    assert not os.path.exists(str(path) + ".tmp")


def test_write_vtu_errors_like_the_cli(tmp_path):
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    with pytest.raises(softtled.InputError, match="write_vtu"):
        sim.write_vtu(str(tmp_path / "no_such_dir" / "x.vtu"))
    with pytest.raises(softtled.InputError, match="write_vtu"):
        sim.write_vtu(str(tmp_path))  # a directory


def render_or_skip(sim, path, **kw):
    if not softtled.HAVE_RENDER:
        pytest.skip("this module was built without the renderer (SOFTTLED_RENDER=OFF)")
    try:
        return sim.render_png(str(path), **kw)
    except softtled.ResourceError as e:  # no EGL (no GPU driver, no Mesa): the machine, not the code
        pytest.skip(f"no EGL context on this machine: {e}")


@pytest.mark.parametrize("color", ["displacement", "von_mises"])
def test_render_png_equals_softtled_render(exe, tmp_path, color):
    # render_png frames the body with `softtled render --fixed-camera`'s camera (the rest
    # pose's framing), and draws through the same headless loop: the same PNG, byte for byte,
    # for the |u| and the von Mises colour maps (their legends included).
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    sim.advance(0.025)
    py_png = tmp_path / "py.png"
    renderer = render_or_skip(sim, py_png, width=200, height=150, color=color)
    assert renderer
    out = tmp_path / "cli"
    run_cli(exe, "render", "--scene", scene("torus_coarse.toml"), "--backend", "cpu", "--at", "0.025", "--out",
            str(out), "--size", "200x150", "--color", color, "--fixed-camera", "--stem", "cli")
    cli_png = out / "cli_t0.0250.png"
    assert py_png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert py_png.read_bytes() == cli_png.read_bytes()


def test_render_png_bad_options(tmp_path):
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    with pytest.raises(softtled.InputError, match="color 'plaid'"):
        sim.render_png(str(tmp_path / "x.png"), color="plaid")
    with pytest.raises(softtled.InputError, match="size 8x8"):
        sim.render_png(str(tmp_path / "x.png"), width=8, height=8)
    # A bad camera value is named with its value (one message for all three before).
    for kw, text in (({"zoom": 0}, r"zoom = 0: must be in \[0.01, 100\]"),
                     ({"azimuth": float("nan")}, "azimuth = nan"), ({"elevation": 90}, "elevation = 90")):
        with pytest.raises(softtled.InputError, match=text):
            sim.render_png(str(tmp_path / "x.png"), **kw)


def test_outputs_never_overwrite_the_scene_or_its_files(tmp_path):
    """write_vtu and render_png onto the scene file or a file it reads are refused (as
    the CLI refuses it, naming both), and those files are left byte for byte."""
    src = open(scene("torus_on_mesh.toml")).read()
    mesh = os.path.join(os.path.dirname(scene("torus_on_mesh.toml")), "..", "meshes", "bowl.obj")
    (tmp_path / "bowl.obj").write_bytes(open(mesh, "rb").read())
    (tmp_path / "s.toml").write_text(src.replace("../meshes/bowl.obj", "bowl.obj"))
    sim = softtled.Simulation(str(tmp_path / "s.toml"), backend="cpu")
    before = {p: (tmp_path / p).read_bytes() for p in ("s.toml", "bowl.obj")}
    for target in ("s.toml", "bowl.obj"):
        with pytest.raises(softtled.InputError, match="the same file"):
            sim.write_vtu(str(tmp_path / target))
        with pytest.raises(softtled.InputError, match="the same file"):
            sim.render_png(str(tmp_path / target), width=64, height=48)
    assert {p: (tmp_path / p).read_bytes() for p in before} == before
