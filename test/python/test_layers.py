"""The layers: the front ends (the node and nodelet in src/ros, the offline tools in
src/tools, the Python modules in src/python) reach the computation only through jle::Pipeline and read only its record;
none of them names the estimator behind it (jle::Estimator, estimator.hpp,
Pipeline::estimator(), which is not public). Run by test/CMakeLists.txt under pytest."""

import os
import re

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
FRONT_ENDS = ["src/ros", "src/tools", "src/python", "include/joint_load_estimator/ros"]
BEHIND_THE_PIPELINE = re.compile(
    r"(?<![A-Za-z_/\"])Estimator(?![A-Za-z_.\"])|estimator\.hpp|\.estimator\(\)|->estimator\(\)")


def sources(folder):
    for root, _, files in os.walk(os.path.join(REPO, folder)):
        for name in sorted(files):
            if name.endswith((".cpp", ".hpp", ".h")):
                yield os.path.join(root, name)


def test_front_ends_do_not_reach_behind_the_pipeline():
    found = []
    for folder in FRONT_ENDS:
        for path in sources(folder):
            with open(path, encoding="utf-8") as f:
                for number, line in enumerate(f, 1):
                    if BEHIND_THE_PIPELINE.search(line):
                        found.append("%s:%d: %s" % (os.path.relpath(path, REPO), number,
                                                   line.strip()))
    assert not found, "front ends reaching behind jle::Pipeline:\n" + "\n".join(found)


def test_the_pattern_finds_what_it_must():
    for line in ["const jle::Estimator& e = p.estimator();", "#include <x/estimator.hpp>",
                 "pipeline_->estimator().data()", "Estimator estimator(model, config);"]:
        assert BEHIND_THE_PIPELINE.search(line), line
    for line in ["BiasEstimator b;", "EstimatorNode node;", "jle::EstimatorConfig c;",
                 "smoothedEstimatorConfig(s)", 'py::class_<PyEstimator> c(m, "Estimator",']:
        assert not BEHIND_THE_PIPELINE.search(line), line
