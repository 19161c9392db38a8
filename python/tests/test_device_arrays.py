"""GPU arrays through __cuda_array_interface__ (Simulation.device_displacements): the solver's own
live buffer, no copy. Read back here with the CUDA runtime through ctypes (no CuPy needed): after
ordering on the interface's stream, row r of the device array is mesh node rows[r] of
displacements(), bit for bit. Skipped where the module has no usable CUDA device."""
import ctypes
import ctypes.util
import time

import numpy as np
import pytest

import softtled
from conftest import scene


def cudart():
    for name in ("libcudart.so", ctypes.util.find_library("cudart") or "", "/usr/local/cuda/lib64/libcudart.so"):
        try:
            return ctypes.CDLL(name) if name else None
        except OSError:
            continue
    return None


@pytest.fixture
def gpu_sim():
    try:
        sim = softtled.Simulation(scene("torus_drop.toml"), backend="cuda", set=["solver.precision=float"])
    except softtled.InputError as e:  # no CUDA backend compiled in, or no device
        pytest.skip(f"no CUDA backend: {e}")
    if cudart() is None:
        pytest.skip("libcudart not found (set LD_LIBRARY_PATH to the CUDA toolkit's lib64)")
    return sim


def read_back(rt, iface, n, dtype):
    """The n x 3 array the interface describes, copied to the host after its stream."""
    ptr, read_only = iface["data"]
    assert not read_only  # PyTorch accepts no read-only interface (README)
    assert rt.cudaStreamSynchronize(ctypes.c_void_p(iface["stream"])) == 0
    soa = np.empty((3, n), dtype=dtype)  # the strides say struct-of-arrays: component-major
    assert rt.cudaMemcpy(soa.ctypes.data_as(ctypes.c_void_p), ctypes.c_void_p(ptr), ctypes.c_size_t(soa.nbytes),
                         ctypes.c_int(2)) == 0  # cudaMemcpyDeviceToHost
    return soa.T


def test_the_device_array_is_the_live_state_in_place(gpu_sim):
    rt = cudart()
    n = gpu_sim.nnode
    first = None
    for seconds in (0.025, 1e-4):  # in contact by then (first contact ~0.02 s), then a few more steps
        gpu_sim.advance(seconds)
        d = gpu_sim.device_displacements()
        iface = d.__cuda_array_interface__
        assert iface["version"] == 3 and iface["shape"] == (n, 3) and iface["typestr"] == "<f4"
        assert iface["strides"] == (4, 4 * n)
        first = first or iface["data"][0]
        assert iface["data"][0] == first, "the interface points at the live buffer, not a copy per call"
        rows = d.rows
        assert sorted(rows.tolist()) == list(range(n)), "rows must be a permutation of the mesh's nodes"
        u_dev = read_back(rt, iface, n, np.float32)
        np.testing.assert_array_equal(u_dev.astype(np.float64), gpu_sim.displacements()[rows])
        du_dev = read_back(rt, gpu_sim.device_increments().__cuda_array_interface__, n, np.float32)
        np.testing.assert_array_equal(du_dev.astype(np.float64) / gpu_sim.dt, gpu_sim.velocities()[rows])
    assert gpu_sim.diagnostics()["n_contact"] > 0


def test_torch_reads_the_buffer_in_place(gpu_sim):
    """A real consumer: PyTorch (where installed) wraps the interface without a copy."""
    torch = pytest.importorskip("torch")
    gpu_sim.advance(0.02)
    d = gpu_sim.device_displacements()
    t = torch.as_tensor(d, device="cuda")
    assert t.data_ptr() == d.__cuda_array_interface__["data"][0], "torch must share the solver's buffer"
    assert t.shape == (gpu_sim.nnode, 3) and t.dtype == torch.float32
    np.testing.assert_array_equal(t.cpu().numpy().astype(np.float64), gpu_sim.displacements()[d.rows])


def test_cpu_backend_says_where_its_state_is():
    sim = softtled.Simulation(scene("torus_coarse.toml"), backend="cpu")
    with pytest.raises(ValueError, match="keeps its state in host memory"):
        sim.device_displacements()
