// The Python module joint_load_estimator._core (pybind11): the model, batch inverse
// dynamics over numpy arrays, the online estimator, the offline zero-phase smoothing and
// a bag through the node's message path. A front end: it converts arrays and names and
// calls the core (and jle::processBag); src/joint_load_estimator/__init__.py re-exports
// it. docs/python.md.
#include <joint_load_estimator/config.hpp>
#include <joint_load_estimator/dynamics.hpp>
#include <joint_load_estimator/estimator.hpp>
#include <joint_load_estimator/kinematics.hpp>
#include <joint_load_estimator/model.hpp>
#include <joint_load_estimator/pipeline.hpp>
#include <joint_load_estimator/ros/bag_processing.hpp>
#include <joint_load_estimator/ros/conversions.hpp>
#include <joint_load_estimator/ros/settings.hpp>
#include <joint_load_estimator/urdf_reader.hpp>
#include <joint_load_estimator/zero_phase.hpp>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace py = pybind11;

namespace {

// Arrays in: C-contiguous doubles (anything else is converted).
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A model and how it was made (Estimator rebuilds it with a config's model options).
struct PyModel {
  jle::Model<double> model;
  std::string xml;
  jle::ModelOptions options;
};

PyModel modelFromString(const std::string& xml, bool floating_base,
                        const std::vector<std::string>& keep_fixed_joints) {
  PyModel m;
  m.xml = xml;
  m.options.floating_base = floating_base;
  m.options.keep_fixed_joints = keep_fixed_joints;
  m.model = jle::modelFromUrdfString(xml, m.options);
  return m;
}

PyModel modelFromFile(const std::string& path, bool floating_base,
                      const std::vector<std::string>& keep_fixed_joints) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  PyModel m;
  m.xml = text.str();
  m.options.floating_base = floating_base;
  m.options.keep_fixed_joints = keep_fixed_joints;
  m.model = jle::modelFromUrdfFile(path, m.options);  // its errors name the file
  return m;
}

std::vector<std::string> namesOf(const std::vector<std::string>& names,
                                 const std::vector<int>& segments) {
  std::vector<std::string> out;
  for (int s : segments) out.push_back(names[static_cast<std::size_t>(s)]);
  return out;
}

// `a` as rows x cols (rows < 0: any), or an error naming `what`.
void checkShape(const Array& a, long rows, long cols, const std::string& what) {
  const bool ok = a.ndim() == 2 && (rows < 0 || a.shape(0) == rows) && a.shape(1) == cols;
  if (ok) return;
  std::string shape = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(a.shape(d));
  throw std::invalid_argument(what + " must have shape (" +
                              (rows < 0 ? std::string("N") : std::to_string(rows)) + ", " +
                              std::to_string(cols) + "), it has " + shape + ")");
}

jle::WrenchFrame frameOf(const std::string& name) {
  if (name == "child") return jle::WrenchFrame::kChild;
  if (name == "parent") return jle::WrenchFrame::kParent;
  if (name == "world") return jle::WrenchFrame::kWorld;
  throw std::invalid_argument("frame must be 'child', 'parent' or 'world', not '" + name + "'");
}

Eigen::Vector3d gravityOf(const py::object& gravity) {
  if (gravity.is_none()) return jle::EstimatorConfig().gravity_world;  // the one default
  const std::vector<double> g = gravity.cast<std::vector<double>>();
  if (g.size() != 3 || !std::isfinite(g[0]) || !std::isfinite(g[1]) || !std::isfinite(g[2]))
    throw std::invalid_argument("gravity must be three finite numbers [m/s^2]");
  return Eigen::Vector3d(g[0], g[1], g[2]);
}

// The inputs of a batch, checked, as raw rows.
struct Batch {
  long n = 0;
  const double *q = nullptr, *qd = nullptr, *qdd = nullptr;
  std::vector<int> wrench_frames;
  std::vector<const double*> wrenches;  // n x 6 each: force, moment in the link frame
  const double *pose = nullptr, *twist = nullptr, *acceleration = nullptr;  // floating base
};

void takeBase(const jle::Model<double>& model, const py::dict& base, Batch& b,
              std::vector<Array>& keep) {
  if (!model.floating_base) {
    if (!base.empty()) throw std::invalid_argument("base_* arrays given for a fixed-base model");
    return;
  }
  const char* const keys[3] = {"base_pose", "base_twist", "base_acceleration"};
  const long cols[3] = {7, 6, 6};
  const double** out[3] = {&b.pose, &b.twist, &b.acceleration};
  for (int i = 0; i < 3; ++i) {
    if (!base.contains(keys[i]) || base[keys[i]].is_none())
      throw std::invalid_argument(std::string("a floating-base model needs ") + keys[i]);
    keep.push_back(base[keys[i]].cast<Array>());
    checkShape(keep.back(), b.n, cols[i], keys[i]);
    *out[i] = keep.back().data();
  }
}

Batch takeBatch(const jle::Model<double>& model, const Array& q, const Array& qd, const Array& qdd,
                const py::object& wrenches, const py::dict& base, std::vector<Array>& keep) {
  Batch b;
  checkShape(q, -1, model.nq, "q");
  b.n = static_cast<long>(q.shape(0));
  checkShape(qd, b.n, model.nq, "qd");
  checkShape(qdd, b.n, model.nq, "qdd");
  b.q = q.data(), b.qd = qd.data(), b.qdd = qdd.data();
  if (!wrenches.is_none())
    for (const auto& item : wrenches.cast<py::dict>()) {
      const std::string link = item.first.cast<std::string>();
      b.wrench_frames.push_back(model.frameIndex(link));
      keep.push_back(item.second.cast<Array>());
      checkShape(keep.back(), b.n, 6, "wrenches['" + link + "']");
      b.wrenches.push_back(keep.back().data());
    }
  takeBase(model, base, b, keep);
  return b;
}

jle::BaseState<double> baseAt(const Batch& b, long i) {
  jle::BaseState<double> base;
  const double* p = b.pose + 7 * i;
  Eigen::Quaterniond orientation(p[6], p[3], p[4], p[5]);
  const double norm = orientation.norm();
  if (!(std::abs(norm - 1.0) <= 0.01))
    throw std::invalid_argument("base_pose[" + std::to_string(i) +
                                "]: the quaternion (qx, qy, qz, qw) has norm " +
                                std::to_string(norm) + ", not 1 (within 1 %)");
  orientation.coeffs() /= norm;  // as joint_loads does
  base.R_world_base = orientation.toRotationMatrix();
  base.p_world_base = Eigen::Vector3d(p[0], p[1], p[2]);
  const double* v = b.twist + 6 * i;
  const double* a = b.acceleration + 6 * i;
  base.v_world = Eigen::Vector3d(v[0], v[1], v[2]);
  base.omega_world = Eigen::Vector3d(v[3], v[4], v[5]);
  base.a_world = Eigen::Vector3d(a[0], a[1], a[2]);
  base.alpha_world = Eigen::Vector3d(a[3], a[4], a[5]);
  return base;
}

// Sample i of the batch through the model: forwardKinematics, the applied wrenches,
// inverseDynamics (what joint_loads does per CSV row).
void solveSample(const jle::Model<double>& model, jle::Data<double>& data, const Batch& b, long i,
                 const Eigen::Vector3d& gravity, jle::VectorX<double>& q, jle::VectorX<double>& qd,
                 jle::VectorX<double>& qdd) {
  const long nq = model.nq;
  q = Eigen::Map<const jle::VectorX<double>>(b.q + nq * i, nq);
  qd = Eigen::Map<const jle::VectorX<double>>(b.qd + nq * i, nq);
  qdd = Eigen::Map<const jle::VectorX<double>>(b.qdd + nq * i, nq);
  const jle::BaseState<double> base = model.floating_base ? baseAt(b, i) : jle::BaseState<double>();
  jle::forwardKinematics(model, data, q, qd, qdd, gravity, base);
  for (std::size_t k = 0; k < b.wrenches.size(); ++k) {
    const double* w = b.wrenches[k] + 6 * i;
    jle::addExternalWrench(model, data, b.wrench_frames[k], Eigen::Vector3d(w[0], w[1], w[2]),
                           Eigen::Vector3d(w[3], w[4], w[5]), jle::WrenchFrame::kLocal);
  }
  jle::inverseDynamics(model, data);
}

void putWrench(const jle::Wrench<double>& w, double* out) {
  for (int c = 0; c < 3; ++c) out[c] = w.force[c], out[3 + c] = w.moment[c];
}

py::dict inverseDynamicsBatch(const PyModel& m, const Array& q, const Array& qd, const Array& qdd,
                              const py::object& wrenches, const std::string& frame_name,
                              const py::object& gravity_given, const py::dict& base) {
  const jle::Model<double>& model = m.model;
  std::vector<Array> keep;  // the converted arrays live until the end
  const Batch b = takeBatch(model, q, qd, qdd, wrenches, base, keep);
  const jle::WrenchFrame frame = frameOf(frame_name);
  const Eigen::Vector3d gravity = gravityOf(gravity_given);
  const std::vector<int>& joints = model.moving_segments;
  const auto m_joints = static_cast<py::ssize_t>(joints.size());
  Array wrench({static_cast<py::ssize_t>(b.n), m_joints, py::ssize_t(6)});
  Array effort({static_cast<py::ssize_t>(b.n), m_joints});
  Array residual({static_cast<py::ssize_t>(model.floating_base ? b.n : 0), py::ssize_t(6)});
  double *w = wrench.mutable_data(), *e = effort.mutable_data(), *r = residual.mutable_data();
  {
    py::gil_scoped_release release;
    jle::Data<double> data(model);
    jle::VectorX<double> qi(model.nq), qdi(model.nq), qddi(model.nq);
    for (long i = 0; i < b.n; ++i) {
      solveSample(model, data, b, i, gravity, qi, qdi, qddi);
      for (int s : joints) {
        putWrench(jle::jointWrench(model, data, s, frame), w);
        w += 6;
        *e++ = data.effort[static_cast<std::size_t>(s)];
      }
      if (model.floating_base) {
        putWrench(jle::jointWrench(model, data, 0, jle::WrenchFrame::kWorld), r);
        r += 6;
      }
    }
  }
  py::dict out;
  out["joints"] = namesOf(model.joint_name, joints);
  out["links"] = namesOf(model.link_name, joints);
  out["frame"] = frame_name;
  out["wrench"] = wrench;
  out["effort"] = effort;
  if (model.floating_base) out["base_residual"] = residual;
  return out;
}

// ---- the online estimator -----------------------------------------------------------

// The estimator with the model and settings it was made from.
class PyEstimator {
 public:
  PyEstimator(const PyModel& m, const std::string& config) {
    if (!config.empty()) {
      try {
        settings_ = jle::parseSettings(jle::loadYaml(config));
      } catch (const jle::SettingsError& e) {
        throw jle::SettingsError(config + ": " + e.what());
      }
    }
    jle::ModelOptions options = jle::modelOptions(settings_);
    options.floating_base = options.floating_base || m.options.floating_base;
    for (const std::string& j : m.options.keep_fixed_joints)
      if (std::find(options.keep_fixed_joints.begin(), options.keep_fixed_joints.end(), j) ==
          options.keep_fixed_joints.end())
        options.keep_fixed_joints.push_back(j);
    model_ = jle::modelFromUrdfString(m.xml, options);
    estimator_ = std::make_unique<jle::Estimator>(model_, settings_.estimator);
    segments_ = jle::publishedSegments(estimator_->model(), settings_.estimator.joints);
  }

