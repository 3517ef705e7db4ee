// The Python module joint_load_estimator._core (pybind11), ROS-free: the model, batch
// inverse dynamics over numpy arrays, the online estimator (jle::Pipeline, the node's
// message path: joint states, wrenches, plates and frames in, the whole record out) and
// the offline zero-phase smoothing. A front end: it converts arrays and names and calls
// the core; src/joint_load_estimator/__init__.py re-exports it (bag_bindings.cpp, the
// module _bag, reads bags). docs/python.md.
#include "records.hpp"

#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>
#include <joint_load_estimator/settings/config.hpp>
#include <joint_load_estimator/settings/settings_reader.hpp>

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
#include <map>
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

// A model and how it was made (PyEstimator rebuilds it with a config's model options).
struct PyModel {
  jle::Model<double> model;
  std::string xml;
  jle::ModelOptions options;
};

PyModel modelFromString(const std::string& xml, bool floating_base,
                        const std::vector<std::string>& keep_fixed_joints,
                        bool accept_nonphysical_inertia) {
  PyModel m;
  m.xml = xml;
  m.options.floating_base = floating_base;
  m.options.keep_fixed_joints = keep_fixed_joints;
  m.options.accept_nonphysical_inertia = accept_nonphysical_inertia;
  m.model = jle::modelFromUrdfString(xml, m.options);
  return m;
}

PyModel modelFromFile(const std::string& path, bool floating_base,
                      const std::vector<std::string>& keep_fixed_joints,
                      bool accept_nonphysical_inertia) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  PyModel m;
  m.xml = text.str();
  m.options.floating_base = floating_base;
  m.options.keep_fixed_joints = keep_fixed_joints;
  m.options.accept_nonphysical_inertia = accept_nonphysical_inertia;
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

// ---- the online estimator: jle::Pipeline, the node's message path ----------------------

// Stamps [ns] of the estimator's times t [s]: t = 0 is this stamp (a message path takes
// stamps, and stamp 0 means "none" on a stream that has had stamps).
constexpr jle::Stamp kOrigin = 1000000000LL * 1000000000LL;

jle::Stamp stampOf(double t) {
  if (!std::isfinite(t) || std::abs(t) > 1e9)
    throw std::invalid_argument("t must be a finite time [s] within 1e9 s of 0");
  return kOrigin + static_cast<jle::Stamp>(std::llround(t * 1e9));
}

double secondsOf(jle::Stamp stamp) { return 1e-9 * static_cast<double>(stamp - kOrigin); }

// Frames the URDF does not hold rigidly, as Python sets them (tf2's role in the node).
class PyFrames : public jle::FrameSource {
 public:
  void set(const std::string& target, const std::string& frame, const Eigen::Isometry3d& X) {
    poses_[{target, frame}] = X;
  }
  bool lookup(const std::string& target, const std::string& frame, jle::Stamp, Eigen::Isometry3d& X,
              std::string& error) override {
    const auto it = poses_.find({target, frame});
    if (it == poses_.end()) {
      error = "no transform set (Estimator.set_transform('" + target + "', '" + frame + "', pose))";
      return false;
    }
    X = it->second;
    return true;
  }

 private:
  std::map<std::pair<std::string, std::string>, Eigen::Isometry3d> poses_;
};

Eigen::Isometry3d poseOf(const Array& p, const std::string& what) {
  if (p.ndim() != 1 || p.shape(0) != 7)
    throw std::invalid_argument(what + " must be 7 numbers (x y z qx qy qz qw)");
  const double* x = p.data();
  const Eigen::Quaterniond o(x[6], x[3], x[4], x[5]);
  if (!(std::abs(o.norm() - 1.0) <= 0.01))
    throw std::invalid_argument(what + ": the quaternion (qx, qy, qz, qw) has norm " +
                                std::to_string(o.norm()) + ", not 1 (within 1 %)");
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = o.normalized().toRotationMatrix();
  X.translation() = Eigen::Vector3d(x[0], x[1], x[2]);
  return X;
}

