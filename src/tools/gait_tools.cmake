# The gait demo (included at the end of CMakeLists.txt, after the targets):
# make_gait_bag (a walking trial over two force plates, as a bag) and its tests.

add_executable(make_gait_bag src/tools/make_gait_bag.cpp)
target_link_libraries(make_gait_bag joint_load_estimator_ros)

install(TARGETS make_gait_bag RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # The demo's check on the real node: the pelvis residual of the gait bag is filter
  # error only, and every joint gets its loads (test/rostest/gait.test).
  jle_add_node_test(test_node_gait gait.test test/rostest/test_gait.cpp)
  target_link_libraries(test_node_gait joint_load_estimator_ros)
  target_compile_definitions(test_node_gait PRIVATE
    JLE_MAKE_GAIT_BAG="$<TARGET_FILE:make_gait_bag>")
  add_dependencies(test_node_gait make_gait_bag)

  # The same trial as a CSV file through joint_loads (the offline path for a trial of
  # one's own).
  jle_add_unit_test(test_gait_csv test/unit/test_gait_csv.cpp)
  target_compile_definitions(test_gait_csv PRIVATE
    JLE_MAKE_GAIT_BAG="$<TARGET_FILE:make_gait_bag>")
  add_dependencies(test_gait_csv make_gait_bag joint_loads)
endif()
