# The accuracy study (bench/accuracy.cpp, tools/accuracy.sh) and the ground-truth test.
# Built with the tests: `catkin_make tests` or the target by name.
if(CATKIN_ENABLE_TESTING)
  # ground_truth.cpp belongs in joint_load_estimator_core; until it is listed there, the
  # targets below compile it themselves.
  get_target_property(_jle_core_sources joint_load_estimator_core SOURCES)
  set(_jle_ground_truth)
  if(NOT "src/core/ground_truth.cpp" IN_LIST _jle_core_sources)
    set(_jle_ground_truth src/core/ground_truth.cpp)
  endif()

  add_executable(accuracy bench/accuracy.cpp ${_jle_ground_truth})
  target_link_libraries(accuracy joint_load_estimator_core)
  target_compile_definitions(accuracy PRIVATE
    JLE_ACCURACY_DATA="${CMAKE_CURRENT_SOURCE_DIR}/test/data")
  add_dependencies(tests accuracy)

  if(NOT TARGET test_ground_truth)
    jle_add_unit_test(test_ground_truth test/unit/test_ground_truth.cpp ${_jle_ground_truth})
  endif()
endif()