std::vector<double> valuesOf(const py::object& given, std::size_t n, const std::string& what) {
  if (given.is_none()) return {};
  const Array a = given.cast<Array>();
  if (a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != n)
    throw std::invalid_argument(what + " must have " + std::to_string(n) + " entries");
  return std::vector<double>(a.data(), a.data() + n);
}

Eigen::Vector3d vector3Of(const Array& a, const std::string& what) {
  if (a.ndim() != 1 || a.shape(0) != 3) throw std::invalid_argument(what + " must be 3 numbers");
  return Eigen::Vector3d(a.data()[0], a.data()[1], a.data()[2]);
}

// The node's message path with the model and settings it was made from.
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
    options.accept_nonphysical_inertia =
        options.accept_nonphysical_inertia || m.options.accept_nonphysical_inertia;
    for (const std::string& j : m.options.keep_fixed_joints)
      if (std::find(options.keep_fixed_joints.begin(), options.keep_fixed_joints.end(), j) ==
          options.keep_fixed_joints.end())
        options.keep_fixed_joints.push_back(j);
    model_ = jle::modelFromUrdfString(m.xml, options);
    reset();
  }

  // A new pipeline: every filter and counter from the start (the transforms are kept).
  void reset() { pipeline_ = std::make_unique<jle::Pipeline>(model_, settings_, &frames_); }
  const jle::Pipeline& pipeline() const { return *pipeline_; }
  jle::Pipeline& pipeline() { return *pipeline_; }

  void setTransform(const std::string& target, const std::string& frame, const Array& pose) {
    frames_.set(target, frame, poseOf(pose, "pose"));
  }

  std::string addJointState(double t, const py::object& names_given, const Array& q,
                            const py::object& qd, const py::object& effort,
                            const py::object& base_pose) {
    if (q.ndim() != 1) throw std::invalid_argument("q must be one-dimensional");
    const std::size_t n = static_cast<std::size_t>(q.shape(0));
    const std::vector<std::string> names = names_given.is_none()
                                               ? model_.coordinate_names
                                               : names_given.cast<std::vector<std::string>>();
    if (names.size() != n)
      throw std::invalid_argument("names has " + std::to_string(names.size()) + " entries and q " +
                                  std::to_string(n));
    if (!base_pose.is_none()) setBasePose(base_pose.cast<Array>());
    const jle::Stamp stamp = stampOf(t);
    return jle::toString(
        pipeline_->onJointState(stamp, stamp, names, std::vector<double>(q.data(), q.data() + n),
                                valuesOf(qd, n, "qd"), valuesOf(effort, n, "effort")));
  }

  std::string addWrench(int k, double t, const Array& force, const Array& moment,
                        const std::string& frame) {
    const jle::Settings& s = pipeline_->settings();
    if (k < 0 || k >= static_cast<int>(s.wrenches.size()))
      throw std::invalid_argument("no wrench input " + std::to_string(k));
    const jle::Stamp stamp = stampOf(t);
    const std::size_t i = static_cast<std::size_t>(k);
    const std::string& given = !frame.empty()                 ? frame
                               : !s.wrenches[i].frame.empty() ? s.wrenches[i].frame
                                                              : s.estimator.wrenches[i].link;
    return jle::toString(pipeline_->onWrench(k, stamp, stamp, given, vector3Of(force, "force"),
                                             vector3Of(moment, "moment")));
  }

  std::string addPlate(int k, double t, const Array& force, const Array& moment,
                       const std::string& frame) {
    const jle::Settings& s = pipeline_->settings();
    if (k < 0 || k >= static_cast<int>(s.force_plates.size()))
      throw std::invalid_argument("no force plate " + std::to_string(k));
    const jle::Stamp stamp = stampOf(t);
    const std::string& given =
        frame.empty() ? s.force_plates[static_cast<std::size_t>(k)].frame : frame;
    return jle::toString(pipeline_->onPlate(k, stamp, stamp, given, vector3Of(force, "force"),
                                            vector3Of(moment, "moment")));
  }

  py::dict record(bool smoothed) const {
    if (smoothed && !pipeline_->hasSmoothed())
      throw std::invalid_argument("smoothed/enabled is false: no smoothed stream");
    const jle::LoadsRecord& r = smoothed ? pipeline_->smoothedRecord() : pipeline_->record();
    jle_python::RecordColumns one(r);
    one.add(r);
    return one.result(&secondsOf);
  }

  // The loads of the last published sample: m x 6 wrenches (child frame), m efforts.
  py::dict loads() const {
    const jle::LoadsRecord& r = pipeline_->record();
    const auto m = static_cast<py::ssize_t>(r.joint.size());
    Array wrench({m, py::ssize_t(6)});
    double* w = wrench.mutable_data();
    for (std::size_t i = 0; i < r.joint.size(); ++i, w += 6)
      for (int c = 0; c < 3; ++c) w[c] = r.force[i][c], w[3 + c] = r.moment[i][c];
    py::dict out;
    out["t"] = secondsOf(r.stamp);
    out["wrench"] = wrench;
    out["effort"] = Array(m, r.effort.data());
    return out;
  }

  py::dict run(const Array& t, const Array& q, const py::list& wrenches, const py::object& qd,
               const py::object& base_pose);

 private:
  void setBasePose(const Array& pose) {
    const jle::Settings& s = pipeline_->settings();
    frames_.set(s.world_frame, s.base_frame, poseOf(pose, "base_pose"));
  }

  jle::Settings settings_;
  jle::Model<double> model_;
  PyFrames frames_;
  std::unique_ptr<jle::Pipeline> pipeline_;
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
    for (py::ssize_t i = 0; i < s.t.shape(0); ++i) stampOf(s.t.data()[i]);  // checked here
    series.push_back(std::move(s));
  }
  return series;
}

