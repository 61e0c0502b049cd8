"""The MAPF benchmark inputs are byte-exact copies: every file matches SHA256SUMS, and every
input in the folder is listed there."""
import hashlib
import os

BENCH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench", "mapf")


def sums():
    with open(os.path.join(BENCH, "SHA256SUMS")) as f:
        return dict(reversed(line.split()) for line in f if line.strip())


def test_checksums_match():
    listed = sums()
    assert len(listed) >= 30  # 5 maps, 25 scenarios (+ SOURCE.txt)
    for name, digest in listed.items():
        with open(os.path.join(BENCH, name), "rb") as f:
            assert hashlib.sha256(f.read()).hexdigest() == digest, name


def test_every_input_is_listed():
    inputs = [n for n in os.listdir(BENCH) if n.endswith((".map", ".scen"))]
    assert len(inputs) == 30
    assert set(inputs) <= set(sums())
