"""NumPy arrays: which are zero-copy read-only views and which are copies (README, "Python")."""
import gc

import numpy as np
import pytest

import softtled
from conftest import scene


@pytest.fixture
def sim():
    return softtled.Simulation(scene("torus_coarse.toml"), backend="cpu", set=["time.duration=0.01"])


def test_displacements_is_a_read_only_view_of_the_host_state(sim):
    sim.advance(0.005)
    u = sim.displacements()
    assert u.shape == (sim.nnode, 3) and u.dtype == np.float64
    assert not u.flags.writeable and not u.flags.owndata
    with pytest.raises(ValueError):
        u[0, 0] = 1.0
    # no copy: two calls see the same memory (the facade's host copy, 3 x nnode SoA)
    assert np.shares_memory(u, sim.displacements())
    assert u.strides == (8, 8 * sim.nnode)
    np.testing.assert_allclose(sim.positions(), sim.rest_positions() + u, rtol=0, atol=0)  # x = X + u, the same sum


def test_the_view_follows_the_state(sim):
    u = sim.displacements()
    snapshot = u.copy()
    sim.advance(0.002)
    assert not np.array_equal(u, snapshot)  # documented: the view shows the state now
    np.testing.assert_array_equal(u, sim.displacements())
    assert sim.diagnostics()["max_u"] == pytest.approx(np.linalg.norm(u, axis=1).max(), rel=1e-12)


def test_views_keep_the_simulation_alive():
    s = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    s.advance(0.003)
    u, X, tets = s.displacements(), s.rest_positions(), s.tets()
    expected = u.copy()
    del s
    gc.collect()
    np.testing.assert_array_equal(u, expected)
    assert X.shape[1] == 3 and tets.shape[1] == 4 and tets.max() < X.shape[0]


def test_copies_are_new_arrays(sim):
    sim.advance(0.004)
    x, v = sim.positions(), sim.velocities()
    assert x.flags.owndata and v.flags.owndata and x.flags.writeable
    assert not np.shares_memory(x, sim.positions())
    # free fall: the half-step velocity (du / dt) of every node is -g (t - dt/2), less damping
    t, dt = sim.time, sim.dt
    assert np.allclose(v[:, 1], v[0, 1]) and v[0, 1] < 0
    assert v[0, 1] == pytest.approx(-9.81 * (t - dt / 2), rel=0.05)
    assert sim.lumped_mass().sum() == pytest.approx(1000 * 2 * np.pi**2 * 7.5e-3 * (2.5e-3)**2, rel=0.15)  # a 45 x 9 polygon torus


def test_rest_mesh_views_are_read_only(sim):
    for a in (sim.rest_positions(), sim.tets(), sim.surface_triangles(), sim.lumped_mass(), sim.contact_state()):
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a[0] = 0


def test_no_cuda_array_interface(sim):
    # The Solver interface hands out host copies only; no device pointer is exposed.
    assert not hasattr(sim.displacements(), "__cuda_array_interface__")
