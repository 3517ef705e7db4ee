# Covariance of the published joint wrenches (issue 8): the propagation in the core,
# its Monte Carlo check and the filters' noise gains.
target_sources(joint_load_estimator_core PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/core/covariance.cpp)
if(CATKIN_ENABLE_TESTING)
  jle_add_unit_test(test_covariance test/unit/test_covariance.cpp)
endif()
