# The move_base-compatible nav node of mbot_navigation, its Python modules (fleet launcher,
# navigation trial) and its tests. Included at the end of CMakeLists.txt, after catkin_package()
# and include_directories().

# mbot_description (robot_model.h) and roslib (ros::package::getPath) are found in CMakeLists.txt.

# (catkin_python_setup() is in CMakeLists.txt: it must come before the dynamic_reconfigure options.)

# ---- cores: goal checks, recovery behaviours, move_base's state machine -- no ROS types
add_library(mbot_nav_core src/goal_checks.cpp src/recovery.cpp src/navigator.cpp)
target_compile_options(mbot_nav_core PRIVATE -Wall -Wextra)
target_link_libraries(mbot_nav_core mbot_global_planner mbot_local_planner mbot_costmap)

# ---- the ROS edge: costmaps (costmap_ros), the move_base interface (nav_node); main() is thin
add_library(mbot_nav_ros src/costmap_ros.cpp src/move_base_params.cpp src/nav_node.cpp)
target_compile_options(mbot_nav_ros PRIVATE -Wall -Wextra)
target_include_directories(mbot_nav_ros PRIVATE ${mbot_description_INCLUDE_DIRS} ${roslib_INCLUDE_DIRS})
target_link_libraries(mbot_nav_ros mbot_nav_core
  ${mbot_description_LIBRARIES} ${roslib_LIBRARIES} ${catkin_LIBRARIES})
add_dependencies(mbot_nav_ros ${catkin_EXPORTED_TARGETS} ${PROJECT_NAME}_gencfg)
add_executable(nav_node src/nav_node_main.cpp)
target_link_libraries(nav_node mbot_nav_ros ${catkin_LIBRARIES})
# The same node as `move_base`: a move_base launch file works after pkg="move_base" ->
# pkg="mbot_navigation" (type="move_base" stays).
add_executable(mbot_move_base src/nav_node_main.cpp)
set_target_properties(mbot_move_base PROPERTIES OUTPUT_NAME move_base)
target_link_libraries(mbot_move_base mbot_nav_ros ${catkin_LIBRARIES})

install(TARGETS mbot_nav_core mbot_nav_ros nav_node mbot_move_base
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

  # the parameter reader against a parameter server (move_base's key sets; no simulator)
  add_rostest_gtest(test_move_base_params test/move_base_params.test test/test_move_base_params.cpp)
  target_link_libraries(test_move_base_params mbot_nav_ros ${catkin_LIBRARIES})
  find_package(mbot_sim QUIET)
  if(mbot_sim_FOUND)
    add_rostest(test/nav_office.test)
    add_rostest(test/nav_bad_goals.test)
    add_rostest(test/nav_corridor.test)
    add_rostest(test/nav_tutorial_client.test)
    add_rostest(test/nav_office_ompl.test)
    add_rostest(test/nav_move_base_dropin.test)
    add_rostest(test/nav_reconfigure.test)
    add_rostest(test/nav_services.test)
    add_rostest(test/nav_omni.test)
    add_rostest(test/nav_oscillation.test)
  endif()
endif()
