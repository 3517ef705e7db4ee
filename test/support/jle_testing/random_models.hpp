// The tests' random numbers (jle::PortableRandom with the draws tests need: vectors,
// rotations, log-uniform numbers), random robot models as URDF strings, deterministic
// from a seed, and the error of the joint loads computed in one scalar type against a
// more precise one on the same inputs. Part of the test support library
// (joint_load_estimator_testing): shared by the unit tests and bench/ (stability, speed_core).
#pragma once

#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace jle_test {

/// jle::PortableRandom (the same seed gives the same model on every platform), with
/// the draws the random models need.
class Random : public jle::PortableRandom {
 public:
  using jle::PortableRandom::PortableRandom;
  /// Log-uniform in [lo, hi] (lo > 0).
  double logUniform(double lo, double hi) { return lo * std::pow(hi / lo, uniform(0.0, 1.0)); }
  /// Uniform on the unit sphere.
  Eigen::Vector3d unitVector() {
    const double z = uniform(-1.0, 1.0), phi = uniform(0.0, 2.0 * M_PI);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
  }
  /// Uniform in the cube [-half_range, half_range)^3 (x, y, z drawn in that order).
  Eigen::Vector3d vector(double half_range) {
    const double x = uniform(-half_range, half_range), y = uniform(-half_range, half_range),
                 z = uniform(-half_range, half_range);
    return Eigen::Vector3d(x, y, z);
  }
  /// A uniformly random rotation: the unit quaternion of four normal numbers (w, x, y, z
  /// drawn in that order).
  Eigen::Matrix3d rotation() {
    const double w = gaussian(), x = gaussian(), y = gaussian(), z = gaussian();
    return Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  }
};

/// Uniform in [lo, hi) from a Random, used like a distribution: UniformIn u(lo, hi);
/// u(rng).
class UniformIn {
 public:
  UniformIn(double lo, double hi) : lo_(lo), hi_(hi) {}
  double operator()(Random& rng) const { return rng.uniform(lo_, hi_); }

 private:
  double lo_, hi_;
};

/// What randomUrdf() builds. Every link has a mass and an inertia; the base is fixed.
struct RandomModelSpec {
  int joints = 6;     ///< moving joints (the model has joints + 1 segments)
  bool tree = false;  ///< false: a serial chain; true: each link hangs from a random earlier one
  double length =
      0.3;  ///< distance between successive joint origins: uniform in [0.5, 1] x length [m]
  /// Link masses log-uniform in [1, mass_ratio] kg.
  double mass_ratio = 1.0;
  /// Each link's inertia (that of a random box of the link's size and mass) is scaled by
  /// a factor log-uniform in [1, inertia_ratio].
  double inertia_ratio = 1.0;
  /// 0: links are random boxes. > 0 ... 1e-12: links are rods of this thickness over
  /// length, whose moment about their axis over the others is about 2 rod^2; < 0: ideal
  /// rods (that moment exactly zero).
  double rod = 0.0;
  /// Every prismatic_every-th joint is prismatic (0: all revolute).
  int prismatic_every = 0;
  std::uint32_t seed = 1;
};

namespace detail {
inline std::string num(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}
inline std::string vec(const Eigen::Vector3d& v) {
  return num(v.x()) + " " + num(v.y()) + " " + num(v.z());
}
}  // namespace detail

