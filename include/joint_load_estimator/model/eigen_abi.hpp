// The Eigen memory layout the core library is built with, which every client must share:
// the library's objects (Estimator, DifferentiatorBank, Model, Data...) hold fixed-size
// Eigen members and their inline code runs on both sides of the library's boundary.
// Left to itself, Eigen aligns those members (and the heap) to the widest vector the
// compiler targets: 16 bytes by default, 32 with -mavx (-march=native), 64 with
// -mavx512f, which changes the objects' layout, so a client built with other flags than
// the library reads its members at the wrong offsets. The package fixes the alignment to
// the default of amd64 and arm64 (what Debian's libraries use: 16 bytes, heap from
// malloc) and exports it: the CMake target joint_load_estimator_core (PUBLIC compile
// definitions) and the catkin package (cmake/joint_load_estimator-extras.cmake) define
//   EIGEN_MAX_ALIGN_BYTES=16 EIGEN_MAX_STATIC_ALIGN_BYTES=16 EIGEN_MALLOC_ALREADY_ALIGNED=1
// Wider vectors still work in a client: Eigen then uses unaligned loads.
#pragma once

#include <Eigen/Core>

#if EIGEN_MAX_ALIGN_BYTES != 16 || EIGEN_MAX_STATIC_ALIGN_BYTES != 16 || \
    !EIGEN_MALLOC_ALREADY_ALIGNED
#error \
    "joint_load_estimator: Eigen's alignment differs from the core library's; compile with \
-DEIGEN_MAX_ALIGN_BYTES=16 -DEIGEN_MAX_STATIC_ALIGN_BYTES=16 -DEIGEN_MALLOC_ALREADY_ALIGNED=1 \
(link the CMake target joint_load_estimator_core or find_package the catkin package)"
#endif
