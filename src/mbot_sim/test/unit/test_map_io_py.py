"""mbot_sim.map_io.read_pgm reads both PGM flavours map_server accepts, and refuses others."""
import numpy as np
import pytest

from mbot_sim.map_io import read_pgm


def test_binary_and_ascii_pgm_give_the_same_pixels(tmp_path):
    pixels = np.array([[0, 100, 254], [254, 205, 0]], dtype=np.uint8)
    (tmp_path / "b.pgm").write_bytes(b"P5\n# comment\n3 2\n255\n" + pixels.tobytes())
    (tmp_path / "a.pgm").write_text("P2\n3 2\n255\n0 100 254\n254 205 0\n")
    assert (read_pgm(str(tmp_path / "b.pgm")) == pixels).all()
    assert (read_pgm(str(tmp_path / "a.pgm")) == pixels).all()


def test_maxval_is_scaled_to_255(tmp_path):
    (tmp_path / "m.pgm").write_text("P2\n2 1\n15\n0 15\n")
    assert read_pgm(str(tmp_path / "m.pgm")).tolist() == [[0, 255]]


def test_not_a_pgm_names_the_file(tmp_path):
    (tmp_path / "x.pgm").write_bytes(b"P6\n1 1\n255\n\x00\x00\x00")
    with pytest.raises(ValueError, match="x.pgm: not a PGM image"):
        read_pgm(str(tmp_path / "x.pgm"))
