"""Scenes as dicts (written as TOML by softtled.scene_to_toml) and as TOML text."""
import math
import tomllib

import numpy as np
import pytest

import softtled
from conftest import scene


def test_dumps_round_trips_through_a_toml_reader():
    d = {
        "units": "mm",
        "body": [{"shape": "torus", "segments": [45, 9], "position": [0, 0, 0.5],
                  "material": {"E": 6000.0}},
                 {"shape": "box", "size": np.array([4.0, 4.0, 4.0]), "position": [0, 30, 0]}],
        "material": {"E": 3000, "nu": 0.49},
        "contact": {"mode": "coulomb", "mu": np.float64(0.3), "self": True},
        "time": {"dt": "auto", "duration": 1e-3},
        "obstacle": [{"shape": "sphere", "center": [0, -20, 0], "radius": 3.0}],
        "output": {"track_points": [[10, 0, 0], [0, -10, 0]]},
        "odd key": 'quote " and \\ and \u00e9',
    }
    text = softtled.scene_to_toml(d)
    back = tomllib.loads(text)
    assert back["body"][0]["material"]["E"] == 6000.0
    assert back["body"][1]["size"] == [4.0, 4.0, 4.0]
    assert back["contact"] == {"mode": "coulomb", "mu": 0.3, "self": True}
    assert back["output"]["track_points"] == [[10, 0, 0], [0, -10, 0]]
    assert back["odd key"] == d["odd key"]
    assert math.isnan(tomllib.loads(softtled.scene_to_toml({"a": {"x": math.nan}}))["a"]["x"])
    with pytest.raises(TypeError):
        softtled.scene_to_toml({"a": {"x": object()}})


def trajectory(sim, n=5):
    out = []
    for _ in range(n):
        sim.advance(0.004)
        out.append(sim.displacements().copy())
    return out


def test_dict_scene_is_the_file_scene():
    path = scene("torus_coarse.toml")
    with open(path, "rb") as f:
        d = tomllib.load(f)
    a = softtled.Simulation(path, backend="cpu", set=["contact.mode=coulomb"])
    b = softtled.Simulation(d, backend="cpu", set=["contact.mode=coulomb"])
    with open(path) as f:
        c = softtled.Simulation.from_toml(f.read(), backend="cpu", set=["contact.mode=coulomb"])
    assert b.source == "<dict>" and c.source == "<toml>"
    assert a.nnode == b.nnode == c.nnode and a.dt == b.dt == c.dt
    for x, y, z in zip(trajectory(a), trajectory(b), trajectory(c)):
        assert np.array_equal(x, y) and np.array_equal(x, z)


def test_set_applies_to_dict_scenes():
    sim = softtled.Simulation({"body": {"shape": "box", "size": [4, 4, 4], "divisions": [2, 2, 2]},
                               "floor": {"enabled": False}},
                              backend="cpu", set="material.E=5000")
    assert sim.params()["E"] == 5000.0 and sim.params()["planes"] == []
