"""examples/python/parameter_sweep.py runs and writes its plot (torus_drop.py: test_cli_parity.py)."""
import pytest

from conftest import run_example

pytest.importorskip("matplotlib")


def test_parameter_sweep_writes_a_png(tmp_path):
    out = tmp_path / "sweep.png"
    rc, _, err = run_example("parameter_sweep.py", "--out", str(out), "--duration", "0.06", "--E", "3000",
                             "--mu", "0.05", "1.0", "--backend", "cpu")
    assert rc == 0, err
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # a ring on a 20 degree slope rolls without slip when mu >= tan(20 deg) / 2 = 0.18
    rolled = {line.split("mu = ")[1].split(":")[0]: float(line.rsplit("= ", 1)[1])
              for line in err.splitlines() if "R theta / s" in line}
    assert rolled["0.05"] < 0.5 < rolled["1"]
