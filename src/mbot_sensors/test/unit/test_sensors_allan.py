"""mbot_sensors.allan on synthetic IMU data with known white noise density N and random walk K
(numpy, no ROS): the overlapping Allan deviation and the fit recover them within 10 %."""
import math

import numpy as np
import pytest

from mbot_sensors import allan


def synthetic(n_density, k_walk, rate, seconds, axes=3, seed=1):
    rng = np.random.default_rng(seed)
    n = int(rate * seconds)
    white = n_density * math.sqrt(rate) * rng.standard_normal((n, axes))
    walk = np.cumsum(k_walk * math.sqrt(1.0 / rate) * rng.standard_normal((n, axes)), axis=0)
    return white + walk + 0.01  # a constant bias does not change the Allan deviation


def test_white_noise_deviation_is_n_over_root_tau():
    rate = 100.0
    data = synthetic(2e-3, 0.0, rate, 3000.0)
    taus, adev = allan.allan_deviation(data, rate, sizes=np.array([1, 10, 100]))
    for tau, row in zip(taus, adev):
        assert row == pytest.approx(2e-3 / math.sqrt(tau), rel=0.05)


def test_recovers_white_noise_and_random_walk_within_10_percent():
    rate, n_density, k_walk = 100.0, 1e-3, 1e-3  # crossover sqrt(3) N / K = 1.7 s
    data = synthetic(n_density, k_walk, rate, 20000.0, seed=7)
    taus, adev = allan.allan_deviation(data, rate)
    assert taus[0] == pytest.approx(0.01) and taus[-1] > 1000.0
    for axis in range(3):
        fit = allan.fit_noise(taus, adev[:, axis], len(data), rate)
        assert fit["white_noise_density"] == pytest.approx(n_density, rel=0.1)
        assert fit["random_walk"] == pytest.approx(k_walk, rel=0.1)


def test_analyse_by_stamps_and_the_table():
    rate = 200.0
    gyro = synthetic(3e-4, 0.0, rate, 200.0, seed=3)
    accel = synthetic(2e-3, 0.0, rate, 200.0, seed=4) + np.array([0.0, 0.0, 9.81])
    stamps = 5.0 + np.arange(len(gyro)) / rate
    result = allan.analyse(stamps, gyro, accel)
    assert result["rate"] == pytest.approx(rate)
    for axis in "xyz":
        assert result["gyro"][axis]["white_noise_density"] == pytest.approx(3e-4, rel=0.1)
        assert result["accel"][axis]["white_noise_density"] == pytest.approx(2e-3, rel=0.1)
    text = allan.table(result)
    assert "40000 samples at 200.0 Hz" in text and "rad/s/sqrt(Hz)" in text
    summary = allan.summary(result)
    assert set(summary["accel"]["z"]) == {"white_noise_density", "bias_instability", "random_walk"}


def test_gaps_and_too_short_recordings_are_refused():
    stamps = np.arange(1000) / 100.0
    data = np.zeros((1000, 3))
    with pytest.raises(ValueError, match="1 gaps"):
        allan.analyse(np.delete(stamps, 500), data[:-1], data[:-1])
    with pytest.raises(ValueError, match="at least 20"):
        allan.analyse(stamps[:5], data[:5], data[:5])


def test_plot_writes_a_png(tmp_path):
    rate = 100.0
    data = synthetic(1e-3, 1e-4, rate, 100.0)
    result = allan.analyse(np.arange(len(data)) / rate, data, data)
    path = str(tmp_path / "allan.png")
    allan.plot(result, path, "synthetic")
    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