  const jle::Estimator& estimator() const { return *estimator_; }
  jle::Estimator& estimator() { return *estimator_; }
  const std::vector<int>& segments() const { return segments_; }
  const jle::Settings& settings() const { return settings_; }

  std::string addJointSample(double t, const Array& q, const py::object& pose,
                             const py::object& qd_object) {
    if (q.ndim() != 1 || q.shape(0) != model_.nq)
      throw std::invalid_argument("q must have " + std::to_string(model_.nq) + " entries");
    jle::BasePose base;
    if (!pose.is_none()) base = basePoseOf(pose.cast<Array>());
    if (model_.floating_base && pose.is_none())
      throw std::invalid_argument("a floating-base model needs base_pose (x y z qx qy qz qw)");
    Array qd;
    if (!qd_object.is_none()) {
      qd = qd_object.cast<Array>();
      if (qd.ndim() != 1 || qd.shape(0) != model_.nq)
        throw std::invalid_argument("qd must have " + std::to_string(model_.nq) + " entries");
    }
    return jle::toString(estimator_->addJointSample(t, q.data(),
                                                    model_.floating_base ? &base : nullptr,
                                                    qd_object.is_none() ? nullptr : qd.data()));
  }

  static jle::BasePose basePoseOf(const Array& p) {
    if (p.ndim() != 1 || p.shape(0) != 7)
      throw std::invalid_argument("base_pose must be 7 numbers (x y z qx qy qz qw)");
    jle::BasePose base;
    const double* x = p.data();
    base.position = Eigen::Vector3d(x[0], x[1], x[2]);
    base.orientation = Eigen::Quaterniond(x[6], x[3], x[4], x[5]);
    return base;
  }

