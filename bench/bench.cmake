# Benchmarks (Google Benchmark). Built with the tests, since they need the same peers
# (KDL); CI runs each once on a tiny input so that they cannot rot.
if(CATKIN_ENABLE_TESTING)
  find_package(benchmark REQUIRED)
  add_executable(bench_speed_core bench/speed_core.cpp)
  target_link_libraries(bench_speed_core joint_load_estimator_core benchmark::benchmark
    ${orocos_kdl_LIBRARIES} ${kdl_parser_LIBRARIES})
  target_include_directories(bench_speed_core PRIVATE ${orocos_kdl_INCLUDE_DIRS}
    ${kdl_parser_INCLUDE_DIRS})
  target_compile_definitions(bench_speed_core PRIVATE
    JLE_BENCH_DATA="${CMAKE_CURRENT_SOURCE_DIR}/test/data")
  add_dependencies(tests bench_speed_core)
endif()

# The node end to end (bench/node_latency.sh runs it against the real node).
add_executable(bench_node_latency bench/node_latency.cpp)
target_link_libraries(bench_node_latency ${catkin_LIBRARIES})
target_include_directories(bench_node_latency PRIVATE ${catkin_INCLUDE_DIRS})
add_dependencies(bench_node_latency ${PROJECT_NAME}_generate_messages_cpp)

if(CATKIN_ENABLE_TESTING)
  add_executable(bench_speed_messages bench/speed_messages.cpp)
  target_link_libraries(bench_speed_messages joint_load_estimator_ros benchmark::benchmark
    ${catkin_LIBRARIES})
  target_include_directories(bench_speed_messages PRIVATE ${catkin_INCLUDE_DIRS})
  target_compile_definitions(bench_speed_messages PRIVATE
    JLE_BENCH_DATA="${CMAKE_CURRENT_SOURCE_DIR}/test/data")
  add_dependencies(bench_speed_messages ${PROJECT_NAME}_generate_messages_cpp)
  add_dependencies(tests bench_speed_messages bench_node_latency)
endif()
