# Map server and localization (fake from ground truth, particle filter) of mbot_navigation.
# Included at the end of CMakeLists.txt, after catkin_package() and include_directories().

# ---- cores: likelihood field, motion and laser models, particle filter, localizer -- no ROS types
add_library(mbot_localization
  src/likelihood_field.cpp
  src/localization_models.cpp
  src/particle_filter.cpp
  src/localization_core.cpp)
target_compile_options(mbot_localization PRIVATE -Wall -Wextra)

# ---- ROS edge shared by the nodes: strict parameters, message conversions
add_library(mbot_localization_ros src/localization_ros.cpp)
target_compile_options(mbot_localization_ros PRIVATE -Wall -Wextra)
target_link_libraries(mbot_localization_ros mbot_localization ${catkin_LIBRARIES})
add_dependencies(mbot_localization_ros ${catkin_EXPORTED_TARGETS})

# ---- nodes
add_executable(fake_localization src/fake_localization_node.cpp)
add_executable(pf_localization src/pf_localization_node.cpp)
foreach(node fake_localization pf_localization)
  target_compile_options(${node} PRIVATE -Wall -Wextra)
  target_link_libraries(${node} mbot_localization_ros mbot_localization ${catkin_LIBRARIES})
  add_dependencies(${node} ${catkin_EXPORTED_TARGETS})
endforeach()

# The map server reads maps with mbot_common's loader (mbot_common::loadMap, in catkin_LIBRARIES),
# the one the simulator uses too.
find_package(roslib REQUIRED)  # ros::package::getPath, to find the workspace maps/ folder
add_executable(map_server src/map_server_node.cpp)
target_compile_options(map_server PRIVATE -Wall -Wextra)
target_include_directories(map_server PRIVATE ${roslib_INCLUDE_DIRS})
target_link_libraries(map_server mbot_localization_ros mbot_localization ${roslib_LIBRARIES} ${catkin_LIBRARIES})
add_dependencies(map_server ${catkin_EXPORTED_TARGETS})

install(TARGETS mbot_localization mbot_localization_ros
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(TARGETS fake_localization pf_localization map_server
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# ---- tests: gtest without a master, rostests with one
if(CATKIN_ENABLE_TESTING)
  mbot_add_gtest(test_particle_filter mbot_localization)

  find_package(rostest REQUIRED)
  add_rostest(test/fake_localization.test)
  add_rostest(test/pf_localization.test)
  add_rostest(test/map_server.test)
endif()
