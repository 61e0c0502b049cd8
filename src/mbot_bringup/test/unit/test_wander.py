"""The wander behaviour drives when clear, never drives into something close ahead."""
import math

from mbot_bringup.wander import WanderConfig, side_clearance, wander_command

BEAMS = 360
ANGLE_MIN = -math.pi
INC = 2 * math.pi / BEAMS


def scan_with(obstacles, default=float("inf")):
    """A 360-beam scan; obstacles maps a bearing [deg] -> range [m] (applied within +-5 deg)."""
    ranges = [default] * BEAMS
    for i in range(BEAMS):
        a = math.degrees(ANGLE_MIN + i * INC)
        for bearing, r in obstacles.items():
            if abs((a - bearing + 180) % 360 - 180) <= 5:
                ranges[i] = r
    return ranges


def test_open_space_drives_straight_at_speed():
    cfg = WanderConfig(speed=0.3)
    v, w = wander_command(scan_with({}), ANGLE_MIN, INC, cfg)
    assert v == 0.3
    assert w == 0.0


def test_wall_ahead_stops_and_turns_to_the_open_side():
    cfg = WanderConfig(speed=0.3, safe_distance=0.6, turn_rate=1.0)
    ranges = scan_with({0: 0.4, 30: 0.5, -60: 0.3})   # right side more cluttered
    v, w = wander_command(ranges, ANGLE_MIN, INC, cfg)
    assert v == 0.0
    assert w == 1.0   # turn left


def test_too_close_reading_counts_as_blocked():
    ranges = scan_with({0: float("-inf")})
    v, _ = wander_command(ranges, ANGLE_MIN, INC)
    assert v == 0.0
    assert side_clearance(ranges, ANGLE_MIN, INC, -0.1, 0.1) == 0.0


def test_side_clearance_reads_the_nearest_finite_range_in_the_sector():
    ranges = scan_with({90: 1.5, 100: 2.5})
    assert side_clearance(ranges, ANGLE_MIN, INC, math.radians(80), math.radians(110)) == 1.5
    assert side_clearance(ranges, ANGLE_MIN, INC, -0.5, 0.5, far=9.0) == 9.0
