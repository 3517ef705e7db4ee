# Offline formats (issues 7 and 8): OpenSim storage files for joint_loads and
# process_bag, joint_loads' floating base and force plates. Included at the end of
# CMakeLists.txt, after the targets exist.


if(CATKIN_ENABLE_TESTING)
  jle_add_unit_test(test_offline_formats test/unit/test_offline_formats.cpp)
  target_compile_definitions(test_offline_formats PRIVATE
    JLE_PROCESS_BAG="$<TARGET_FILE:process_bag>"
    JLE_MAKE_EXAMPLE_BAG="$<TARGET_FILE:make_example_bag>")
  add_dependencies(test_offline_formats joint_loads process_bag make_example_bag)
endif()
