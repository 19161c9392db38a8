"""What the Python module's device arrays save a GPU consumer (issue 17): handing CuPy or PyTorch
the solver's live buffer through __cuda_array_interface__ against the host round trip it replaces
(displacements(), the host copy, uploaded again with cudaMemcpy as cupy.asarray(host) would).
Needs the CUDA backend and libcudart (ctypes; no CuPy needed):
  PYTHONPATH=build/python python3 bench/python_device_arrays.py [scene.toml] [--set key=value ...]"""
import ctypes
import sys
import time

import numpy as np

import softtled


def median_us(f, reps):
    t = []
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        t.append(time.perf_counter() - t0)
    return 1e6 * float(np.median(t))


def main():
    path = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("--") else "assets/scenes/torus_drop.toml"
    sets = [a for a in sys.argv[1:] if "=" in a]
    rt = ctypes.CDLL("libcudart.so")
    sim = softtled.Simulation(path, backend="cuda", set=sets)
    sim.step(200)
    host = np.ascontiguousarray(sim.displacements())
    dev = ctypes.c_void_p()
    assert rt.cudaMalloc(ctypes.byref(dev), ctypes.c_size_t(host.nbytes)) == 0

    def interface():
        sim.device_displacements().__cuda_array_interface__

    def host_round_trip():  # the host copy is already there after a step; then the upload
        h = sim.displacements()
        rt.cudaMemcpy(dev, h.ctypes.data_as(ctypes.c_void_p), ctypes.c_size_t(h.nbytes), ctypes.c_int(1))

    def step_then(f):
        def g():
            sim.step(1)
            f()
        return g

    reps = 2000
    print(f"{path}: {sim.nnode} nodes, {sim.ntet} tets, backend {sim.backend}, {sim.precision}")
    print(f"  device_displacements().__cuda_array_interface__: {median_us(interface, reps):.2f} us (no copy)")
    print(f"  displacements() + upload (cudaMemcpy H2D, {host.nbytes} B): {median_us(host_round_trip, reps):.2f} us")
    try:
        import torch
        d = sim.device_displacements()
        t = torch.as_tensor(d, device="cuda")
        shared = t.data_ptr() == d.__cuda_array_interface__["data"][0]
        us = median_us(lambda: torch.as_tensor(sim.device_displacements(), device="cuda"), reps)
        print(f"  torch.as_tensor(device_displacements()): {us:.2f} us, shares the buffer: {shared}")
    except ImportError:
        print("  (no torch here)")
    s1, s2 = median_us(step_then(interface), 300), median_us(step_then(host_round_trip), 300)
    print(f"  step(1) + interface: {s1:.1f} us;  step(1) + host round trip: {s2:.1f} us "
          "(step(1) downloads the state for the watchdog either way)")
    rt.cudaFree(dev)


if __name__ == "__main__":
    main()