/// A random robot as a URDF document: links link0 (the fixed base) .. linkN, joints
/// j1 .. jN (jK enters linkK), every number printed with 17 significant digits so that
/// the reader recovers the doubles written.
inline std::string randomUrdf(const RandomModelSpec& spec) {
  using detail::num;
  using detail::vec;
  Random rng(spec.seed);
  const double L = spec.length;
  std::string xml = "<?xml version=\"1.0\"?>\n<robot name=\"random\">\n";
  auto link = [&](int k) {
    const double m = rng.logUniform(1.0, std::max(1.0, spec.mass_ratio));
    const double scale = rng.logUniform(1.0, std::max(1.0, spec.inertia_ratio));
    double ixx, iyy, izz;
    if (spec.rod != 0.0) {
      const double len = L * rng.uniform(0.5, 1.0);
      const double d = spec.rod > 0.0 ? spec.rod * len : 0.0;
      ixx = iyy = m * (d * d + len * len) / 12.0;
      izz = m * 2.0 * d * d / 12.0;
    } else {
      const double a = L * rng.uniform(0.2, 1.0), b = L * rng.uniform(0.2, 1.0),
                   c = L * rng.uniform(0.2, 1.0);
      ixx = m * (b * b + c * c) / 12.0;
      iyy = m * (a * a + c * c) / 12.0;
      izz = m * (a * a + b * b) / 12.0;
    }
    const Eigen::Vector3d com = 0.5 * L * rng.unitVector() * rng.uniform(0.0, 1.0);
    const Eigen::Vector3d rpy(rng.uniform(-M_PI, M_PI), rng.uniform(-M_PI / 2, M_PI / 2),
                              rng.uniform(-M_PI, M_PI));
    xml += "  <link name=\"link" + std::to_string(k) + "\">\n    <inertial>\n";
    xml += "      <origin xyz=\"" + vec(com) + "\" rpy=\"" + vec(rpy) + "\"/>\n";
    xml += "      <mass value=\"" + num(m) + "\"/>\n";
    xml += "      <inertia ixx=\"" + num(scale * ixx) + "\" ixy=\"0\" ixz=\"0\" iyy=\"" +
           num(scale * iyy) + "\" iyz=\"0\" izz=\"" + num(scale * izz) + "\"/>\n";
    xml += "    </inertial>\n  </link>\n";
  };
  link(0);
  for (int k = 1; k <= spec.joints; ++k) {
    link(k);
    const int parent = spec.tree ? rng.index(k) : k - 1;
    const bool prismatic = spec.prismatic_every > 0 && k % spec.prismatic_every == 0;
    const Eigen::Vector3d xyz = L * rng.uniform(0.5, 1.0) * rng.unitVector();
    const Eigen::Vector3d rpy(rng.uniform(-M_PI, M_PI), rng.uniform(-M_PI / 2, M_PI / 2),
                              rng.uniform(-M_PI, M_PI));
    const Eigen::Vector3d axis = rng.unitVector();
    xml += "  <joint name=\"j" + std::to_string(k) + "\" type=\"" +
           (prismatic ? "prismatic" : "revolute") + "\">\n";
    xml += "    <parent link=\"link" + std::to_string(parent) + "\"/>\n";
    xml += "    <child link=\"link" + std::to_string(k) + "\"/>\n";
    xml += "    <origin xyz=\"" + vec(xyz) + "\" rpy=\"" + vec(rpy) + "\"/>\n";
    xml += "    <axis xyz=\"" + vec(axis) + "\"/>\n";
    xml += "    <limit lower=\"-1e9\" upper=\"1e9\" effort=\"1e9\" velocity=\"1e9\"/>\n";
    xml += "  </joint>\n";
  }
  xml += "</robot>\n";
  return xml;
}

/// A joint state, coordinates in model.coordinate_names order.
struct State {
  Eigen::VectorXd q, qd, qdd;
};

/// Where randomState draws: each quantity uniform in centre +- half-width, revolute and
/// prismatic coordinates apart [rad or m, /s, /s^2], in the order
/// {q, qd, qdd, prismatic_centre, prismatic_q, prismatic_qd, prismatic_qdd}.
struct StateRanges {
  double q = M_PI, qd = 1.0, qdd = 5.0;  ///< revolute: q in [-q, q)
  double prismatic_centre = 0.0;         ///< prismatic: q in prismatic_centre +- prismatic_q
  double prismatic_q = 0.3, prismatic_qd = 1.0, prismatic_qdd = 5.0;
};

