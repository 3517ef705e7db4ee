# The unit tests (gtest, no master), included by CMakeLists.txt when JLE_UNIT_TESTS is on
# (the default). tools/test.sh builds and runs them once, under ASan + UBSan
# (tools/sanitize.sh), in a workspace of their own.

# --- Unit tests of the core ---------------------------------------------------------
jle_add_unit_test(test_urdf_reader model/test_urdf_reader.cpp)
target_link_libraries(test_urdf_reader ${urdf_LIBRARIES})
target_include_directories(test_urdf_reader PRIVATE ${urdf_INCLUDE_DIRS})
jle_add_unit_test(test_differentiation filters/test_differentiation.cpp)
# The Kalman smoother (differentiator/lag) against a batch solve written in the test.
jle_add_unit_test(test_smoother filters/test_smoother.cpp)
jle_add_unit_test(test_spectral_cutoff filters/test_spectral_cutoff.cpp)
# The offline zero-phase smoother (zero_phase.hpp) against closed forms.
jle_add_unit_test(test_zero_phase filters/test_zero_phase.cpp)
# joint_loads on positions only against scipy (python3-scipy) and closed-form dynamics.
jle_add_unit_test(test_zero_phase_reference filters/test_zero_phase_reference.cpp)
target_compile_definitions(test_zero_phase_reference PRIVATE
  JLE_TEST_SCRIPTS="${PROJECT_SOURCE_DIR}/test/scripts")
add_dependencies(test_zero_phase_reference joint_loads)
# The zero-phase cutoff on coloured noise against the truth and the best fixed cutoff;
# joint_loads' choice, loads and warnings.
jle_add_unit_test(test_zero_phase_coloured filters/test_zero_phase_coloured.cpp)
add_dependencies(test_zero_phase_coloured joint_loads)
jle_add_unit_test(test_adaptive_differentiator filters/test_adaptive_differentiator.cpp)
jle_add_unit_test(test_estimator algorithms/test_estimator.cpp)
# Measured joint velocities (measured_velocity) against the exact loads of an analytic motion.
jle_add_unit_test(test_measured_velocity filters/test_measured_velocity.cpp)
# The immediate and the smoothed stream of one pipeline against the exact loads.
jle_add_unit_test(test_two_streams pipeline/test_two_streams.cpp)
jle_add_unit_test(test_savings algorithms/test_savings.cpp)
jle_add_unit_test(test_ground_truth algorithms/test_ground_truth.cpp)
# The bounds of the stability sweeps (bench/stability.cpp, docs/studies/stability.md).
jle_add_unit_test(test_stability algorithms/test_stability.cpp)
jle_add_unit_test(test_no_allocation pipeline/test_no_allocation.cpp)
jle_add_unit_test(test_closed_form algorithms/test_closed_form.cpp)
# The forward pass's sin and cos (trig.hpp) against long double.
jle_add_unit_test(test_trig algorithms/test_trig.cpp)
jle_add_unit_test(test_invariance algorithms/test_invariance.cpp)
jle_add_unit_test(test_kdl algorithms/test_kdl.cpp)
target_link_libraries(test_kdl ${orocos_kdl_LIBRARIES} ${kdl_parser_LIBRARIES})
target_include_directories(test_kdl PRIVATE ${orocos_kdl_INCLUDE_DIRS} ${kdl_parser_INCLUDE_DIRS})
# External efforts, the momentum observer and contact wrenches against exact contacts and KDL
jle_add_unit_test(test_external_effort algorithms/test_external_effort.cpp)
target_link_libraries(test_external_effort ${orocos_kdl_LIBRARIES} ${kdl_parser_LIBRARIES})
target_include_directories(test_external_effort PRIVATE ${orocos_kdl_INCLUDE_DIRS}
  ${kdl_parser_INCLUDE_DIRS})
jle_add_unit_test(test_cli tools/test_cli.cpp)
add_dependencies(test_cli joint_loads make_trajectory)
# --help and --version of every executable; rviz_config (read with yaml-cpp and liburdf).
set(JLE_EXECUTABLES joint_load_estimator_node joint_loads make_trajectory make_body_urdf
  make_example_bag process_bag summarize_loads make_gait_bag dh_to_urdf csv_to_bag bag_to_csv)
add_dependencies(test_cli ${JLE_EXECUTABLES})
list(TRANSFORM JLE_EXECUTABLES REPLACE "(.+)" "$<TARGET_FILE:\\1>")
list(APPEND JLE_EXECUTABLES ${PROJECT_SOURCE_DIR}/scripts/rviz_config
  ${PROJECT_SOURCE_DIR}/scripts/joint_labels ${PROJECT_SOURCE_DIR}/scripts/plot_efforts)
