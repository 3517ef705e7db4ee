# Force plates (issue 7): the node tests (plates.test), the unit tests of the
# estimator's plate path, and the settings and process_bag with plates. Included at the
# end of CMakeLists.txt, after tests.cmake and bag_tools.cmake.
if(CATKIN_ENABLE_TESTING)
  jle_add_node_test(test_node_plates plates.test test/rostest/test_plates.cpp)
  jle_add_unit_test(test_plates test/unit/test_plates.cpp)

  catkin_add_gtest(test_plates_offline test/unit/test_plates_offline.cpp)
  target_link_libraries(test_plates_offline joint_load_estimator_ros ${catkin_LIBRARIES} gtest_main)
  target_compile_definitions(test_plates_offline PRIVATE
    JLE_ROSTEST_DIR="${CMAKE_CURRENT_SOURCE_DIR}/test/rostest"
    JLE_PROCESS_BAG="$<TARGET_FILE:process_bag>")
  add_dependencies(test_plates_offline process_bag)
endif()