/// A random joint state; per coordinate q, qd, qdd drawn in that order.
inline State randomState(const jle::Model<double>& model, Random& rng, const StateRanges& r) {
  State s;
  s.q.resize(model.nq);
  s.qd.resize(model.nq);
  s.qdd.resize(model.nq);
  std::vector<char> prismatic(static_cast<std::size_t>(model.nq), 0);
  for (int i : model.moving_segments)
    if (model.joint_type[i] == jle::JointType::kPrismatic) prismatic[model.coordinate[i]] = 1;
  for (int k = 0; k < model.nq; ++k) {
    s.q[k] = prismatic[k] ? r.prismatic_centre + rng.uniform(-r.prismatic_q, r.prismatic_q)
                          : rng.uniform(-r.q, r.q);
    const double qd = prismatic[k] ? r.prismatic_qd : r.qd;
    const double qdd = prismatic[k] ? r.prismatic_qdd : r.qdd;
    s.qd[k] = rng.uniform(-qd, qd);
    s.qdd[k] = rng.uniform(-qdd, qdd);
  }
  return s;
}

/// q uniform in [-pi, pi) (prismatic: [-length, length)), qd in [-qd_scale, qd_scale),
/// qdd in [-qdd_scale, qdd_scale).
inline State randomState(const jle::Model<double>& model, Random& rng, double qd_scale,
                         double qdd_scale, double length = 0.3) {
  StateRanges r;
  r.qd = r.prismatic_qd = qd_scale;
  r.qdd = r.prismatic_qdd = qdd_scale;
  r.prismatic_q = length;
  return randomState(model, rng, r);
}

/// A random floating-base state: a uniformly random rotation, then the position,
/// velocity, angular velocity, acceleration and angular acceleration each uniform in a
/// cube of the given half-width [m, m/s, rad/s, m/s^2, rad/s^2], in that order.
inline jle::BaseState<double> randomBase(Random& rng, double p, double v, double omega, double a,
                                         double alpha) {
  jle::BaseState<double> base;
  base.R_world_base = rng.rotation();
  base.p_world_base = rng.vector(p);
  base.v_world = rng.vector(v);
  base.omega_world = rng.vector(omega);
  base.a_world = rng.vector(a);
  base.alpha_world = rng.vector(alpha);
  return base;
}

/// A wrench applied to the robot (dynamics.hpp's addExternalWrench), given in double.
struct AppliedWrench {
  int frame = 0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  jle::WrenchFrame expressed_in = jle::WrenchFrame::kLocal;
};

/// Everything the loads depend on besides the model, in double: the inputs that every
/// scalar type receives (rounded to double first, then converted).
struct Scene {
  State state;
  Eigen::Vector3d gravity{0.0, 0.0, -9.80665};
  jle::BaseState<double> base;
  std::vector<AppliedWrench> wrenches;
};

template <typename S>
jle::BaseState<S> castBase(const jle::BaseState<double>& b) {
  jle::BaseState<S> out;
  out.R_world_base = b.R_world_base.cast<S>();
  out.p_world_base = b.p_world_base.cast<S>();
  out.v_world = b.v_world.cast<S>();
  out.omega_world = b.omega_world.cast<S>();
  out.a_world = b.a_world.cast<S>();
  out.alpha_world = b.alpha_world.cast<S>();
  return out;
}

/// The forward and backward passes in scalar type S (model already cast).
template <typename S>
void computeLoads(const jle::Model<S>& model, jle::Data<S>& data, const Scene& scene) {
  using V3 = Eigen::Matrix<S, 3, 1>;
  const jle::VectorX<S> q = scene.state.q.cast<S>(), qd = scene.state.qd.cast<S>(),
                        qdd = scene.state.qdd.cast<S>();
  jle::forwardKinematics(model, data, q, qd, qdd, V3(scene.gravity.cast<S>()),
                         castBase<S>(scene.base));
  for (const AppliedWrench& w : scene.wrenches)
    jle::addExternalWrench(model, data, w.frame, V3(w.force.cast<S>()), V3(w.moment.cast<S>()),
                           w.expressed_in);
  jle::inverseDynamics(model, data);
}

