# Force plates (issue 7): the node tests (plates.test) and the unit tests of the
# estimator's plate path. Included at the end of CMakeLists.txt, after tests.cmake.
if(CATKIN_ENABLE_TESTING)
  jle_add_node_test(test_node_plates plates.test test/rostest/test_plates.cpp)
  jle_add_unit_test(test_plates test/unit/test_plates.cpp)
endif()
