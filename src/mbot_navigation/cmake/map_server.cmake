# The map server of mbot_navigation (map_server's place, beside move_base; the localization is
# its own package, mbot_localization). Included at the end of CMakeLists.txt, after
# catkin_package() and include_directories().

# Maps are read with mbot_common's loader (mbot_common::loadMap, in catkin_LIBRARIES), the one the
# simulator uses too; strict parameters are mbot_common/ros_edge.h (header-only).
# roslib (found in CMakeLists.txt): ros::package::getPath, to find the workspace maps/ folder
add_executable(map_server src/map_server_node.cpp)
target_compile_options(map_server PRIVATE -Wall -Wextra)
target_include_directories(map_server PRIVATE ${roslib_INCLUDE_DIRS})
target_link_libraries(map_server ${roslib_LIBRARIES} ${catkin_LIBRARIES})
add_dependencies(map_server ${catkin_EXPORTED_TARGETS})

install(TARGETS map_server RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  add_rostest(test/map_server.test)
endif()
