// The records of one stream (jle::LoadsRecord, the whole result of each published sample)
// kept as numpy columns: what the Python modules return for a batch or a bag. ROS-free.
#pragma once

#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace jle_python {

namespace py = pybind11;
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Every output of the records of one stream, N records: per joint (N x joints [x k]),
/// per coordinate (N x nq), per wrench input, per plate, per contact, and per record.
class RecordColumns {
 public:
  /// `sized`: a record of the stream (Pipeline::record() as constructed will do).
  explicit RecordColumns(const jle::LoadsRecord& sized)
      : joints_(sized.joint),
        links_(sized.link),
        nq_(static_cast<std::size_t>(sized.q.size())),
        inputs_(sized.inputs.size()),
        plates_(sized.plates.size()),
        per_covariance_(sized.joint.empty() ? 0 : sized.covariance.size() / sized.joint.size()) {
    for (const jle::ContactEstimate& c : sized.contacts) contact_names_.push_back(c.link);
  }

  void add(const jle::LoadsRecord& r) {
    ++count_;
    stamps_.push_back(r.stamp);
    for (std::size_t i = 0; i < r.joint.size(); ++i) {
      put(wrench_, r.force[i]);
      put(wrench_, r.moment[i]);
    }
    for (std::size_t j = 0; j < kPerJoint; ++j) append(per_joint_[j], *fieldOf(r, j));
    append(covariance_, r.covariance);
    for (const Eigen::VectorXd* v : {&r.q, &r.qd, &r.qdd})
      coordinates_.insert(coordinates_.end(), v->data(), v->data() + v->size());
    for (const jle::InputRecord& in : r.inputs) {
      put(residual_, in.residual.force);
      put(residual_, in.residual.moment);
      input_used_.push_back(in.used);
      input_stale_.push_back(in.stale);
    }
    for (const jle::PlateRecord& p : r.plates) {
      put(cop_, p.reading.cop_plate);
      put(plate_wrench_, p.reading.force_on_foot_plate);
      put(plate_wrench_, p.reading.moment_on_foot_plate);
      plate_scalars_.push_back(p.reading.normal_force);
      plate_scalars_.push_back(p.reading.free_moment);
      plate_contact_.push_back(p.reading.contact);
      plate_stale_.push_back(p.stale);
    }
    for (const jle::ContactEstimate& c : r.contacts) {
      put(contact_wrench_, c.force);
      put(contact_wrench_, c.moment);
      contact_active_.push_back(c.active);
    }
    put(base_, r.base_force);
    put(base_, r.base_moment);
    in_contact_.push_back(r.in_contact);
    contact_started_.push_back(r.contact_started);
    contact_ended_.push_back(r.contact_ended);
    contact_changed_.push_back(r.contact_changed);
    contact_joint_.push_back(r.contact_joint);
    contact_link_.push_back(r.contact_link);
    planar_.push_back(r.planar);
    status_.push_back(r.status);
  }

  /// The columns; `seconds` turns a stamp [ns] into the `t` column [s].
  py::dict result(const std::function<double(jle::Stamp)>& seconds) const {
    const auto n = static_cast<py::ssize_t>(count_);
    const auto m = static_cast<py::ssize_t>(joints_.size());
    py::dict out;
    out["joints"] = joints_;
    out["links"] = links_;
    out["frame"] = "child";
    std::vector<double> t;
    for (jle::Stamp s : stamps_) t.push_back(seconds(s));
    out["t"] = Array(n, t.data());
    out["stamp_ns"] = py::array_t<std::int64_t>(n, stamps_.data());
    out["wrench"] = Array({n, m, py::ssize_t(6)}, wrench_.data());
    for (std::size_t j = 0; j < kPerJoint; ++j) {
      const std::vector<double>& v = per_joint_[j];
      out[kPerJointNames[j]] = Array({n, v.empty() ? py::ssize_t(0) : m}, v.data());
    }
    const auto per = static_cast<py::ssize_t>(per_covariance_);
    out["covariance"] = Array({n, per ? m : 0, per}, covariance_.data());
    const auto nq = static_cast<py::ssize_t>(nq_);
    Array coordinates({n, py::ssize_t(3), nq}, coordinates_.data());
    out["q"] = coordinates[py::make_tuple(py::slice(0, n, 1), 0)];
    out["qd"] = coordinates[py::make_tuple(py::slice(0, n, 1), 1)];
    out["qdd"] = coordinates[py::make_tuple(py::slice(0, n, 1), 2)];
    putInputs(out, n);
    putPlates(out, n);
    const auto c = static_cast<py::ssize_t>(contact_names_.size());
    out["contact_links"] = contact_names_;
    out["contact_wrench"] = Array({n, c, py::ssize_t(6)}, contact_wrench_.data());
    out["contact_active"] = flags(contact_active_, {n, c});
    out["in_contact"] = flags(in_contact_, {n});
    out["contact_started"] = flags(contact_started_, {n});
    out["contact_changed"] = flags(contact_changed_, {n});
    out["contact_ended"] = flags(contact_ended_, {n});
    out["contact_joint"] = contact_joint_;
    out["contact_link"] = contact_link_;
    out["base_residual"] = Array({n, py::ssize_t(6)}, base_.data());
    out["planar"] = flags(planar_, {n});
    out["status"] = py::array_t<std::uint8_t>(n, status_.data());
    return out;
  }

