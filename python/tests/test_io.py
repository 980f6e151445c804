"""Point-set files: written and read in every format, and read from the command line's."""

import numpy as np
import pytest

import specvar


@pytest.mark.parametrize("fmt", ["text", "binary", "json"])
def test_round_trip_keeps_every_bit(tmp_path, fmt):
    sets = specvar.sample("poisson", 100, realizations=3, seed=2, cache=False)
    path = tmp_path / f"p.{fmt}"
    specvar.write_points(path, sets, format=fmt)
    assert np.array_equal(specvar.read_points(path), sets)


def test_reads_what_the_command_line_writes(cli, tmp_path):
    path = tmp_path / "cli.bin"
    cli("sample", "-s", "halton", "-n", "64", "-d", "3", "--realizations", "2", "--seed", "4", "--binary", "-o", str(path))
    assert path.read_bytes()[:4] == b"UTK!"
    assert np.array_equal(specvar.read_points(path), specvar.sample("halton", 64, realizations=2, dimension=3, seed=4))


def test_sets_of_different_sizes_come_back_as_a_list(tmp_path):
    path = tmp_path / "ragged.txt"
    path.write_text("0.1 0.2\n0.3 0.4\n#\n0.5 0.6\n")
    sets = specvar.read_points(path)
    assert isinstance(sets, list) and [s.shape for s in sets] == [(2, 2), (1, 2)]


def test_file_errors_name_the_line(tmp_path):
    path = tmp_path / "bad.txt"
    path.write_text("0.1 0.2\n0.3 oops\n")
    with pytest.raises(ValueError, match="line 2"):
        specvar.read_points(path)
    with pytest.raises(ValueError):
        specvar.read_points(tmp_path / "missing.txt")
    with pytest.raises(ValueError, match="format"):
        specvar.write_points(tmp_path / "x", np.array([[0.5, 0.5]]), format="csv")
