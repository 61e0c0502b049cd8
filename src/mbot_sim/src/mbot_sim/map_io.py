"""Kept for callers not switched over yet: PGM images are read by mbot_common.maps (read_pgm,
and load_map for a whole map_server map), the same reader the C++ tools share."""
from mbot_common.maps import read_pgm  # noqa: F401