/// Worst relative errors over the joints (and the samples merged into it).
struct Error {
  double wrench = 0.0;  ///< |(dF, dM)| / |(F, M)|, the 6-vector in N and N m
  double force = 0.0;   ///< |dF| / |F|
  double moment = 0.0;  ///< |dM| / |M|
  void merge(const Error& o) {
    wrench = std::max(wrench, o.wrench);
    force = std::max(force, o.force);
    moment = std::max(moment, o.moment);
  }
};

/// Relative error of the joint wrenches of `data` (type S) against `ref` (type R, more
/// precise), per moving joint in its child frame, computed in R. A component whose
/// reference is exactly zero is skipped.
template <typename R, typename S>
Error relativeError(const std::vector<int>& joints, const std::vector<Eigen::Matrix<S, 3, 1>>& f,
                    const std::vector<Eigen::Matrix<S, 3, 1>>& m,
                    const std::vector<Eigen::Matrix<R, 3, 1>>& f_ref,
                    const std::vector<Eigen::Matrix<R, 3, 1>>& m_ref) {
  using V3 = Eigen::Matrix<R, 3, 1>;
  Error e;
  auto ratio = [](R num, R den) { return den > R(0) ? static_cast<double>(num / den) : 0.0; };
  for (int i : joints) {
    V3 df, dm;
    for (int k = 0; k < 3; ++k) {
      df[k] = static_cast<R>(f[i][k]) - f_ref[i][k];
      dm[k] = static_cast<R>(m[i][k]) - m_ref[i][k];
    }
    using std::sqrt;
    const R num2 = df.squaredNorm() + dm.squaredNorm();
    const R den2 = f_ref[i].squaredNorm() + m_ref[i].squaredNorm();
    e.wrench = std::max(e.wrench, ratio(sqrt(num2), sqrt(den2)));
    e.force = std::max(e.force, ratio(df.norm(), f_ref[i].norm()));
    e.moment = std::max(e.moment, ratio(dm.norm(), m_ref[i].norm()));
  }
  return e;
}

/// The error of the loads computed in float, double and (where R is more precise than
/// long double) long double, against R, for one model and scene.
template <typename R>
struct PrecisionComparison {
  Error of_float, of_double, of_long_double;
  void merge(const PrecisionComparison& o) {
    of_float.merge(o.of_float);
    of_double.merge(o.of_double);
    of_long_double.merge(o.of_long_double);
  }
};

/// The model with every term computed: Model::analyze() lets the backward pass skip a
/// gyroscopic term it proves zero; a reference must not inherit that proof.
template <typename S>
jle::Model<S> computeEverything(jle::Model<S> m) {
  m.gyroscopic.assign(m.gyroscopic.size(), 1);
  return m;
}

/// The same model in every precision, with its workspaces. float and double use the
/// model as given (with its skips); long double and R compute every term.
template <typename R>
struct Precisions {
  explicit Precisions(const jle::Model<double>& m)
      : d(m),
        f(m.cast<float>()),
        ld(computeEverything(m.cast<long double>())),
        r(computeEverything(m.cast<R>())),
        data_d(d),
        data_f(f),
        data_ld(ld),
        data_r(r) {}
  jle::Model<double> d;
  jle::Model<float> f;
  jle::Model<long double> ld;
  jle::Model<R> r;
  jle::Data<double> data_d;
  jle::Data<float> data_f;
  jle::Data<long double> data_ld;
  jle::Data<R> data_r;

  PrecisionComparison<R> compare(const Scene& scene) {
    computeLoads(d, data_d, scene);
    computeLoads(f, data_f, scene);
    computeLoads(ld, data_ld, scene);
    computeLoads(r, data_r, scene);
    PrecisionComparison<R> c;
    const std::vector<int>& j = d.moving_segments;
    c.of_double = relativeError<R>(j, data_d.force, data_d.moment, data_r.force, data_r.moment);
    c.of_float = relativeError<R>(j, data_f.force, data_f.moment, data_r.force, data_r.moment);
    c.of_long_double =
        relativeError<R>(j, data_ld.force, data_ld.moment, data_r.force, data_r.moment);
    return c;
  }
};

}  // namespace jle_test
