#!/usr/bin/env python3
"""rostest for map_server: /map, /map_metadata and /static_map against fixture maps.

test/fixtures/maps/fixture.pgm is 4 x 3 pixels (top row first in the file):
    0   255 255 128
    255 255 0   255
    255 128 255 0
With occupied_thresh 0.65 and free_thresh 0.196, black (0) is occupied, white (255) free and
grey (128, occupancy 0.498) unknown; with negate: 1 black and white swap roles. The map's row 0
is the image's bottom row (map_server flips the image).
"""
import os
import subprocess
import unittest

import rospy
import rostest
import rospkg
from mbot_common.maps import load_map
from mbot_common.paths import find_maps_directory
from nav_msgs.msg import MapMetaData, OccupancyGrid
from nav_msgs.srv import GetMap
from roslib.packages import find_node

PKG = "mbot_navigation"
TIMEOUT = 30.0  # [s] wall time

# expected cell values, map row 0 (bottom) first
FIXTURE = [0, -1, 0, 100,
           0, 0, 100, 0,
           100, 0, 0, -1]
FIXTURE_NEGATED = [100, -1, 100, 0,
                   100, 100, 0, 100,
                   0, 100, 100, -1]


class MapServerTest(unittest.TestCase):
    def check_info(self, info, width, height, resolution, origin):
        self.assertEqual((info.width, info.height), (width, height))
        self.assertAlmostEqual(info.resolution, resolution, places=6)
        self.assertAlmostEqual(info.origin.position.x, origin[0], places=9)
        self.assertAlmostEqual(info.origin.position.y, origin[1], places=9)
        self.assertAlmostEqual(info.origin.orientation.w, 1.0, places=9)  # yaw 0

    def test_fixture_map_topic_metadata_and_service(self):
        grid = rospy.wait_for_message("/map", OccupancyGrid, timeout=TIMEOUT)
        self.assertEqual(grid.header.frame_id, "map")
        self.check_info(grid.info, 4, 3, 0.1, (-1.0, 2.5))
        self.assertEqual(list(grid.data), FIXTURE)
        # the flip: the image's top-left pixel (black) is the map's top-left cell (0, 2)
        self.assertEqual(grid.data[2 * 4 + 0], 100)
        self.assertEqual(grid.data[0 * 4 + 0], 0)

        meta = rospy.wait_for_message("/map_metadata", MapMetaData, timeout=TIMEOUT)
        self.check_info(meta, 4, 3, 0.1, (-1.0, 2.5))

        rospy.wait_for_service("/static_map", timeout=TIMEOUT)
        served = rospy.ServiceProxy("/static_map", GetMap)().map
        self.assertEqual(served.header.frame_id, "map")
        self.check_info(served.info, 4, 3, 0.1, (-1.0, 2.5))
        self.assertEqual(list(served.data), FIXTURE)

    def test_negated_map_and_frame_id(self):
        grid = rospy.wait_for_message("/negated/map", OccupancyGrid, timeout=TIMEOUT)
        self.assertEqual(grid.header.frame_id, "negated_map")
        self.check_info(grid.info, 4, 3, 0.25, (3.0, -2.0))
        self.assertEqual(list(grid.data), FIXTURE_NEGATED)
        rospy.wait_for_service("/negated/static_map", timeout=TIMEOUT)
        self.assertEqual(list(rospy.ServiceProxy("/negated/static_map", GetMap)().map.data),
                         FIXTURE_NEGATED)

    def test_bare_name_comes_from_workspace_maps(self):
        # the workspace's maps/ folder, found from this package as map_server looks for it
        maps = find_maps_directory(rospkg.RosPack().get_path(PKG))
        expected = load_map(os.path.join(maps, "empty.yaml"))
        grid = rospy.wait_for_message("/bare/map", OccupancyGrid, timeout=TIMEOUT)
        self.check_info(grid.info, expected.width, expected.height, expected.resolution, expected.origin)

    def run_map_server(self, *args):
        binary = find_node(PKG, "map_server")
        self.assertTrue(binary, "map_server executable not found")
        done = subprocess.run([binary[0]] + list(args) + ["__name:=map_server_under_test"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT,
                              universal_newlines=True)
        output = done.stdout + done.stderr
        fatal = [line for line in output.splitlines() if "FATAL" in line]
        return done.returncode, fatal, output

    def test_missing_map_exits_with_its_name(self):
        missing = "/nonexistent/mbot_maps/missing_map.yaml"
        code, fatal, output = self.run_map_server(missing)
        self.assertEqual(code, 1, output)
        self.assertEqual(len(fatal), 1, output)
        self.assertIn(missing, fatal[0])

    def test_invalid_map_names_the_key(self):
        invalid = os.path.join(rospkg.RosPack().get_path(PKG), "test", "fixtures", "maps", "invalid_unknown_key.yaml")
        code, fatal, output = self.run_map_server(invalid)
        self.assertEqual(code, 1, output)
        self.assertEqual(len(fatal), 1, output)
        self.assertIn("invalid_unknown_key.yaml", fatal[0])
        self.assertIn("resolutoin", fatal[0])

    def test_no_map_at_all_is_an_error(self):
        code, fatal, output = self.run_map_server()
        self.assertEqual(code, 1, output)
        self.assertEqual(len(fatal), 1, output)
        self.assertIn("no map given", fatal[0])


if __name__ == "__main__":
    rospy.init_node("test_map_server")
    rostest.rosrun(PKG, "map_server_wiring", MapServerTest)
