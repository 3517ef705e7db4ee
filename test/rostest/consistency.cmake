# Predicted against measured (issue 8): the node's sensor and base residuals, the bias
# calibration service, and the core's sensor substitution. Included at the end of
# CMakeLists.txt.

if(CATKIN_ENABLE_TESTING)
  jle_add_unit_test(test_sensor_joint test/unit/test_sensor_joint.cpp)
  jle_add_node_test(test_node_consistency consistency.test test/rostest/test_consistency.cpp)
endif()