  // The loads of the last published sample: m x 6 wrenches (child frame), m efforts.
  py::dict loads() const {
    const jle::Data<double>& d = estimator_->data();
    Array wrench({static_cast<py::ssize_t>(segments_.size()), py::ssize_t(6)});
    Array effort({static_cast<py::ssize_t>(segments_.size())});
    double *w = wrench.mutable_data(), *e = effort.mutable_data();
    for (int s : segments_) {
      putWrench(jle::jointWrench(estimator_->model(), d, s, jle::WrenchFrame::kChild), w);
      w += 6;
      *e++ = d.effort[static_cast<std::size_t>(s)];
    }
    py::dict out;
    out["t"] = estimator_->stamp();
    out["wrench"] = wrench;
    out["effort"] = effort;
    return out;
  }

  py::dict run(const Array& t, const Array& q, const py::list& wrenches);

 private:
  void appendLoads(std::vector<double>& stamps, std::vector<double>& w,
                   std::vector<double>& e) const;
  jle::Settings settings_;
  jle::Model<double> model_;
  std::unique_ptr<jle::Estimator> estimator_;
  std::vector<int> segments_;
};

// One wrench input's samples for run(): times [s] and n x 6 readings.
struct WrenchSeries {
  Array t, w;
  std::size_t next = 0;
};

std::vector<WrenchSeries> wrenchSeries(const py::list& wrenches, int inputs) {
  if (static_cast<int>(py::len(wrenches)) > inputs)
    throw std::invalid_argument("wrenches: " + std::to_string(py::len(wrenches)) + " series for " +
                                std::to_string(inputs) + " wrench inputs of the config");
  std::vector<WrenchSeries> series;
  for (std::size_t k = 0; k < py::len(wrenches); ++k) {
    const py::tuple pair = wrenches[k].cast<py::tuple>();
    if (pair.size() != 2) throw std::invalid_argument("wrenches[k] must be a pair (t, wrench)");
    WrenchSeries s{pair[0].cast<Array>(), pair[1].cast<Array>(), 0};
    const std::string what = "wrenches[" + std::to_string(k) + "]";
    if (s.t.ndim() != 1) throw std::invalid_argument(what + ": t must be one-dimensional");
    checkShape(s.w, static_cast<long>(s.t.shape(0)), 6, what + " readings");
    series.push_back(std::move(s));
  }
  return series;
}

void PyEstimator::appendLoads(std::vector<double>& stamps, std::vector<double>& w,
                              std::vector<double>& e) const {
  stamps.push_back(estimator_->stamp());
  const jle::Data<double>& d = estimator_->data();
  for (int s : segments_) {
    double out[6];
    putWrench(jle::jointWrench(estimator_->model(), d, s, jle::WrenchFrame::kChild), out);
    w.insert(w.end(), out, out + 6);
    e.push_back(d.effort[static_cast<std::size_t>(s)]);
  }
}

py::dict PyEstimator::run(const Array& t, const Array& q, const py::list& wrenches) {
  if (model_.floating_base)
    throw std::invalid_argument(
        "estimate(): a fixed-base model only; feed a floating base sample by sample "
        "(add_joint_sample with base_pose)");
  if (t.ndim() != 1) throw std::invalid_argument("t must be one-dimensional");
  const long n = static_cast<long>(t.shape(0));
  checkShape(q, n, model_.nq, "q");
  std::vector<WrenchSeries> series =
      wrenchSeries(wrenches, static_cast<int>(settings_.estimator.wrenches.size()));
  const std::size_t m = segments_.size();
  std::vector<double> stamps, w, e;
  std::vector<std::string> status(static_cast<std::size_t>(n));
  {
    py::gil_scoped_release release;
    for (long i = 0; i < n; ++i) {
      const double ti = t.data()[i];
      for (std::size_t k = 0; k < series.size(); ++k)  // every reading up to ti first
        for (WrenchSeries& s = series[k];
             s.next < static_cast<std::size_t>(s.t.shape(0)) && s.t.data()[s.next] <= ti;
             ++s.next) {
          const double* x = s.w.data() + 6 * s.next;
          estimator_->addWrench(static_cast<int>(k), s.t.data()[s.next],
                                Eigen::Vector3d(x[0], x[1], x[2]),
                                Eigen::Vector3d(x[3], x[4], x[5]));
        }
      const jle::SampleStatus st = estimator_->addJointSample(ti, q.data() + model_.nq * i);
      status[static_cast<std::size_t>(i)] = jle::toString(st);
      if (st == jle::SampleStatus::kPublished) appendLoads(stamps, w, e);
      // A smoother's other samples due at this one (after a longer interval, a gap).
      for (jle::SampleStatus due = st; estimator_->takeDue(due);)
        if (due == jle::SampleStatus::kPublished) appendLoads(stamps, w, e);
    }
    // A smoother's (differentiator/lag) last samples: smoothed with the data there is.
    jle::SampleStatus st = jle::SampleStatus::kPublished;
    while (estimator_->flush(st))
      if (st == jle::SampleStatus::kPublished) appendLoads(stamps, w, e);
  }
  const auto rows = static_cast<py::ssize_t>(stamps.size()), cols = static_cast<py::ssize_t>(m);
  py::dict out;
  out["t"] = Array(rows, stamps.data());
  out["wrench"] = Array({rows, cols, py::ssize_t(6)}, w.data());
  out["effort"] = Array({rows, cols}, e.data());
  out["status"] = status;
  return out;
}

// ---- zero-phase smoothing -------------------------------------------------------------

jle::ZeroPhaseConfig zeroPhaseConfig(const py::object& cutoff, const std::string& rule, int order,
                                     int padding) {
  jle::ZeroPhaseConfig z;
  if (!cutoff.is_none()) {
    z.rule = jle::CutoffRule::kFixed;
    z.cutoff = cutoff.cast<double>();
  } else if (!jle::parseCutoffRule(rule, z.rule)) {
    throw std::invalid_argument(
        "rule must be 'auto', 'spectrum', 'velocity', 'gcv' or 'residual', not '" + rule + "'");
  }
  z.order = order;
  z.padding = padding;
  return z;
}

std::vector<double> timesOf(const Array& t) {
  if (t.ndim() != 1) throw std::invalid_argument("t must be one-dimensional");
  return std::vector<double>(t.data(), t.data() + t.shape(0));
}

Eigen::MatrixXd matrixOf(const Array& x, std::size_t rows) {
  checkShape(x, static_cast<long>(rows), x.ndim() == 2 ? static_cast<long>(x.shape(1)) : 1, "x");
  Eigen::MatrixXd m(x.shape(0), x.shape(1));
  for (py::ssize_t i = 0; i < x.shape(0); ++i)
    for (py::ssize_t c = 0; c < x.shape(1); ++c) m(i, c) = x.data()[i * x.shape(1) + c];
  return m;
}

Array arrayOf(const Eigen::MatrixXd& m) {
  Array a({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  double* o = a.mutable_data();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index c = 0; c < m.cols(); ++c) *o++ = m(i, c);
  return a;
}

py::dict smoothZeroPhase(const Array& t_in, const Array& x_in, const py::object& cutoff,
                         const std::string& rule, int order, int padding) {
  const std::vector<double> t = timesOf(t_in);
  const Eigen::MatrixXd x = matrixOf(x_in, t.size());
  const jle::ZeroPhaseConfig z = zeroPhaseConfig(cutoff, rule, order, padding);
  jle::ZeroPhaseResult r;
  {
    py::gil_scoped_release release;
    r = jle::smoothZeroPhase(t, x, z);
  }
  py::dict out;
  out["value"] = arrayOf(r.value);
  out["rate"] = arrayOf(r.rate);
  out["accel"] = arrayOf(r.accel);
  out["cutoff"] = r.cutoff;
  return out;
}

Array lowPassZeroPhase(const Array& t_in, const Array& x_in, double cutoff, int order,
                       int padding) {
  const std::vector<double> t = timesOf(t_in);
  const Eigen::MatrixXd x = matrixOf(x_in, t.size());
  Eigen::MatrixXd y;
  {
    py::gil_scoped_release release;
    y = jle::lowPassZeroPhase(t, x, cutoff, order, padding);
  }
  return arrayOf(y);
}

// ---- a bag through the node's message path --------------------------------------------

// The records of one stream, kept as columns.
class RecordColumns {
 public:
  void add(const jle::LoadsRecord& r) {
    stamps_.push_back(r.stamp);
    for (std::size_t i = 0; i < r.joint.size(); ++i) {
      for (int c = 0; c < 3; ++c) wrench_.push_back(r.force[i][c]);
      for (int c = 0; c < 3; ++c) wrench_.push_back(r.moment[i][c]);
    }
    append(effort_, r.effort);
    append(stddev_, r.effort_stddev);
    append(position_, r.position);
    append(velocity_, r.velocity);
    append(acceleration_, r.acceleration);
    append(motor_, r.motor_effort);
    append(measured_, r.measured_effort);
  }
  py::dict result(const std::vector<std::string>& joints,
                  const std::vector<std::string>& links) const;

 private:
  static void append(std::vector<double>& to, const std::vector<double>& from) {
    to.insert(to.end(), from.begin(), from.end());
  }
  std::vector<jle::Stamp> stamps_;
  std::vector<double> wrench_, effort_, stddev_, position_, velocity_, acceleration_, motor_,
      measured_;
};

py::dict RecordColumns::result(const std::vector<std::string>& joints,
                               const std::vector<std::string>& links) const {
  const auto n = static_cast<py::ssize_t>(stamps_.size());
  const auto m = static_cast<py::ssize_t>(joints.size());
  const auto columns = [&](const std::vector<double>& v) {
    return Array({n, v.empty() ? py::ssize_t(0) : m}, v.data());
  };
  std::vector<double> t;
  for (jle::Stamp s : stamps_) t.push_back(jle::toRosTime(s).toSec());  // as process_bag writes
  py::dict out;
  out["joints"] = joints;
  out["links"] = links;
  out["frame"] = "child";
  out["t"] = Array(n, t.data());
  out["stamp_ns"] = py::array_t<std::int64_t>(n, stamps_.data());
  out["wrench"] = Array({n, m, py::ssize_t(6)}, wrench_.data());
  out["effort"] = columns(effort_);
  out["effort_stddev"] = columns(stddev_);
  out["position"] = columns(position_);
  out["velocity"] = columns(velocity_);
  out["acceleration"] = columns(acceleration_);
  out["motor_effort"] = columns(motor_);
  out["measured_effort"] = columns(measured_);
  return out;
}

// Every published record of both streams.
class RecordSink : public jle::LoadsSink {
 public:
  void open(const jle::Pipeline& pipeline) override {
    const jle::LoadsRecord& r = pipeline.record();
    joints_ = r.joint;
    links_ = r.link;
    has_smoothed_ = pipeline.hasSmoothed();
  }
  void write(const jle::LoadsRecord& r, long) override { immediate_.add(r); }
  void writeSmoothed(const jle::LoadsRecord& r, long) override { smoothed_.add(r); }
  // The immediate stream's columns, and its smoothed stream's under "smoothed" (None when
  // smoothed/enabled is false).
  py::dict result() const {
    py::dict out = immediate_.result(joints_, links_);
    out["smoothed"] = has_smoothed_ ? py::object(smoothed_.result(joints_, links_)) : py::none();
    return out;
  }

 private:
  std::vector<std::string> joints_, links_;
  bool has_smoothed_ = false;
  RecordColumns immediate_, smoothed_;
};

py::dict processBag(const std::string& bag, const std::string& urdf, const std::string& config,
                    const py::object& zero_phase, const std::string& cutoff_rule, bool summary) {
  jle::BagOptions options;
  options.bag = bag;
  options.urdf = urdf;
  options.config = config;
  options.summary = summary;
  if (!zero_phase.is_none()) {
    options.smooth = true;
    const bool automatic = py::isinstance<py::str>(zero_phase);
    if (automatic && zero_phase.cast<std::string>() != "auto")
      throw std::invalid_argument("zero_phase must be a cutoff [Hz], 'auto' or None");
    options.smoothing = zeroPhaseConfig(automatic ? py::none() : zero_phase, cutoff_rule, 4, 0);
  }
  RecordSink sink;
  {
    py::gil_scoped_release release;
    jle::processBag(options, sink);
  }
  return sink.result();
}

// ---- the module -----------------------------------------------------------------------

void defineModel(py::module_& m) {
  py::class_<PyModel>(m, "Model", "A robot (or body) model from a URDF: segments, joints, frames.")
      .def(py::init(&modelFromFile), py::arg("path"), py::kw_only(),
           py::arg("floating_base") = false,
           py::arg("keep_fixed_joints") = std::vector<std::string>(),
           "Reads a URDF file (errors name the file and the link or joint at fault).")
      .def_static("from_string", &modelFromString, py::arg("xml"), py::kw_only(),
                  py::arg("floating_base") = false,
                  py::arg("keep_fixed_joints") = std::vector<std::string>(),
                  "Parses a URDF document (e.g. the robot_description parameter).")
      .def_property_readonly("nq", [](const PyModel& p) { return p.model.nq; })
      .def_property_readonly("floating_base",
                             [](const PyModel& p) { return p.model.floating_base; })
      .def_property_readonly(
          "coordinate_names", [](const PyModel& p) { return p.model.coordinate_names; },
          "Names of the nq coordinates: the columns of q, qd, qdd.")
      .def_property_readonly(
          "joint_names",
          [](const PyModel& p) { return namesOf(p.model.joint_name, p.model.moving_segments); },
          "The joints whose loads inverse_dynamics returns (moving joints, URDF tree order, "
          "mimic joints included).")
      .def_property_readonly(
          "child_links",
          [](const PyModel& p) { return namesOf(p.model.link_name, p.model.moving_segments); },
          "The child link of each of joint_names: the frame of its wrench (frame='child').")
      .def_property_readonly(
          "link_names",
          [](const PyModel& p) {
            std::vector<std::string> names;
            for (const jle::Frame<double>& f : p.model.frames) names.push_back(f.name);
            return names;
          },
          "Every URDF link (where a wrench may be applied).")
      .def_property_readonly("total_mass", [](const PyModel& p) { return p.model.totalMass(); })
      .def_property_readonly("warnings", [](const PyModel& p) { return p.model.warnings; });
}

void defineEstimator(py::module_& m) {
  py::class_<PyEstimator>(m, "Estimator",
                          "The node's online estimator (filters, wrench inputs, loads).")
      .def(py::init<const PyModel&, const std::string&>(), py::arg("model"),
           py::arg("config") = std::string(),
           "config: the node's parameters as a YAML file (config/default.yaml); empty: the "
           "node's defaults.")
      .def("add_joint_sample", &PyEstimator::addJointSample, py::arg("t"), py::arg("q"),
           py::arg("base_pose") = py::none(), py::arg("qd") = py::none(),
           "qd: the measured joint velocities (NaN: none at this sample), used as the "
           "configuration's measured_velocity says.")
      .def(
          "add_wrench",
          [](PyEstimator& e, int k, double t, const std::vector<double>& f,
             const std::vector<double>& mom) {
            if (k < 0 || k >= static_cast<int>(e.settings().estimator.wrenches.size()))
              throw std::invalid_argument("no wrench input " + std::to_string(k));
            if (f.size() != 3 || mom.size() != 3)
              throw std::invalid_argument("force and moment must be 3 numbers each");
            return e.estimator().addWrench(k, t, Eigen::Vector3d(f[0], f[1], f[2]),
                                           Eigen::Vector3d(mom[0], mom[1], mom[2]));
          },
          py::arg("k"), py::arg("t"), py::arg("force"), py::arg("moment"))
      .def("reset", [](PyEstimator& e) { e.estimator().reset(); })
      .def(
          "flush",
          [](PyEstimator& e) -> py::object {
            jle::SampleStatus st = jle::SampleStatus::kPublished;
            if (!e.estimator().flush(st)) return py::none();
            return py::str(jle::toString(st));
          },
          "The end of a stream: with a smoother (differentiator/lag > 0) the next sample "
          "still to come, smoothed with the data there is: its status as add_joint_sample "
          "gives it ('published': loads() and stamp hold it), None when none is left.")
      .def("loads", &PyEstimator::loads)
      .def("run", &PyEstimator::run, py::arg("t"), py::arg("q"), py::arg("wrenches") = py::list())
      .def_property_readonly("joints",
                             [](const PyEstimator& e) {
                               return namesOf(e.estimator().model().joint_name, e.segments());
                             })
      .def_property_readonly("links",
                             [](const PyEstimator& e) {
                               return namesOf(e.estimator().model().link_name, e.segments());
                             })
      .def_property_readonly(
          "coordinate_names",
          [](const PyEstimator& e) { return e.estimator().model().coordinate_names; })
      .def_property_readonly("delay_samples",
                             [](const PyEstimator& e) { return e.estimator().delaySamples(); })
      .def_property_readonly("stamp", [](const PyEstimator& e) { return e.estimator().stamp(); })
      .def_property_readonly("q", [](const PyEstimator& e) { return e.estimator().q(); })
      .def_property_readonly("qd", [](const PyEstimator& e) { return e.estimator().qd(); })
      .def_property_readonly("qdd", [](const PyEstimator& e) { return e.estimator().qdd(); });
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "joint_load_estimator: per-segment 6x6 inverse dynamics (C++ core)";
  defineModel(m);
  m.def("_inverse_dynamics", &inverseDynamicsBatch, py::arg("model"), py::arg("q"), py::arg("qd"),
        py::arg("qdd"), py::arg("wrenches"), py::arg("frame"), py::arg("gravity"), py::arg("base"));
  defineEstimator(m);
  m.def("_smooth_zero_phase", &smoothZeroPhase, py::arg("t"), py::arg("x"), py::arg("cutoff"),
        py::arg("rule"), py::arg("order"), py::arg("padding"));
  m.def("_low_pass_zero_phase", &lowPassZeroPhase, py::arg("t"), py::arg("x"), py::arg("cutoff"),
        py::arg("order"), py::arg("padding"));
  m.def("_process_bag", &processBag, py::arg("bag"), py::arg("urdf"), py::arg("config"),
        py::arg("zero_phase"), py::arg("cutoff_rule"), py::arg("summary"));
  m.attr("default_gravity") = std::vector<double>{jle::EstimatorConfig().gravity_world[0],
                                                  jle::EstimatorConfig().gravity_world[1],
                                                  jle::EstimatorConfig().gravity_world[2]};
}
