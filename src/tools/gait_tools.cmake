# The gait demo (included at the end of CMakeLists.txt, after the targets):
# make_gait_bag (a walking trial over two force plates, as a bag) and its tests.

add_executable(make_gait_bag src/tools/make_gait_bag.cpp)
target_link_libraries(make_gait_bag joint_load_estimator_ros)

install(TARGETS make_gait_bag RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
