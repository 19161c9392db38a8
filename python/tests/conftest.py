"""Shared fixtures of the module's tests: the softtled executable, the assets and examples.

ctest sets SOFTTLED_EXE, SOFTTLED_ASSETS, SOFTTLED_EXAMPLES and PYTHONPATH (python/CMakeLists.txt);
by hand: PYTHONPATH=build/python SOFTTLED_EXE=build/softtled python3 -m pytest python/tests
"""
import os
import subprocess
import sys

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ASSETS = os.environ.get("SOFTTLED_ASSETS", os.path.join(ROOT, "assets"))
EXAMPLES = os.environ.get("SOFTTLED_EXAMPLES", os.path.join(ROOT, "examples", "python"))
SCENES = os.path.join(ASSETS, "scenes")


def scene(name):
    return os.path.join(SCENES, name)


@pytest.fixture(scope="session")
def exe():
    path = os.environ.get("SOFTTLED_EXE", os.path.join(ROOT, "build", "softtled"))
    if not os.path.isfile(path):
        pytest.skip(f"no softtled executable at {path} (set SOFTTLED_EXE)")
    return path


def run_cli(exe, *args, check=True):
    """The CLI's exit code, stdout and stderr."""
    p = subprocess.run([exe, *args], capture_output=True, text=True, timeout=600)
    if check and p.returncode != 0:
        raise AssertionError(f"softtled {' '.join(args)} exited {p.returncode}:\n{p.stderr}")
    return p.returncode, p.stdout, p.stderr


def run_example(name, *args):
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *args], capture_output=True, text=True,
                       timeout=600, env=dict(os.environ))
    return p.returncode, p.stdout, p.stderr
