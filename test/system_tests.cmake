# The system tests: the link test, the Python bindings, the rostest node tests and the
# soaks; included by CMakeLists.txt when JLE_SYSTEM_TESTS is on (the default). They run
# on the Release build (tools/test.sh: catkin run_tests and the soak stages).

# --- The link test: a client compiled with -march=native (or -mavx2) against the core
# library as built with the project's flags (its Eigen alignment exported: CMakeLists.txt)
# must give the loads the test itself computes. Skipped, saying why, on a CPU without AVX.
include(CheckCXXCompilerFlag)
check_cxx_compiler_flag(-march=native JLE_HAVE_MARCH_NATIVE)
check_cxx_compiler_flag(-mavx2 JLE_HAVE_MAVX2)
jle_add_unit_test(test_link_client link/test_link_client.cpp)
set(JLE_LINK_FLAG "")
if(JLE_HAVE_MARCH_NATIVE)
  set(JLE_LINK_FLAG -march=native)
elseif(JLE_HAVE_MAVX2)
  set(JLE_LINK_FLAG -mavx2)
endif()
if(JLE_LINK_FLAG)
  add_executable(link_client EXCLUDE_FROM_ALL link/link_client.cpp)
  target_link_libraries(link_client joint_load_estimator_core)
  target_compile_options(link_client PRIVATE ${JLE_LINK_FLAG})
  add_dependencies(test_link_client link_client)
  target_compile_definitions(test_link_client PRIVATE
    JLE_LINK_CLIENT="$<TARGET_FILE:link_client>" JLE_LINK_CLIENT_FLAGS="${JLE_LINK_FLAG}")
endif()

# --- The Python bindings (pytest, python3-pytest) ----------------------------------
# joint_load_estimator (src/python) against joint_loads and process_bag on the same inputs
# (to 1e-12) and a closed form; the gait demo's peak table (tools/gait_peaks.py, with
# make_gait_bag) against the docs; rviz for any robot (estimator.launch rviz:=true, on Xvfb,
# its screenshot's pixels: test_rviz.py, with make_example_bag); run in the workspace's
# environment (devel/env.sh puts the devel Python path first), its JUnit file where
# catkin_test_results reads it.
set(JLE_PYTEST_RESULT ${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/pytest-bindings.xml)
catkin_run_tests_target(pytest bindings pytest-bindings.xml
  COMMAND "JLE_TEST_DATA=${JLE_TEST_DATA} JLE_JOINT_LOADS=$<TARGET_FILE:joint_loads> \
JLE_PROCESS_BAG=$<TARGET_FILE:process_bag> JLE_MAKE_EXAMPLE_BAG=$<TARGET_FILE:make_example_bag> \
JLE_MAKE_GAIT_BAG=$<TARGET_FILE:make_gait_bag> JLE_NODE=$<TARGET_FILE:joint_load_estimator_node> \
/usr/bin/python3 -m pytest -q -p no:cacheprovider ${PROJECT_SOURCE_DIR}/test/python \
--junitxml=${JLE_PYTEST_RESULT}"
  DEPENDENCIES joint_load_estimator_python joint_load_estimator_python_bag joint_loads
  process_bag make_example_bag make_gait_bag joint_load_estimator_node)

# --- Node tests (rostest) -----------------------------------------------------------
jle_add_node_test(test_node_loads loads.test rostest/test_loads.cpp)
jle_add_node_test(test_node_inputs inputs.test rostest/test_inputs.cpp)
jle_add_node_test(test_node_bad_config bad_config.test rostest/test_bad_config.cpp)
# Hostile inputs (issue 14): every message used or counted, diagnostics on their own timer.
jle_add_node_test(test_node_hostile hostile.test rostest/test_hostile.cpp)
# External efforts of the running node: ~contact, ~external_wrench/<link>, diagnostics.
jle_add_node_test(test_node_external external.test rostest/test_external.cpp)
target_link_libraries(test_node_external joint_load_estimator_testing ${orocos_kdl_LIBRARIES}
  ${kdl_parser_LIBRARIES})
target_include_directories(test_node_external PRIVATE ${orocos_kdl_INCLUDE_DIRS}
  ${kdl_parser_INCLUDE_DIRS})
# One message path: the node under rosbag play and process_bag on the same bag agree.
jle_add_node_test(test_node_agreement agreement.test rostest/test_agreement.cpp)
target_compile_definitions(test_node_agreement PRIVATE JLE_PROCESS_BAG="$<TARGET_FILE:process_bag>")
add_dependencies(test_node_agreement process_bag)
jle_add_node_test(test_node_plates plates.test rostest/test_plates.cpp)
# The node's sensor and base residuals and the bias calibration service.
jle_add_node_test(test_node_consistency consistency.test rostest/test_consistency.cpp)
target_link_libraries(test_node_consistency joint_load_estimator_testing)
# The gait demo on the real node: the pelvis residual of the gait bag is filter error
# only, and every joint gets its loads.
jle_add_node_test(test_node_gait gait.test rostest/test_gait.cpp)
target_link_libraries(test_node_gait joint_load_estimator_ros)
target_compile_definitions(test_node_gait PRIVATE
  JLE_MAKE_GAIT_BAG="$<TARGET_FILE:make_gait_bag>")
add_dependencies(test_node_gait make_gait_bag)

# launch/estimator.launch in a namespace with a remap (URDF from a file and from an
# existing parameter), ~joint_efforts, ~reconfigure (dynamic_reconfigure).
jle_add_node_test(test_node_any_robot any_robot.test rostest/test_any_robot.cpp)

# --- Soaks (run by tools/test.sh, built with `tests`) -------------------------------
# 1e6 samples through JointStateMap + Estimator with bad messages mixed in; checks flat
# memory and exact counts.
add_executable(soak soak/soak.cpp)
target_link_libraries(soak joint_load_estimator_ros)
target_compile_definitions(soak PRIVATE JLE_TEST_DATA="${JLE_TEST_DATA}")
add_dependencies(tests soak)
# The real node over ROS (soak/node_soak.sh): 1e6 joint states with bad messages mixed
# in, driven by node_soak (a roscpp driver).
add_executable(node_soak soak/node_soak.cpp)
target_link_libraries(node_soak joint_load_estimator_ros)
add_dependencies(node_soak joint_load_estimator_node)
add_dependencies(tests node_soak)
# Programs of the tests, not of the package: out of `all` (bench/CMakeLists.txt).
set_target_properties(soak node_soak PROPERTIES EXCLUDE_FROM_ALL TRUE)
