# savings.planar (include/joint_load_estimator/planar.hpp): the planar 3x3 path against
# the 6x6 one and the paper's planar foot.
if(CATKIN_ENABLE_TESTING)
  jle_add_unit_test(test_planar test/unit/test_planar.cpp)
endif()