// An optional N x cols array of run(), checked; null when not given.
const double* rowsOf(const py::object& given, long n, long cols, const std::string& what,
                     std::vector<Array>& keep) {
  if (given.is_none()) return nullptr;
  keep.push_back(given.cast<Array>());
  checkShape(keep.back(), n, cols, what);
  return keep.back().data();
}

py::dict PyEstimator::run(const Array& t, const Array& q, const py::list& wrenches,
                          const py::object& qd_given, const py::object& base_given) {
  if (t.ndim() != 1) throw std::invalid_argument("t must be one-dimensional");
  const long n = static_cast<long>(t.shape(0));
  checkShape(q, n, model_.nq, "q");
  std::vector<Array> keep;
  const double* qd = rowsOf(qd_given, n, model_.nq, "qd", keep);
  const double* base = rowsOf(base_given, n, 7, "base_pose", keep);
  if (model_.floating_base && !base)
    throw std::invalid_argument("a floating-base model needs base_pose (N x 7)");
  for (long i = 0; i < n; ++i) stampOf(t.data()[i]);
  std::vector<WrenchSeries> series =
      wrenchSeries(wrenches, static_cast<int>(pipeline_->settings().wrenches.size()));
  std::vector<Eigen::Isometry3d> poses;
  for (long i = 0; base && i < n; ++i) {
    Array row(py::ssize_t(7), base + 7 * i);
    poses.push_back(poseOf(row, "base_pose[" + std::to_string(i) + "]"));
  }
  jle_python::RecordColumns immediate(pipeline_->record());
  std::unique_ptr<jle_python::RecordColumns> smoothed;
  if (pipeline_->hasSmoothed())
    smoothed = std::make_unique<jle_python::RecordColumns>(pipeline_->smoothedRecord());
  std::vector<std::string> status(static_cast<std::size_t>(n));
  {
    py::gil_scoped_release release;
    jle::Pipeline& p = *pipeline_;
    const jle::Settings& s = p.settings();
    const std::vector<double> none;
    std::vector<double> position(static_cast<std::size_t>(model_.nq)), velocity;
    if (qd) velocity.resize(position.size());
    const auto drain = [&] {
      while (p.takeDrained()) immediate.add(p.record());
      if (!smoothed) return;
      if (p.smoothedPublished()) smoothed->add(p.smoothedRecord());
      while (p.takeDrainedSmoothed()) smoothed->add(p.smoothedRecord());
    };
    for (long i = 0; i < n; ++i) {
      const double ti = t.data()[i];
      for (std::size_t k = 0; k < series.size(); ++k)  // every reading up to ti first
        for (WrenchSeries& w = series[k];
             w.next < static_cast<std::size_t>(w.t.shape(0)) && w.t.data()[w.next] <= ti;
             ++w.next) {
          const double* x = w.w.data() + 6 * w.next;
          const jle::Stamp stamp = stampOf(w.t.data()[w.next]);
          const std::string& frame =
              s.wrenches[k].frame.empty() ? s.estimator.wrenches[k].link : s.wrenches[k].frame;
          p.onWrench(static_cast<int>(k), stamp, stamp, frame, Eigen::Vector3d(x[0], x[1], x[2]),
                     Eigen::Vector3d(x[3], x[4], x[5]));
          drain();
        }
      std::copy(q.data() + model_.nq * i, q.data() + model_.nq * (i + 1), position.begin());
      if (qd) std::copy(qd + model_.nq * i, qd + model_.nq * (i + 1), velocity.begin());
      if (base) frames_.set(s.world_frame, s.base_frame, poses[static_cast<std::size_t>(i)]);
      const jle::Stamp stamp = stampOf(ti);
      const jle::Outcome o =
          p.onJointState(stamp, stamp, model_.coordinate_names, position, velocity, none);
      status[static_cast<std::size_t>(i)] = jle::toString(o);
      if (o == jle::Outcome::kPublished) immediate.add(p.record());
      drain();
    }
    // A smoother's last samples: smoothed with the data there is.
    while (p.flush()) immediate.add(p.record());
    while (smoothed && p.flushSmoothed()) smoothed->add(p.smoothedRecord());
  }
  py::dict out = immediate.result(&secondsOf);
  // "status" is what became of each joint state here (the documented key); the records'
  // own status bits (trusted, settling, stale input, implausible load) move aside.
  out["loads_status"] = py::object(out["status"]);
  out["status"] = status;
  out["smoothed"] = smoothed ? py::object(smoothed->result(&secondsOf)) : py::none();
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
                         const std::string& rule, int order, int padding, const py::dict& forces) {
  const std::vector<double> t = timesOf(t_in);
  const Eigen::MatrixXd x = matrixOf(x_in, t.size());
  const jle::ZeroPhaseConfig z = zeroPhaseConfig(cutoff, rule, order, padding);
  std::vector<jle::FilteredAlike> alike;
  for (const auto& [name, pair] : forces) {
    const auto [tf, xf] = pair.cast<std::pair<Array, Array>>();
    alike.push_back({timesOf(tf), Eigen::MatrixXd(), py::str(name)});
    alike.back().x = matrixOf(xf, alike.back().t.size());
  }
  jle::ZeroPhaseResult r;
  {
    py::gil_scoped_release release;
    r = jle::smoothZeroPhase(t, x, z, Eigen::MatrixXd(), alike);
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

// ---- the module -----------------------------------------------------------------------

void defineModel(py::module_& m) {
  py::class_<PyModel>(m, "Model", "A robot (or body) model from a URDF: segments, joints, frames.")
      .def(py::init(&modelFromFile), py::arg("path"), py::kw_only(),
           py::arg("floating_base") = false,
           py::arg("keep_fixed_joints") = std::vector<std::string>(),
           py::arg("accept_nonphysical_inertia") = false,
           "Reads a URDF file (errors name the file and the link or joint at fault). "
           "accept_nonphysical_inertia: keep an inertia that is not physical (identified "
           "parameters), with a warning per violation, instead of refusing the model.")
      .def_static("from_string", &modelFromString, py::arg("xml"), py::kw_only(),
                  py::arg("floating_base") = false,
                  py::arg("keep_fixed_joints") = std::vector<std::string>(),
                  py::arg("accept_nonphysical_inertia") = false,
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

py::dict counters(const jle::Pipeline& p) {
  const jle::PipelineCounters& c = p.counters();
  py::dict out;
  const char* kinds[] = {"joint_state", "wrench", "plate"};
  for (int k = 0; k < static_cast<int>(jle::InputKind::kCount); ++k) {
    py::dict per;
    for (int o = 0; o < static_cast<int>(jle::Outcome::kCount); ++o)
      per[jle::toString(static_cast<jle::Outcome>(o))] = c.outcomes[k][o];
    out[kinds[k]] = per;
  }
  out["unknown_joints"] = c.unknown_joints;
  out["resets"] = c.resets;
  out["nonfinite_efforts"] = c.nonfinite_efforts;
  out["nonfinite_velocities"] = c.nonfinite_velocities;
  out["mimic_contradictions"] = c.mimic_contradictions;
  out["held_samples"] = c.held_samples;
  return out;
}

void defineEstimatorInputs(py::class_<PyEstimator>& c) {
  c.def("add_joint_state", &PyEstimator::addJointState, py::arg("t"), py::kw_only(),
        py::arg("names") = py::none(), py::arg("q"), py::arg("qd") = py::none(),
        py::arg("effort") = py::none(), py::arg("base_pose") = py::none(),
        "A JointState: names (default: coordinate_names), positions, and optionally measured "
        "velocities and efforts (NaN: none for that joint), and a floating base's pose (x y z "
        "qx qy qz qw in world_frame). Returns what became of it: 'published' (record() holds "
        "its loads), 'used', or the reason it was not used ('invalid', 'stamp order', ...; "
        "problem says why).")
      .def(
          "add_joint_sample",
          [](PyEstimator& e, double t, const Array& q, const py::object& base_pose,
             const py::object& qd) {
            return e.addJointState(t, py::none(), q, qd, py::none(), base_pose);
          },
          py::arg("t"), py::arg("q"), py::arg("base_pose") = py::none(), py::arg("qd") = py::none(),
          "add_joint_state with q in coordinate_names order.")
      .def("add_wrench", &PyEstimator::addWrench, py::arg("k"), py::arg("t"), py::arg("force"),
           py::arg("moment"), py::arg("frame") = std::string(),
           "A reading of wrench input k of the config: force [N], moment [N m] about the origin "
           "of `frame` (default: the input's configured frame, else its link). Returns its "
           "outcome ('used', or why not).")
      .def("add_plate", &PyEstimator::addPlate, py::arg("k"), py::arg("t"), py::arg("force"),
           py::arg("moment"), py::arg("frame") = std::string(),
           "A sample of force plate k of the config: what the foot applies to the plate, plate "
           "frame (default: the configured frame), moment about its origin.")
      .def("set_transform", &PyEstimator::setTransform, py::arg("target"), py::arg("frame"),
           py::arg("pose"),
           "The pose (x y z qx qy qz qw) of `frame` in `target`, for frames the URDF does not "
           "hold rigidly (tf2's role in the node: a plate's frame in the world, a sensor's "
           "frame); kept until set again.")
      .def("reset", &PyEstimator::reset, "Every filter and counter from the start.");
}

void defineEstimatorOutputs(py::class_<PyEstimator>& c) {
  c.def("_record", &PyEstimator::record, py::arg("smoothed") = false,
        "The last published record as Loads arrays of one sample (every output: loads, "
        "efforts, coordinates, sensor residuals, plates, base residual, external efforts).")
      .def("loads", &PyEstimator::loads)
      .def(
          "take_drained", [](PyEstimator& e) { return e.pipeline().takeDrained(); },
          "After every input: true while another record is due (a smoother's), each then in "
          "record().")
      .def("take_drained_smoothed",
           [](PyEstimator& e) { return e.pipeline().takeDrainedSmoothed(); })
      .def(
          "smoothed_published",
          [](const PyEstimator& e) { return e.pipeline().smoothedPublished(); },
          "Whether the last input put a smoothed record in record(smoothed=True).")
      .def(
          "flush",
          [](PyEstimator& e) -> py::object {
            if (!e.pipeline().flush()) return py::none();
            return py::str("published");
          },
          "The end of a stream: with a smoother (differentiator/lag > 0) the next sample "
          "still to come, smoothed with the data there is ('published': record() holds it), "
          "None when none is left.")
      .def(
          "flush_smoothed", [](PyEstimator& e) { return e.pipeline().flushSmoothed(); },
          "As flush, for the smoothed stream: true while a record was put in "
          "record(smoothed=True).")
      .def("run", &PyEstimator::run, py::arg("t"), py::arg("q"), py::arg("wrenches") = py::list(),
           py::arg("qd") = py::none(), py::arg("base_pose") = py::none());
}

void defineEstimator(py::module_& m) {
  py::class_<PyEstimator> c(m, "Estimator",
                            "The node's message path (jle::Pipeline): its filters, checks, "
                            "both streams and every output.");
  c.def(py::init<const PyModel&, const std::string&>(), py::arg("model"),
        py::arg("config") = std::string(),
        "config: the node's parameters as a YAML file (config/default.yaml); empty: the node's "
        "defaults.");
  defineEstimatorInputs(c);
  defineEstimatorOutputs(c);
  c.def_property_readonly("joints",
                          [](const PyEstimator& e) { return e.pipeline().record().joint; })
      .def_property_readonly("links",
                             [](const PyEstimator& e) { return e.pipeline().record().link; })
      .def_property_readonly(
          "coordinate_names",
          [](const PyEstimator& e) { return e.pipeline().model().coordinate_names; })
      .def_property_readonly("delay_samples",
                             [](const PyEstimator& e) { return e.pipeline().delaySamples(); })
      .def_property_readonly("has_smoothed",
                             [](const PyEstimator& e) { return e.pipeline().hasSmoothed(); })
      .def_property_readonly(
          "stamp", [](const PyEstimator& e) { return secondsOf(e.pipeline().record().stamp); })
      .def_property_readonly("q", [](const PyEstimator& e) { return e.pipeline().record().q; })
      .def_property_readonly("qd", [](const PyEstimator& e) { return e.pipeline().record().qd; })
      .def_property_readonly("qdd", [](const PyEstimator& e) { return e.pipeline().record().qdd; })
      .def_property_readonly("problem", [](const PyEstimator& e) { return e.pipeline().problem(); })
      .def_property_readonly("counters",
                             [](const PyEstimator& e) { return counters(e.pipeline()); });
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "joint_load_estimator: per-segment 6x6 inverse dynamics (C++ core)";
  defineModel(m);
  m.def("_inverse_dynamics", &inverseDynamicsBatch, py::arg("model"), py::arg("q"), py::arg("qd"),
        py::arg("qdd"), py::arg("wrenches"), py::arg("frame"), py::arg("gravity"), py::arg("base"));
  defineEstimator(m);
  m.def("_smooth_zero_phase", &smoothZeroPhase, py::arg("t"), py::arg("x"), py::arg("cutoff"),
        py::arg("rule"), py::arg("order"), py::arg("padding"), py::arg("forces"));
  m.def("_low_pass_zero_phase", &lowPassZeroPhase, py::arg("t"), py::arg("x"), py::arg("cutoff"),
        py::arg("order"), py::arg("padding"));
  m.attr("default_gravity") = std::vector<double>{jle::EstimatorConfig().gravity_world[0],
                                                  jle::EstimatorConfig().gravity_world[1],
                                                  jle::EstimatorConfig().gravity_world[2]};
}