 private:
  static constexpr std::size_t kPerJoint = 10;
  static constexpr const char* kPerJointNames[kPerJoint] = {
      "effort",   "effort_stddev", "effort_per_kg", "measured_effort", "position",
      "velocity", "acceleration",  "motor_effort",  "external_effort", "external_effort_stddev"};
  static const std::vector<double>* fieldOf(const jle::LoadsRecord& r, std::size_t j) {
    const std::vector<double>* fields[kPerJoint] = {&r.effort,          &r.effort_stddev,
                                                    &r.effort_per_kg,   &r.measured_effort,
                                                    &r.position,        &r.velocity,
                                                    &r.acceleration,    &r.motor_effort,
                                                    &r.external_effort, &r.external_effort_stddev};
    return fields[j];
  }
  void putInputs(py::dict& out, py::ssize_t n) const {
    const auto k = static_cast<py::ssize_t>(inputs_);
    out["input_residual"] = Array({n, k, py::ssize_t(6)}, residual_.data());
    out["input_used"] = flags(input_used_, {n, k});
    out["input_stale"] = flags(input_stale_, {n, k});
  }
  void putPlates(py::dict& out, py::ssize_t n) const {
    const auto p = static_cast<py::ssize_t>(plates_);
    out["cop"] = Array({n, p, py::ssize_t(3)}, cop_.data());
    out["plate_reaction"] = Array({n, p, py::ssize_t(6)}, plate_wrench_.data());
    Array scalars({n, p, py::ssize_t(2)}, plate_scalars_.data());
    out["normal_force"] = scalars[py::make_tuple(py::ellipsis(), 0)];
    out["free_moment"] = scalars[py::make_tuple(py::ellipsis(), 1)];
    out["plate_contact"] = flags(plate_contact_, {n, p});
    out["plate_stale"] = flags(plate_stale_, {n, p});
  }
  static py::array_t<bool> flags(const std::vector<char>& v, std::vector<py::ssize_t> shape) {
    py::array_t<bool> a(shape);
    bool* o = a.mutable_data();
    for (char c : v) *o++ = c != 0;
    return a;
  }
  static void append(std::vector<double>& to, const std::vector<double>& from) {
    to.insert(to.end(), from.begin(), from.end());
  }
  static void put(std::vector<double>& to, const Eigen::Vector3d& v) {
    to.insert(to.end(), v.data(), v.data() + 3);
  }

  std::vector<std::string> joints_, links_;
  std::size_t nq_, inputs_, plates_, per_covariance_;
  std::size_t count_ = 0;
  std::vector<std::string> contact_names_, contact_joint_, contact_link_;
  std::vector<jle::Stamp> stamps_;
  std::vector<double> wrench_, covariance_, coordinates_, residual_, cop_, plate_wrench_,
      plate_scalars_, contact_wrench_, base_;
  std::vector<double> per_joint_[kPerJoint];
  std::vector<std::uint8_t> status_;
  std::vector<char> input_used_, input_stale_, plate_contact_, plate_stale_, in_contact_,
      contact_active_, contact_started_, contact_changed_, contact_ended_, planar_;
};

}  // namespace jle_python
