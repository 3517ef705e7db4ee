# The node soak (test/soak/node_soak.sh): the real joint_load_estimator node over ROS,
# 1e6 joint states with bad messages mixed in, driven by node_soak (a roscpp driver).
# Built with `tests` (devel/lib/joint_load_estimator/node_soak); run by tools/test.sh.
if(CATKIN_ENABLE_TESTING)
  add_executable(node_soak test/soak/node_soak.cpp)
  target_link_libraries(node_soak joint_load_estimator_ros)
  add_dependencies(node_soak joint_load_estimator_node)
  if(TARGET tests)
    add_dependencies(tests node_soak)
  endif()
endif()
