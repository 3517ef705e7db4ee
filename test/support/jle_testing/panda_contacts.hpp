// Issue 40's scene: a Panda moving at 1 kHz about its ready pose (every joint inside its
// limits) with three step contacts (20 N at a fingertip 5 cm off the flange's axis,
// 5 N m on link 4, 15 N on link 5), its measured efforts from KDL's recursive Newton-Euler with
// external forces (ChainIdSolver_RNE, Debian's liborocos-kdl-dev): an implementation independent of
// this package's dynamics. Shared by test_external_effort and the node test test_external.
// Header-only, ROS-free; needs KDL and kdl_parser.
#pragma once

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace jle_testing {

/// A wrench applied TO a link during [t_on, t_off): force at `point`, plus `moment`, all
/// in the link frame [m, N, N m].
struct StepContact {
  std::string link;
  Eigen::Vector3d point, force, moment;
  double t_on, t_off;
  /// The child link of the most distal joint the wrench loads: where detection must put
  /// it (a contact on link k loads joints 1..k only).
  std::string detected_link;
};

class PandaContacts {
 public:
  static constexpr double kRate = 1000.0;   // [Hz]
  static constexpr double kDuration = 5.0;  // [s]
  std::vector<StepContact> contacts = {
      {"panda_hand_tcp", {0.0, 0.05, 0.0}, {18.0, 0.0, -8.7}, {0, 0, 0}, 2.0, 2.5, "panda_link7"},
      {"panda_link4", {0, 0, 0}, {0, 0, 0}, {0.0, 0.0, 5.0}, 3.0, 3.5, "panda_link4"},
      {"panda_link5", {0.0, 0.08, -0.1}, {15.0, 0.0, 0.0}, {0, 0, 0}, 4.0, 4.5, "panda_link5"}};

  /// `urdf_text`: the Panda chain (panda_link0 .. panda_hand_tcp), 7 joints.
  explicit PandaContacts(const std::string& urdf_text) {
    KDL::Tree tree;
    if (!kdl_parser::treeFromString(urdf_text, tree) ||
        !tree.getChain("panda_link0", "panda_hand_tcp", chain_) || chain_.getNrOfJoints() != 7)
      throw std::runtime_error("PandaContacts: not the Panda chain");
    solver_ = std::make_unique<KDL::ChainIdSolver_RNE>(chain_, KDL::Vector(0, 0, -9.80665));
  }

  /// Index of the contact acting at t, -1 none.
  int active(double t) const {
    for (std::size_t k = 0; k < contacts.size(); ++k)
      if (t >= contacts[k].t_on && t < contacts[k].t_off) return static_cast<int>(k);
    return -1;
  }

  /// Sinusoids of 0.25 rad at 0.3 to 0.66 Hz about the ready pose (0, -pi/4, 0, -3pi/4,
  /// 0, pi/2, pi/4): joints 4 and 6 stay 0.3 rad or more inside their limits.
  void state(double t, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) const {
    const double q0[7] = {0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785};
    q.resize(7);
    qd.resize(7);
    qdd.resize(7);
    for (int i = 0; i < 7; ++i) {
      const double w = 2.0 * M_PI * 0.3 * (1.0 + 0.2 * i), phase = 0.7 * i, a = 0.25;
      q[i] = q0[i] + a * std::sin(w * t + phase);
      qd[i] = a * w * std::cos(w * t + phase);
      qdd[i] = -a * w * w * std::sin(w * t + phase);
    }
  }

  /// What the robot measures at t [s]: the positions with encoder noise (1e-4 rad) and
  /// the efforts with 0.1 N m of noise, drawn from `gauss` on `rng` in that order (the
  /// core's test and the node's test draw the same noise).
  void measured(double t, std::mt19937& rng, std::normal_distribution<double>& gauss,
                Eigen::VectorXd& q, std::vector<double>& effort) const {
    Eigen::VectorXd qd, qdd;
    state(t, q, qd, qdd);
    effort = efforts(t);
    for (int i = 0; i < 7; ++i) q[i] += 1e-4 * gauss(rng);
    for (double& e : effort) e += 0.1 * gauss(rng);
  }

  /// The joint efforts at t with the active contact's wrench (KDL's RNE) [N m].
  std::vector<double> efforts(double t) const {
    Eigen::VectorXd q, qd, qdd;
    state(t, q, qd, qdd);
    const unsigned n = chain_.getNrOfJoints();
    KDL::JntArray kq(n), kqd(n), kqdd(n), tau(n);
    kq.data = q;
    kqd.data = qd;
    kqdd.data = qdd;
    KDL::Wrenches f_ext(chain_.getNrOfSegments(), KDL::Wrench::Zero());
    const int k = active(t);
    if (k >= 0) {
      const StepContact& c = contacts[static_cast<std::size_t>(k)];
      const Eigen::Vector3d moment_origin = c.moment + c.point.cross(c.force);
      // KDL: f_ext[i] acts on segment i, in its frame, moment about its origin.
      f_ext[segment(c.link)] =
          KDL::Wrench(KDL::Vector(c.force.x(), c.force.y(), c.force.z()),
                      KDL::Vector(moment_origin.x(), moment_origin.y(), moment_origin.z()));
    }
    if (solver_->CartToJnt(kq, kqd, kqdd, f_ext, tau) < 0)
      throw std::runtime_error("PandaContacts: KDL's RNE failed");
    return std::vector<double>(tau.data.data(), tau.data.data() + n);
  }

 private:
  std::size_t segment(const std::string& link) const {
    for (unsigned i = 0; i < chain_.getNrOfSegments(); ++i)
      if (chain_.getSegment(i).getName() == link) return i;
    throw std::runtime_error("PandaContacts: no segment " + link);
  }
  KDL::Chain chain_;
  std::unique_ptr<KDL::ChainIdSolver_RNE> solver_;
};

}  // namespace jle_testing
