// libFuzzer target: the URDF loader. Any input must either give a model that keeps the
// model.hpp invariants and on which the dynamics run, or throw jle::ModelError; any
// other exception, a crash or a sanitizer report is a bug. Built by build_and_run.sh.
#include "fuzz_check.hpp"

#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  // The whole input is the XML; its last byte also picks the options (a plain URDF
  // file ends in '>' or a line break, so the seeds try both ways).
  jle::ModelOptions options;
  if (size > 0) {
    options.floating_base = (bytes[size - 1] & 1) != 0;
    // The UR5 seed's tool flange (another document without it is refused: unknown name).
    if (bytes[size - 1] & 2) options.keep_fixed_joints = {"wrist_3_link-tool0_fixed_joint"};
  }
  const std::string xml(reinterpret_cast<const char*>(bytes), size);
  jle::Model<double> model;
  try {
    model = jle::modelFromUrdfString(xml, options);
  } catch (const jle::ModelError&) {
    return 0;  // refused with a message: the documented outcome
  }
  const int n = model.nsegments();
  JLE_FUZZ_CHECK(n >= 1);
  JLE_FUZZ_CHECK(model.parent.size() == static_cast<std::size_t>(n));
  JLE_FUZZ_CHECK(model.parent[0] < 0);
  for (int i = 1; i < n; ++i)
    JLE_FUZZ_CHECK(model.parent[static_cast<std::size_t>(i)] >= 0 &&
                   model.parent[static_cast<std::size_t>(i)] < i);
  JLE_FUZZ_CHECK(model.coordinate_names.size() == static_cast<std::size_t>(model.nq));
  for (int s : model.moving_segments) JLE_FUZZ_CHECK(s > 0 && s < n);
  for (const auto& f : model.frames) {
    JLE_FUZZ_CHECK(f.segment >= 0 && f.segment < n);
    JLE_FUZZ_CHECK(model.frameIndex(f.name) >= 0);
  }
  if (n > 1000) return 0;  // a long chain is legal; keep each run quick
  jle::Data<double> data(model);
  const jle::VectorX<double> q = jle::VectorX<double>::Constant(model.nq, 0.3);
  jle::BaseState<double> base;
  jle::forwardKinematics(model, data, q, q, q, Eigen::Vector3d(0.0, 0.0, -9.81), base);
  jle::inverseDynamics(model, data);
  for (int s = 0; s < n; ++s) (void)jle::jointWrench(model, data, s, jle::WrenchFrame::kWorld);
  (void)model.cast<float>();
  return 0;
}
