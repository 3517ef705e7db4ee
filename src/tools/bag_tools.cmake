# Bag tools and the demo (included at the end of CMakeLists.txt, after the targets):
# make_example_bag (a deterministic example bag), process_bag (the node's estimate over
# a bag, offline), summarize_loads (a table of the loads a node publishes), their test.

add_executable(make_example_bag src/tools/make_example_bag.cpp)
target_link_libraries(make_example_bag joint_load_estimator_ros)

add_executable(process_bag src/tools/process_bag.cpp)
target_link_libraries(process_bag joint_load_estimator_ros)

add_executable(summarize_loads src/tools/summarize_loads.cpp)
target_link_libraries(summarize_loads joint_load_estimator_ros)

install(TARGETS make_example_bag process_bag summarize_loads
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_process_bag test/unit/test_process_bag.cpp)
  target_link_libraries(test_process_bag joint_load_estimator_ros ${catkin_LIBRARIES})
  target_compile_definitions(test_process_bag PRIVATE
    JLE_TEST_DATA="${CMAKE_CURRENT_SOURCE_DIR}/test/data"
    JLE_PROCESS_BAG="$<TARGET_FILE:process_bag>"
    JLE_MAKE_EXAMPLE_BAG="$<TARGET_FILE:make_example_bag>")
  add_dependencies(test_process_bag process_bag make_example_bag)
endif()
