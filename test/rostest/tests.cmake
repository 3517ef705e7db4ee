# Node tests: rostest launch files (test/rostest/*.test) that start the real
# joint_load_estimator node beside a gtest node driving it through its topics.
# Included at the end of CMakeLists.txt, after the targets exist.
if(CATKIN_ENABLE_TESTING)
  find_package(rostest REQUIRED)

  # jle_add_node_test(<gtest target> <launch file in test/rostest> <sources...>)
  function(jle_add_node_test target launch_file)
    add_rostest_gtest(${target} test/rostest/${launch_file} ${ARGN})
    target_link_libraries(${target} joint_load_estimator_core ${catkin_LIBRARIES})
    target_include_directories(${target} PRIVATE include ${catkin_INCLUDE_DIRS})
    # The launch file starts the node: build it with the test.
    add_dependencies(${target} joint_load_estimator_node ${PROJECT_NAME}_generate_messages_cpp)
    target_compile_definitions(${target} PRIVATE
      JLE_TEST_DATA="${CMAKE_CURRENT_SOURCE_DIR}/test/data"
      JLE_ROSTEST_DIR="${CMAKE_CURRENT_SOURCE_DIR}/test/rostest"
      JLE_NODE="$<TARGET_FILE:joint_load_estimator_node>")
  endfunction()

  jle_add_node_test(test_node_loads loads.test test/rostest/test_loads.cpp)
  jle_add_node_test(test_node_inputs inputs.test test/rostest/test_inputs.cpp)
  jle_add_node_test(test_node_bad_config bad_config.test test/rostest/test_bad_config.cpp)
  jle_add_node_test(test_node_agreement agreement.test test/rostest/test_agreement.cpp)
  target_compile_definitions(test_node_agreement PRIVATE JLE_PROCESS_BAG="$<TARGET_FILE:process_bag>")
  add_dependencies(test_node_agreement process_bag)
endif()
