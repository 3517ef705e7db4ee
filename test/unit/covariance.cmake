# Covariance of the published joint wrenches (issue 8): the propagation in the core,
# its Monte Carlo check and the filters' noise gains.
if(CATKIN_ENABLE_TESTING)
  jle_add_unit_test(test_covariance test/unit/test_covariance.cpp)
endif()