string(REPLACE ";" "|" JLE_EXECUTABLES_LIST "${JLE_EXECUTABLES}")
target_compile_definitions(test_cli PRIVATE
  "JLE_EXECUTABLES=\"${JLE_EXECUTABLES_LIST}\""
  JLE_RVIZ_CONFIG="${PROJECT_SOURCE_DIR}/scripts/rviz_config"
  JLE_PACKAGE_XML="${PROJECT_SOURCE_DIR}/package.xml")
target_link_libraries(test_cli ${urdf_LIBRARIES} yaml-cpp)
target_include_directories(test_cli PRIVATE ${urdf_INCLUDE_DIRS})
jle_add_unit_test(test_frames model/test_frames.cpp)
jle_add_unit_test(test_sensor_bias algorithms/test_sensor_bias.cpp)
jle_add_unit_test(test_pipeline pipeline/test_pipeline.cpp)
# The message path's frame resolver against a fake frame source and the URDF's numbers.
jle_add_unit_test(test_frame_resolver pipeline/test_frame_resolver.cpp)
# The time axis of the message path: jumps, rogue stamps, order, ns round trip.
jle_add_unit_test(test_timeline pipeline/test_timeline.cpp)
# The result record: a delayed estimate's own stamp and efforts; the status bits.
jle_add_unit_test(test_record_builder pipeline/test_record_builder.cpp)
jle_add_unit_test(test_never_silent pipeline/test_never_silent.cpp)
jle_add_unit_test(test_sample_clock filters/test_sample_clock.cpp)
# The estimator's parts, each against closed forms.
jle_add_unit_test(test_input_buffer algorithms/test_input_buffer.cpp)
jle_add_unit_test(test_plate_inputs algorithms/test_plate_inputs.cpp)
# JointLoads beside the loads: q, q-dot, q-ddot and the friction motor effort.
jle_add_unit_test(test_outputs algorithms/test_outputs.cpp)
jle_add_unit_test(test_sensor_joints algorithms/test_sensor_joints.cpp)
jle_add_unit_test(test_covariance_parts algorithms/test_covariance_parts.cpp)
jle_add_unit_test(test_base_channels algorithms/test_base_channels.cpp)
jle_add_unit_test(test_config model/test_config.cpp)
# The settings reader (ROS library, no master): ok and ko YAML per key family, the docs.
catkin_add_gtest(test_settings ros/test_settings.cpp)
target_link_libraries(test_settings joint_load_estimator_ros gtest_main)
# GCC 12 at -O1 under the sanitizers (tools/sanitize.sh) reports -Wmaybe-uninitialized
# inside libstdc++'s <regex> (std::function in _NFA's states): warned, not an error.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(test_settings PRIVATE -Wno-error=maybe-uninitialized)
endif()
target_compile_definitions(test_settings PRIVATE
  JLE_TEST_CONFIG="${PROJECT_SOURCE_DIR}/test/config"
  JLE_DEFAULT_YAML="${PROJECT_SOURCE_DIR}/config/default.yaml"
  JLE_RECONFIGURE_CFG="${PROJECT_SOURCE_DIR}/cfg/Estimator.cfg"
  JLE_README="${PROJECT_SOURCE_DIR}/README.md"
  JLE_NODE_DOC="${PROJECT_SOURCE_DIR}/docs/node.md"
  JLE_EXTERNAL_DOC="${PROJECT_SOURCE_DIR}/docs/external_loads.md")
# savings.planar: the planar 3x3 path against the 6x6 one and the paper's planar foot.
jle_add_unit_test(test_planar algorithms/test_planar.cpp)
# The human body model (make_body_urdf, docs/body_model.md), read by KDL too
# (robot_state_publisher's reader), and the force-plate sign conventions.
jle_add_unit_test(test_body model/test_body.cpp)
target_compile_definitions(test_body PRIVATE JLE_MAKE_BODY_URDF="$<TARGET_FILE:make_body_urdf>")
add_dependencies(test_body make_body_urdf joint_loads)
target_link_libraries(test_body ${orocos_kdl_LIBRARIES} ${kdl_parser_LIBRARIES})
target_include_directories(test_body PRIVATE ${orocos_kdl_INCLUDE_DIRS} ${kdl_parser_INCLUDE_DIRS})
jle_add_unit_test(test_force_plate algorithms/test_force_plate.cpp)
# The estimator's force-plate path.
jle_add_unit_test(test_plates algorithms/test_plates.cpp)
# OpenSim storage files, joint_loads' floating base and force plates, process_bag's
# storage output.
jle_add_unit_test(test_offline_formats tools/test_offline_formats.cpp)
target_compile_definitions(test_offline_formats PRIVATE
  JLE_PROCESS_BAG="$<TARGET_FILE:process_bag>"
  JLE_MAKE_EXAMPLE_BAG="$<TARGET_FILE:make_example_bag>")
