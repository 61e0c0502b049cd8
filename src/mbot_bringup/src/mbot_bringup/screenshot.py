"""Capture the whole X display (rviz under Xvfb) as a PNG, and check that it shows something."""
import subprocess

import numpy as np


def capture(display, path):
    """Save a screenshot of X display `display` (e.g. ":99") to `path` with ImageMagick's import."""
    subprocess.run(["import", "-display", display, "-window", "root", path], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=60)
    return path


def looks_rendered(path, min_colors=16):
    """True when the image has at least `min_colors` distinct colours (a blank or black window
    has one or two)."""
    import matplotlib.image as mpimg
    img = mpimg.imread(path)
    flat = (img[..., :3].reshape(-1, 3) * 255).astype(np.uint8)
    return len(np.unique(flat[:: max(1, len(flat) // 200000)], axis=0)) >= min_colors
