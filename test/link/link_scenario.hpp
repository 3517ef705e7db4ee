// The run the link test compares: the estimator on the Panda with the default filter
// (constant-jerk Kalman) and with a Savitzky-Golay fit, a wrist wrench input, a smooth
// trajectory. Compiled twice: into the test with the project's flags, and into a client
// built with other flags (-march=native) against the installed-style core library.
#pragma once

#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace jle_link {

/// Per published sample: the stamp, every segment's effort, force and moment, for
/// each of the two filters in turn.
inline std::vector<double> runScenario(const std::string& urdf_file) {
  const jle::Model<double> model = jle::modelFromUrdfFile(urdf_file);
  std::vector<double> out;
  for (int variant = 0; variant < 2; ++variant) {
    jle::EstimatorConfig config;  // defaults: constant-jerk Kalman
    if (variant == 1) {
      config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
      config.differentiator.window = 9;
      config.differentiator.delay = 4;
    }
    jle::WrenchInputConfig wrist;
    wrist.link = "panda_hand";
    config.wrenches.push_back(wrist);
    jle::Estimator estimator(model, config);  // on the stack: the client's layout
    std::vector<double> q(static_cast<std::size_t>(model.nq));
    for (int k = 0; k < 300; ++k) {
      const double t = 1e-3 * k;
      estimator.addWrench(0, t, Eigen::Vector3d(1.0 + std::sin(3.0 * t), -2.0, 5.0 * t),
                          Eigen::Vector3d(0.1, 0.2 * std::cos(t), -0.3));
      for (int i = 0; i < model.nq; ++i) q[i] = 0.4 * std::sin(2.0 * t + 0.7 * i) + 0.1 * i;
      if (estimator.addJointSample(t, q.data()) != jle::SampleStatus::kPublished) continue;
      out.push_back(estimator.last().stamp());
      out.push_back(estimator.filters().delaySamples());
      const jle::Data<double>& d = estimator.last().data();
      for (int s = 0; s < model.nsegments(); ++s) {
        out.push_back(d.effort[s]);
        for (int c = 0; c < 3; ++c) out.push_back(d.force[s][c]);
        for (int c = 0; c < 3; ++c) out.push_back(d.moment[s][c]);
      }
      const jle::Wrench<double> w = estimator.last().appliedWrench(0);
      for (int c = 0; c < 3; ++c) out.push_back(w.force[c]);
    }
  }
  return out;
}

}  // namespace jle_link
