// The Python module joint_load_estimator._bag (pybind11): a bag through the node's
// message path (jle::processBag, bag_processing.hpp), both streams' records as numpy
// columns. The one part of the bindings that needs ROS (rosbag, tf2): imported by
// joint_load_estimator.process_bag only, so that the core module loads without ROS.
#include "records.hpp"

#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/ros/bag_processing.hpp>

#include <pybind11/pybind11.h>

#include <memory>
#include <stdexcept>
#include <string>

namespace py = pybind11;
using jle_python::RecordColumns;

namespace {

// Every published record of both streams.
class RecordSink : public jle::LoadsSink {
 public:
  void open(const jle::Pipeline& pipeline) override {
    immediate_ = std::make_unique<RecordColumns>(pipeline.record());
    if (pipeline.hasSmoothed())
      smoothed_ = std::make_unique<RecordColumns>(pipeline.smoothedRecord());
  }
  void write(const jle::LoadsRecord& r, long) override { immediate_->add(r); }
  void writeSmoothed(const jle::LoadsRecord& r, long) override { smoothed_->add(r); }
  // The immediate stream's columns, and its smoothed stream's under "smoothed" (None when
  // smoothed/enabled is false). `t` as process_bag --csv writes it: sec + 1e-9 nsec.
  py::dict result() const {
    const auto seconds = [](jle::Stamp s) {
      return static_cast<double>(s / 1000000000) + 1e-9 * static_cast<double>(s % 1000000000);
    };
    py::dict out = immediate_->result(seconds);
    out["smoothed"] = smoothed_ ? py::object(smoothed_->result(seconds)) : py::none();
    return out;
  }

 private:
  std::unique_ptr<RecordColumns> immediate_, smoothed_;
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
    if (py::isinstance<py::str>(zero_phase)) {
      if (zero_phase.cast<std::string>() != "auto")
        throw std::invalid_argument("zero_phase must be a cutoff [Hz], 'auto' or None");
      if (!jle::parseCutoffRule(cutoff_rule, options.smoothing.rule))
        throw std::invalid_argument(
            "cutoff_rule must be 'auto', 'spectrum', 'velocity', 'gcv' or 'residual', not '" +
            cutoff_rule + "'");
    } else {
      options.smoothing.rule = jle::CutoffRule::kFixed;
      options.smoothing.cutoff = zero_phase.cast<double>();
    }
  }
  RecordSink sink;
  {
    py::gil_scoped_release release;
    jle::processBag(options, sink);
  }
  return sink.result();
}

}  // namespace

PYBIND11_MODULE(_bag, m) {
  m.doc() = "joint_load_estimator: process_bag's code over a bag (needs ROS)";
  m.def("_process_bag", &processBag, py::arg("bag"), py::arg("urdf"), py::arg("config"),
        py::arg("zero_phase"), py::arg("cutoff_rule"), py::arg("summary"));
}
