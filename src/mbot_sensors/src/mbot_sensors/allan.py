"""Allan deviation of a static IMU recording and its noise parameters (no ROS here).

The method of IEEE Std 952-1997 (Annex C, Allan variance) as the Kalibr allan_variance_ros tool
applies it: the overlapping Allan deviation of each axis over log-spaced cluster times tau, and
the noise terms fitted to it:

    sigma^2(tau) = N^2 / tau + B^2 * 2 ln2 / pi + K^2 * tau / 3

N (white noise density, the slope -1/2 line, read at tau = 1 s: sigma(1) = N), B (bias
instability, the flat part) and K (bias random walk, the slope +1/2 line, read at tau = 3 s:
sigma(3) = K) are found by a non-negative least squares fit of sigma^2 over all cluster times,
each weighted by its statistical uncertainty (an Allan variance from M clusters is known to about
1/sqrt(M)). Units: gyro N [rad/s/sqrt(Hz)], K [rad/s^2/sqrt(Hz)]; accel N [m/s^2/sqrt(Hz)],
K [m/s^3/sqrt(Hz)].

    taus, adev = allan_deviation(samples, rate)       # samples: (n, axes) array
    fit = fit_noise(taus, adev[:, 0], n_samples, rate)
"""
import math

import numpy as np

#: sigma^2 of the flat part (bias instability B) is B^2 * 2 ln2 / pi (IEEE 952).
FLICKER = 2.0 * math.log(2.0) / math.pi