add_dependencies(test_offline_formats joint_loads process_bag make_example_bag)
# Covariance of the joint wrenches: the propagation, its Monte Carlo check and the
# filters' noise gains.
jle_add_unit_test(test_covariance algorithms/test_covariance.cpp)
# The published sigma through the message path with the node's defaults: the default
# period against every-sample propagation (start-up, gap, loop) and a Monte Carlo.
jle_add_unit_test(test_covariance_pipeline pipeline/test_covariance_pipeline.cpp)
# The core's sensor-joint substitution.
jle_add_unit_test(test_sensor_joint algorithms/test_sensor_joint.cpp)
# dh_to_urdf against Newton-Euler written in the test from the DH equations, and KDL.
jle_add_unit_test(test_dh_to_urdf model/test_dh_to_urdf.cpp)
target_compile_definitions(test_dh_to_urdf PRIVATE JLE_DH_TO_URDF="$<TARGET_FILE:dh_to_urdf>")
add_dependencies(test_dh_to_urdf dh_to_urdf)
target_link_libraries(test_dh_to_urdf ${orocos_kdl_LIBRARIES} ${kdl_parser_LIBRARIES})
target_include_directories(test_dh_to_urdf PRIVATE ${orocos_kdl_INCLUDE_DIRS}
  ${kdl_parser_INCLUDE_DIRS})

# The gait trial as a CSV file through joint_loads.
jle_add_unit_test(test_gait_csv tools/test_gait_csv.cpp)
target_compile_definitions(test_gait_csv PRIVATE
  JLE_MAKE_GAIT_BAG="$<TARGET_FILE:make_gait_bag>")
add_dependencies(test_gait_csv make_gait_bag joint_loads)

# --- Unit tests of the ROS library and the bag tools (no master) --------------------
catkin_add_gtest(test_process_bag tools/test_process_bag.cpp)
target_link_libraries(test_process_bag joint_load_estimator_ros joint_load_estimator_testing
  ${catkin_LIBRARIES} ${orocos_kdl_LIBRARIES} ${kdl_parser_LIBRARIES})
target_include_directories(test_process_bag PRIVATE ${orocos_kdl_INCLUDE_DIRS}
  ${kdl_parser_INCLUDE_DIRS})
target_compile_definitions(test_process_bag PRIVATE
  JLE_TEST_DATA="${JLE_TEST_DATA}"
  JLE_PROCESS_BAG="$<TARGET_FILE:process_bag>"
  JLE_MAKE_EXAMPLE_BAG="$<TARGET_FILE:make_example_bag>")
add_dependencies(test_process_bag process_bag make_example_bag)
# The node's wait for a late transform (Tf2FrameSource, tf_wait).
catkin_add_gtest(test_tf_wait ros/test_tf_wait.cpp)
target_link_libraries(test_tf_wait joint_load_estimator_ros ${catkin_LIBRARIES} gtest_main)
# csv_to_bag and bag_to_csv: the bag's contents, and CSV -> bag -> process_bag -> CSV
# against joint_loads on the same CSV.
catkin_add_gtest(test_csv_to_bag tools/test_csv_to_bag.cpp)
target_link_libraries(test_csv_to_bag joint_load_estimator_ros joint_load_estimator_testing
  ${catkin_LIBRARIES} gtest_main)
target_compile_definitions(test_csv_to_bag PRIVATE
  JLE_TEST_DATA="${JLE_TEST_DATA}"
  JLE_CSV_TO_BAG="$<TARGET_FILE:csv_to_bag>"
  JLE_BAG_TO_CSV="$<TARGET_FILE:bag_to_csv>"
  JLE_JOINT_LOADS="$<TARGET_FILE:joint_loads>"
  JLE_PROCESS_BAG="$<TARGET_FILE:process_bag>")
add_dependencies(test_csv_to_bag csv_to_bag bag_to_csv joint_loads process_bag)
# The node's per-input counts behind its diagnostics (loss by header.seq gaps).
catkin_add_gtest(test_input_health ros/test_input_health.cpp)
target_link_libraries(test_input_health joint_load_estimator_ros gtest_main)
# The settings and process_bag with force plates.
catkin_add_gtest(test_plates_offline tools/test_plates_offline.cpp)
target_link_libraries(test_plates_offline joint_load_estimator_ros ${catkin_LIBRARIES} gtest_main)
target_compile_definitions(test_plates_offline PRIVATE
  JLE_ROSTEST_DIR="${JLE_ROSTEST_DIR}"
  JLE_PROCESS_BAG="$<TARGET_FILE:process_bag>")
add_dependencies(test_plates_offline process_bag)
