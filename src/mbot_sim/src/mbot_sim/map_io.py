"""Read occupancy map images in map_server's PGM format, for Python tools (plots, tests).

The simulator and the map server read maps with the C++ `mbot_sim::loadMap` (map_io.h); this is
the same file format for Python code that only needs the pixels.
"""
import numpy as np


def read_pgm(path):
    """A binary (P5) or ASCII (P2) PGM as a 2D uint8 array, first row = top of the image."""
    with open(path, "rb") as f:
        data = f.read()
    tokens = []
    pos = 0
    while len(tokens) < 4:  # magic, width, height, maxval; '#' starts a comment
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        tokens.append(data[pos:end].decode("ascii"))
        pos = end
    magic, width, height, maxval = tokens[0], int(tokens[1]), int(tokens[2]), int(tokens[3])
    if magic == "P5":
        pixels = np.frombuffer(data, dtype=np.uint8, count=width * height, offset=pos + 1)
    elif magic == "P2":
        pixels = np.array(data[pos:].split()[: width * height], dtype=np.int32)
    else:
        raise ValueError("%s: not a PGM image (magic %r, expected P5 or P2)" % (path, magic))
    return (pixels.reshape(height, width) * (255.0 / maxval)).astype(np.uint8)
