# Added to a catkin client by find_package(catkin COMPONENTS joint_load_estimator):
# Eigen's alignment as the core library was built with it, whatever the client's compiler
# flags (-march=native...). Keep in step with JLE_EIGEN_ABI in CMakeLists.txt and
# include/joint_load_estimator/model/eigen_abi.hpp, which refuses to compile without it.
add_definitions(-DEIGEN_MAX_ALIGN_BYTES=16 -DEIGEN_MAX_STATIC_ALIGN_BYTES=16
  -DEIGEN_MALLOC_ALREADY_ALIGNED=1)
