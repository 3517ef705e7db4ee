# The soak (test/soak/soak.cpp): 1e6 samples through JointStateMap + Estimator with bad
# messages mixed in; checks flat memory and exact counts. Built with `tests` (catkin puts
# it in devel/lib/joint_load_estimator/soak); run by tools/test.sh.
if(CATKIN_ENABLE_TESTING)
  add_executable(soak test/soak/soak.cpp)
  target_link_libraries(soak joint_load_estimator_ros)
  target_compile_definitions(soak PRIVATE JLE_TEST_DATA="${CMAKE_CURRENT_SOURCE_DIR}/test/data")
  if(TARGET tests)
    add_dependencies(tests soak)
  endif()
endif()
