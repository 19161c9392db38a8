"""SoftTLED: soft-body simulation (TLED FEM) from Python.

    import softtled
    sim = softtled.Simulation("assets/scenes/torus_drop.toml", backend="cpu",
                              set=["body.segments=[45,9]"])
    sim.advance(0.05)
    u = sim.displacements()        # nnode x 3, read-only view
    print(sim.diagnostics()["ke"])

README.md, section "Python", lists the API, what is a view and what a copy, and the limits.
"""
import os

from . import _softtled
from ._softtled import (CHUNK_STEPS, HAVE_RENDER, LIVE_PARAMETERS, InputError, ResourceError, SimulationDiverged,
                        step_count, time_decimals)
from .scene_toml import dumps as scene_to_toml

__all__ = ["Simulation", "InputError", "ResourceError", "SimulationDiverged", "scene_to_toml", "step_count",
           "time_decimals", "CHUNK_STEPS", "HAVE_RENDER", "LIVE_PARAMETERS"]


def _source(source):
    # The name relative paths resolve against: a path, so os.PathLike as the scene itself.
    return os.fspath(source) if isinstance(source, os.PathLike) else source


def _overrides(set):
    if set is None:
        return []
    if isinstance(set, str):
        return [set]
    if isinstance(set, (bytes, bytearray)):
        raise TypeError(f"set: a str or a list of str, not {type(set).__name__}")
    out = []
    for s in set:  # str(b"k=v") would pass the repr "b'k=v'" on as a key
        if not isinstance(s, str):
            raise TypeError(f"set: each override must be a str ('section.key=value'), got {type(s).__name__}")
        out.append(s)
    return out


class Simulation(_softtled.Simulation):
    """One scene, meshed and ready to step (the C++ Simulation facade).

    scene: a scene file (str or os.PathLike, as ``softtled run --scene``) or a dict of the
    scene's tables (written as TOML, scene_to_toml). backend: "auto", "cpu" or "cuda", as
    ``--backend``. set: "section.key=value" overrides, as ``--set``. source: the name a
    dict scene has in messages; relative file paths in it resolve against its directory
    (default "<dict>": against the working directory).

    Errors: InputError (a ValueError) with the message ``softtled run`` prints after
    "softtled: error: " (exit code 2).
    """

    def __init__(self, scene, backend="auto", set=None, source="<dict>"):
        if _softtled.Simulation._is_initialised(self):  # pybind11 would keep the old state silently
            raise RuntimeError("Simulation.__init__: this Simulation is already initialised; create a new one")
        if isinstance(scene, dict):
            _softtled.Simulation.__init__(self, "", scene_to_toml(scene), _source(source), backend, _overrides(set))
        elif isinstance(scene, (str, os.PathLike)):
            path = os.fspath(scene)
            if not path:
                raise InputError("scene file '': empty path")
            _softtled.Simulation.__init__(self, path, "", "", backend, _overrides(set))
        else:
            raise TypeError(f"scene: a path or a dict, not {type(scene).__name__}")

    @classmethod
    def from_toml(cls, text, backend="auto", set=None, source="<toml>"):
        """A scene given as TOML text (named `source` in messages)."""
        if not isinstance(text, str):  # str(b"...") would parse the repr "b'...'"
            raise TypeError(f"from_toml: text must be a str, got {type(text).__name__}")
        self = cls.__new__(cls)
        _softtled.Simulation.__init__(self, "", text, _source(source), backend, _overrides(set))
        return self

    def __repr__(self):
        return (f"<softtled.Simulation {self.source!r}: {self.nnode} nodes, {self.ntet} tets, backend {self.backend}, "
                f"t = {self.time:.6g} s, dt = {self.dt:.4g} s>")
