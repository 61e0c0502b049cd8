# The move_base-compatible nav node of mbot_navigation, its Python modules (fleet launcher,
# navigation trial) and its tests. Included at the end of CMakeLists.txt, after catkin_package()
# and include_directories().

find_package(mbot_description REQUIRED)  # robot_model.h: footprint radius and limits
find_package(roslib REQUIRED)            # ros::package::getPath("mbot_description")

# src/mbot_navigation (fleet_launch.py, nav_trial.py). catkin_python_setup() is documented to come
# before catkin_package(); catkin (0.8) only requires it before generate_messages(), which this
# package does not call, so it can live here with the rest of the nav node's build.
catkin_python_setup()

# ---- cores: goal checks, recovery behaviours, move_base's state machine -- no ROS types
add_library(mbot_nav_core src/goal_checks.cpp src/recovery.cpp src/navigator.cpp)
target_compile_options(mbot_nav_core PRIVATE -Wall -Wextra)
target_link_libraries(mbot_nav_core mbot_global_planner mbot_local_planner mbot_costmap)

# ---- the ROS edge: costmaps (costmap_ros), the move_base interface (nav_node); main() is thin
add_library(mbot_nav_ros src/costmap_ros.cpp src/nav_node.cpp)
target_compile_options(mbot_nav_ros PRIVATE -Wall -Wextra)
target_include_directories(mbot_nav_ros PRIVATE ${mbot_description_INCLUDE_DIRS} ${roslib_INCLUDE_DIRS})
target_link_libraries(mbot_nav_ros mbot_nav_core
  ${mbot_description_LIBRARIES} ${roslib_LIBRARIES} ${catkin_LIBRARIES})
add_dependencies(mbot_nav_ros ${catkin_EXPORTED_TARGETS})
add_executable(nav_node src/nav_node_main.cpp)
target_link_libraries(nav_node mbot_nav_ros ${catkin_LIBRARIES})

install(TARGETS mbot_nav_core mbot_nav_ros nav_node
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
catkin_install_python(PROGRAMS nodes/fleet_navigation scripts/nav_trial
  DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(DIRECTORY launch config DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})

# ---- tests: cores without a master (gtest); the node with the simulator (rostest)
if(CATKIN_ENABLE_TESTING)
  mbot_add_gtest(test_nav_core mbot_nav_core)
  mbot_add_gtest(test_nav_costmap_ros mbot_nav_ros)

  find_package(rostest REQUIRED)
  find_package(mbot_sim QUIET)
  if(mbot_sim_FOUND)
    add_rostest(test/nav_office.test)
    add_rostest(test/nav_bad_goals.test)
    add_rostest(test/nav_corridor.test)
    add_rostest(test/nav_tutorial_client.test)
    add_rostest(test/nav_office_ompl.test)
  endif()
endif()