def cluster_sizes(n, points_per_decade=10, min_clusters=9):
    """Cluster sizes m (samples per cluster), log-spaced from 1 up to the largest with at least
    `min_clusters` independent clusters in n samples, without repeats."""
    max_m = max(1, n // min_clusters)
    count = int(math.ceil(math.log10(max_m) * points_per_decade)) + 1 if max_m > 1 else 1
    ms = np.unique(np.round(np.logspace(0, math.log10(max_m), count)).astype(np.int64))
    return ms[ms >= 1]


def allan_deviation(samples, rate, sizes=None):
    """Overlapping Allan deviation of rate samples (gyro rad/s or accel m/s^2).

    samples: array (n,) or (n, axes), equally spaced at `rate` [Hz].
    Returns (taus [s], adev) with adev of shape (len(taus), axes).
    sigma^2(m tau0) = sum_k (theta[k+2m] - 2 theta[k+m] + theta[k])^2 / (2 (m tau0)^2 (n - 2m)),
    theta the integrated signal (IEEE 952, the overlapping estimator).
    """
    y = np.asarray(samples, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    n = y.shape[0]
    if n < 20:
        raise ValueError("need at least 20 samples for an Allan deviation, got %d" % n)
    tau0 = 1.0 / rate
    theta = np.vstack([np.zeros((1, y.shape[1])), np.cumsum(y, axis=0) * tau0])
    ms = cluster_sizes(n) if sizes is None else np.asarray(sizes)
    ms = ms[2 * ms < n]
    adev = np.empty((len(ms), y.shape[1]))
    for i, m in enumerate(ms):
        d = theta[2 * m:] - 2.0 * theta[m:-m] + theta[:-2 * m]
        adev[i] = np.sqrt(np.sum(d * d, axis=0) / (2.0 * (m * tau0) ** 2 * (n + 1 - 2 * m)))
    return ms * tau0, adev


def fit_noise(taus, adev, n_samples, rate):
    """Fit N, B, K (module docstring) to one axis' Allan deviation.

    Returns a dict: white_noise_density (N), bias_instability (B), random_walk (K), and the
    sigma of the fitted curve at each tau (`fitted`)."""
    taus = np.asarray(taus, dtype=float)
    var = np.asarray(adev, dtype=float) ** 2
    duration = n_samples / float(rate)
    clusters = np.maximum(duration / taus - 1.0, 1.0)
    # relative uncertainty of an Allan variance from M clusters ~ 1/sqrt(M)
    weight = np.sqrt(clusters) / np.maximum(var, 1e-300)
    basis = np.column_stack([1.0 / taus, np.full_like(taus, FLICKER), taus / 3.0])
    coef = _nnls(basis * weight[:, None], var * weight)
    n2, b2, k2 = coef
    return {
        "white_noise_density": math.sqrt(n2),
        "bias_instability": math.sqrt(b2),
        "random_walk": math.sqrt(k2),
        "fitted": np.sqrt(basis.dot(coef)),
    }


def _nnls(a, b):
    """Least squares a x = b with x >= 0 (3 unknowns: the best of every subset of free terms)."""
    best, best_cost = np.zeros(a.shape[1]), float(np.sum(b * b))
    cols = a.shape[1]
    for mask in range(1, 1 << cols):
        idx = [j for j in range(cols) if mask & (1 << j)]
        x, _, _, _ = np.linalg.lstsq(a[:, idx], b, rcond=None)
        if np.any(x < 0.0):
            continue
        full = np.zeros(cols)
        full[idx] = x
        cost = float(np.sum((a.dot(full) - b) ** 2))
        if cost < best_cost:
            best, best_cost = full, cost
    return best


def analyse(stamps, gyro, accel):
    """Allan deviation and fits of an IMU recording.

    stamps [s] (n,), gyro and accel (n, 3). The rate is the median sample spacing; a recording
    with gaps (a spacing over 1.5 of it) or out of order raises ValueError, since the estimator
    needs equally spaced samples.
    Returns a dict: rate, samples, duration, taus, and per sensor ("gyro", "accel") per axis
    ("x", "y", "z"): adev and the fit_noise() result.
    """
    stamps = np.asarray(stamps, dtype=float)
    if len(stamps) < 20:
        raise ValueError("need at least 20 samples, got %d" % len(stamps))
    dt = np.diff(stamps)
    period = float(np.median(dt))
    if not period > 0.0:
        raise ValueError("the stamps do not increase (median spacing %g s)" % period)
    gaps = int(np.sum((dt > 1.5 * period) | (dt <= 0.0)))
    if gaps:
        raise ValueError("%d gaps or repeats in the stamps (spacing not %.6f s): the Allan deviation needs "
                         "an unbroken recording" % (gaps, period))
    rate = 1.0 / period
    out = {"rate": rate, "samples": len(stamps), "duration": len(stamps) * period}
    for name, data in (("gyro", gyro), ("accel", accel)):
        taus, adev = allan_deviation(np.asarray(data, dtype=float), rate)
        out["taus"] = taus
        out[name] = {}
        for i, axis in enumerate("xyz"):
            fit = fit_noise(taus, adev[:, i], len(stamps), rate)
            fit["adev"] = adev[:, i]
            out[name][axis] = fit
    return out


UNITS = {"gyro": ("rad/s/sqrt(Hz)", "rad/s", "rad/s^2/sqrt(Hz)"),
         "accel": ("m/s^2/sqrt(Hz)", "m/s^2", "m/s^3/sqrt(Hz)")}


def table(result):
    """The fitted parameters as text, one line per sensor and axis."""
    header = ("sensor", "axis", "white noise density N", "bias instability B", "random walk K")
    lines = ["%d samples at %.1f Hz (%.1f s)" % (result["samples"], result["rate"], result["duration"]),
             "%-6s %-4s %-26s %-22s %-26s" % header]
    for sensor in ("gyro", "accel"):
        n_unit, b_unit, k_unit = UNITS[sensor]
        for axis in "xyz":
            f = result[sensor][axis]
            lines.append("%-6s %-4s %-26s %-22s %-26s" % (
                sensor, axis, "%.4g %s" % (f["white_noise_density"], n_unit),
                "%.4g %s" % (f["bias_instability"], b_unit), "%.4g %s" % (f["random_walk"], k_unit)))
    return "\n".join(lines)


def summary(result):
    """The parameters as plain data (for --json)."""
    out = {"rate": result["rate"], "samples": result["samples"], "duration": result["duration"]}
    for sensor in ("gyro", "accel"):
        out[sensor] = {axis: {key: result[sensor][axis][key]
                              for key in ("white_noise_density", "bias_instability", "random_walk")}
                       for axis in "xyz"}
    return out


def plot(result, path, title=""):
    """Allan deviation curves with the fitted -1/2 and +1/2 lines, gyro and accel, to a PNG."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    taus = result["taus"]
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    for ax, sensor in zip(axes, ("gyro", "accel")):
        n_unit, _, k_unit = UNITS[sensor]
        for axis, colour in zip("xyz", ("tab:red", "tab:green", "tab:blue")):
            f = result[sensor][axis]
            ax.loglog(taus, f["adev"], color=colour, label="%s %s" % (sensor, axis))
            ax.loglog(taus, f["white_noise_density"] / np.sqrt(taus), "--", color=colour, linewidth=0.8)
            if f["random_walk"] > 0.0:
                ax.loglog(taus, f["random_walk"] * np.sqrt(taus / 3.0), ":", color=colour, linewidth=0.8)
        ax.set_xlabel("cluster time tau [s]")
        ax.set_ylabel("Allan deviation [%s]" % ("rad/s" if sensor == "gyro" else "m/s^2"))
        ax.set_title("%s: -- N/sqrt(tau) (N at tau=1 s), : K sqrt(tau/3) (K at tau=3 s)" % sensor, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def read_imu_bag(path, topic):
    """(stamps, gyro, accel) of the sensor_msgs/Imu messages on `topic` in a rosbag, by header
    stamp. Raises ValueError naming the problem (no such file, not a bag, no such topic, another
    message type, too few messages)."""
    import os

    import rosbag

    if not os.path.isfile(path):
        raise ValueError("%s: no such file" % path)
    try:
        bag = rosbag.Bag(path)
    except Exception as error:  # rosbag raises several types for a file that is not a bag
        raise ValueError("%s: not a readable rosbag (%s)" % (path, error))
    with bag:
        topics = bag.get_type_and_topic_info().topics
        if topic not in topics:
            raise ValueError("%s: no topic %s (topics: %s)" % (path, topic, ", ".join(sorted(topics)) or "none"))
        if topics[topic].msg_type != "sensor_msgs/Imu":
            raise ValueError("%s: %s is %s, expected sensor_msgs/Imu" % (path, topic, topics[topic].msg_type))
        rows = []
        for _, msg, _ in bag.read_messages(topics=[topic]):
            w, a = msg.angular_velocity, msg.linear_acceleration
            rows.append((msg.header.stamp.to_sec(), w.x, w.y, w.z, a.x, a.y, a.z))
    if len(rows) < 20:
        raise ValueError("%s: %d messages on %s, need at least 20" % (path, len(rows), topic))
    data = np.array(sorted(rows))
    return data[:, 0], data[:, 1:4], data[:, 4:7]
