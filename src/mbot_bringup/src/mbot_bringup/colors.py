"""One colour per robot, the same in the simulator's markers, the rviz view and the report."""
import math


def robot_colors(robots, world_robots):
    """{robot: (r, g, b)}: the simulator's marker colour of its index in the world file (robots
    the world does not name follow on), darkened to 80 %; from the 7th robot on the hues shift by
    half a step so that no two of 12 robots share one."""
    order = list(world_robots) + [r for r in robots if r not in world_robots]
    colors = {}
    for r in robots:
        i = order.index(r)
        hue = ((i % 6) + 0.5 * ((i // 6) % 2)) / 6.0
        rgb = [0.5 + 0.5 * math.cos(2.0 * math.pi * (hue - k / 3.0)) for k in range(3)]
        colors[r] = tuple(0.8 * c for c in rgb)
    return colors
