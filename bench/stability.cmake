# Numerical stability: the sweeps (bench/stability.cpp, tools/stability.sh, which writes
# docs/stability.md) and the bounds they establish (test/unit/test_stability.cpp).
# Built with the tests: `catkin_make tests` or the targets by name.
if(CATKIN_ENABLE_TESTING)
  if(NOT TARGET test_stability)
    jle_add_unit_test(test_stability test/unit/test_stability.cpp)
  endif()

  # The sweeps' reference is GCC's __float128 (libquadmath): where the compiler has no
  # such type, the tool is not built (the test needs only long double).
  include(CheckCXXSourceCompiles)
  set(CMAKE_REQUIRED_LIBRARIES quadmath)
  check_cxx_source_compiles("
    #include <quadmath.h>
    int main() { __float128 x = 2; return sqrtq(x) > 1 ? 0 : 1; }" JLE_HAVE_QUADMATH)
  unset(CMAKE_REQUIRED_LIBRARIES)
  if(JLE_HAVE_QUADMATH)
    add_executable(stability bench/stability.cpp)
    target_link_libraries(stability joint_load_estimator_core quadmath)
    target_compile_definitions(stability PRIVATE
      JLE_BENCH_DATA="${CMAKE_CURRENT_SOURCE_DIR}/test/data")
    add_dependencies(tests stability)
  else()
    message(STATUS "stability: no __float128 / libquadmath, bench/stability.cpp not built")
  endif()
endif()
