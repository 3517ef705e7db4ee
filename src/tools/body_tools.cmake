# The human body model (included at the end of CMakeLists.txt, after the targets):
# make_body_urdf (a lower-body URDF from body mass and height, docs/body_model.md), its
# tests, and the force-plate sign tests.

add_executable(make_body_urdf src/tools/make_body_urdf.cpp)
target_link_libraries(make_body_urdf joint_load_estimator_core)
install(TARGETS make_body_urdf RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  jle_add_unit_test(test_body test/unit/test_body.cpp)
  target_compile_definitions(test_body PRIVATE JLE_MAKE_BODY_URDF="$<TARGET_FILE:make_body_urdf>")
  add_dependencies(test_body make_body_urdf)
  # KDL (robot_state_publisher's reader) reads the same tree.
  target_link_libraries(test_body ${orocos_kdl_LIBRARIES} ${kdl_parser_LIBRARIES})
  target_include_directories(test_body PRIVATE ${orocos_kdl_INCLUDE_DIRS} ${kdl_parser_INCLUDE_DIRS})
  jle_add_unit_test(test_force_plate test/unit/test_force_plate.cpp)
endif()
