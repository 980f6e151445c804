"""The notebook-style example runs end to end and writes its plot."""

import pathlib
import subprocess
import sys

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "compare_samplers.py"


def test_the_example_writes_its_plot(tmp_path):
    done = subprocess.run([sys.executable, str(EXAMPLE), str(tmp_path)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    png = tmp_path / "compare_samplers.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    assert "scipy Sobol' N=256, shifted: predicted" in done.stdout
