// process_bag and make_example_bag, run as processes on bags written here: process_bag
// must give what the estimator gives when driven directly with the same messages (its
// plumbing: topics, partial-name mapping, wrench frames, settings file, CSV and bag
// output), it must agree with the exact efforts make_example_bag computes from the
// analytic trajectory (the whole chain, derivatives estimated from positions), and it
// must refuse bad input with a message naming the culprit.
#include <joint_load_estimator/Contact.h>
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <geometry_msgs/WrenchStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <jle_testing/tool_test.hpp>

#include <jle_testing/panda_contacts.hpp>

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const std::string kData = JLE_TEST_DATA;
const std::string kPanda = kData + "/urdf/panda_demo.urdf";
constexpr double kPi = 3.141592653589793;

// ------------------------------------------------------------------ processes, files

using jle_test::quote;
using jle_test::readFile;
using jle_test::writeFile;

struct Result {
  int status = -1;     // exit status, -1 if the process did not exit normally
  std::string output;  // standard output and error
};

Result run(const std::string& command) {
  Result r;
  std::FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (p == nullptr) return r;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, p)) > 0) r.output.append(buffer, n);
  const int status = pclose(p);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// A CSV of numbers, parsed here (the tools' reader is not its own judge).
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
};

Table readCsv(const std::string& path) {
  Table t;
  std::ifstream in(path);
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string cell;
    std::vector<double> row;
    while (std::getline(s, cell, ',')) {
      if (first)
        t.header.push_back(cell);
      else
        row.push_back(std::strtod(cell.c_str(), nullptr));
    }
    if (!first) t.rows.push_back(row);
    first = false;
  }
  return t;
}

class ProcessBagTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("jle_test_process_bag_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // process_bag with kConfig on clean.bag and on NAME.bag, each to its CSV: NAME's run.
  Result runBesideClean(const std::string& name);
  // NAME.csv is clean.csv, row for row (more than 100 rows).
  void expectCleanCsv(const std::string& name);

  fs::path dir_;
};

// ------------------------------------------------------------ a bag written by the test

// The arm's "ready" pose and a smooth motion about it; the fingers still.
const std::vector<std::string> kJoints = {"panda_joint1", "panda_joint2",       "panda_joint3",
                                          "panda_joint4", "panda_joint5",       "panda_joint6",
                                          "panda_joint7", "panda_finger_joint1"};
double position(std::size_t k, double t) {
  const double ready[] = {0.0, -kPi / 4, 0.0, -3 * kPi / 4, 0.0, kPi / 2, kPi / 4, 0.02};
  if (k == 7) return ready[k];
  return ready[k] + 0.3 * std::sin(2 * kPi * (0.3 + 0.1 * static_cast<double>(k)) * t + k);
}

struct Messages {
  // In time order, wrench samples between the joint samples.
  std::vector<std::pair<ros::Time, sensor_msgs::JointState>> joints;
  std::vector<std::pair<ros::Time, geometry_msgs::WrenchStamped>> wrenches;
};

// 300 joint states at 1 kHz (names reversed and an extra joint the model lacks: the
// mapping by name is exercised), efforts = 100 + sample index (to pair with the
// estimate), and a wrench at 400 Hz stamped between the joint samples, expressed in
// panda_hand_tcp (rotated and offset from panda_link8, where it is configured to act).
Messages makeMessages() {
  Messages m;
  for (int i = 0; i < 300; ++i) {
    const double t = 0.001 * i;
    sensor_msgs::JointState js;
    js.header.stamp = ros::Time(2000.0) + ros::Duration(t);
    js.name.push_back("not_in_the_model");
    js.position.push_back(0.5);
    js.effort.push_back(0.0);
    for (std::size_t k = kJoints.size(); k-- > 0;) {
      js.name.push_back(kJoints[k]);
      js.position.push_back(position(k, t));
      js.effort.push_back(100.0 + i + 0.1 * static_cast<double>(k));
    }
    m.joints.emplace_back(js.header.stamp, js);
  }
  for (int i = 0; i < 120; ++i) {
    const double t = 0.0025 * i + 0.0003;
    geometry_msgs::WrenchStamped w;
    w.header.stamp = ros::Time(2000.0) + ros::Duration(t);
    w.header.frame_id = "panda_hand_tcp";
    w.wrench.force.x = 5.0 * std::sin(3 * t);
    w.wrench.force.y = -3.0;
    w.wrench.force.z = -15.0 + 2.0 * std::cos(5 * t);
    w.wrench.torque.x = 0.2;
    w.wrench.torque.y = -0.1 * std::sin(7 * t);
    w.wrench.torque.z = 0.05;
    m.wrenches.emplace_back(w.header.stamp, w);
  }
  return m;
}

void writeBag(const std::string& path, const Messages& m) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (const auto& j : m.joints) bag.write("/arm/joint_states", j.first, j.second);
  for (const auto& w : m.wrenches) bag.write("/ft", w.first, w.second);
}

const char* const kConfig = R"(# the test's settings
joint_states_topic: arm/joint_states
joints: [panda_joint2, panda_joint4, panda_joint7]
decimation: 2
gravity: [0.0, 0.0, -9.81]
differentiator:
  type: savitzky_golay
  window: 11
  order: 3
  delay: 5
wrenches:
  - topic: /ft
    link: panda_link8
    sign: -1
    timeout: 0.5
)";

Result ProcessBagTest::runBesideClean(const std::string& name) {
  writeFile(path("config.yaml"), kConfig);
  const std::string tool = std::string(JLE_PROCESS_BAG) + " --urdf " + quote(kPanda) +
                           " --config " + quote(path("config.yaml"));
  const Result clean =
      run(tool + " --bag " + quote(path("clean.bag")) + " --csv " + quote(path("clean.csv")));
  EXPECT_EQ(clean.status, 0) << clean.output;
  return run(tool + " --bag " + quote(path(name + ".bag")) + " --csv " +
             quote(path(name + ".csv")));
}

void ProcessBagTest::expectCleanCsv(const std::string& name) {
  const Table a = readCsv(path("clean.csv")), b = readCsv(path(name + ".csv"));
  EXPECT_EQ(b.header, a.header);
  ASSERT_EQ(b.rows.size(), a.rows.size());
  ASSERT_GT(a.rows.size(), 100u);
  for (std::size_t i = 0; i < a.rows.size(); ++i) EXPECT_EQ(b.rows[i], a.rows[i]) << "row " << i;
}

// The estimator of kConfig, configured here by hand (not by the settings parser); with
// `smoothed`, its smoothed stream's (the default: constant-jerk Kalman smoother, process
// noise 1e3, measurement noise 1e-4, lag 0.2 s; docs/how_it_works.md "Two streams").
jle::Estimator referenceEstimator(const jle::Model<double>& model, bool smoothed) {
  jle::EstimatorConfig config;
  if (smoothed) {
    config.differentiator.type = jle::DifferentiatorType::kKalman;
    config.differentiator.kalman_model = jle::KalmanModel::kConstantJerk;
    config.differentiator.process_noise = 400.0;  // defaultSmoother()
    config.differentiator.measurement_noise = 1e-4;
    config.differentiator.lag = 0.2;
  } else {
    config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
    config.differentiator.window = 11;
    config.differentiator.order = 3;
    config.differentiator.delay = 5;
  }
  config.gravity_world = Eigen::Vector3d(0.0, 0.0, -9.81);
  config.decimation = 2;
  jle::WrenchInputConfig input;
  input.name = "/ft";
  input.link = "panda_link8";
  input.sign = -1.0;
  input.timeout = 0.5;
  config.wrenches.push_back(input);
  return jle::Estimator(model, config);
}

// panda_hand_tcp in panda_link8, from the URDF's numbers: panda_hand_joint turns by
// -pi/4 about z at the flange, panda_hand_tcp_joint is 0.1034 m along the hand's z.
const Eigen::Matrix3d kR_link8_tcp =
    Eigen::AngleAxisd(-kPi / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
const Eigen::Vector3d kP_link8_tcp(0.0, 0.0, 0.1034);

struct Expected {
  std::vector<double> t;
  std::vector<std::vector<double>> values;  // per row: fx..effort per published joint
  std::vector<std::vector<double>> measured;
};

// The estimator's published loads into a row of `e`.
void take(const jle::Estimator& estimator, const std::vector<int>& published,
          const ros::Time& origin, const std::map<double, std::vector<double>>& efforts,
          Expected& e) {
  e.t.push_back((origin + ros::Duration(estimator.last().stamp())).toSec());
  std::vector<double> row;
  for (int s : published) {
    const jle::Data<double>& d = estimator.last().data();
    for (int c = 0; c < 3; ++c) row.push_back(d.force[static_cast<std::size_t>(s)][c]);
    for (int c = 0; c < 3; ++c) row.push_back(d.moment[static_cast<std::size_t>(s)][c]);
    row.push_back(d.effort[static_cast<std::size_t>(s)]);
  }
  e.values.push_back(row);
  e.measured.push_back(efforts.at(estimator.last().stamp()));
}

// Drives the estimator directly with the messages, in time order (and to the end of the
// stream: a smoother's last samples).
Expected expectedLoads(const Messages& m, bool smoothed = false) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kPanda);
  jle::Estimator estimator = referenceEstimator(model, smoothed);
  const std::vector<int> published = {model.segmentOfJoint("panda_joint2"),
                                      model.segmentOfJoint("panda_joint4"),
                                      model.segmentOfJoint("panda_joint7")};
  std::map<double, std::vector<double>> efforts;  // by stamp, of the published joints
  Expected e;
  // process_bag's time axis: seconds since the whole second of the first stamp.
  const ros::Time origin(m.joints.front().first.sec, 0);
  auto rel = [&](const ros::Time& t) { return (t - origin).toSec(); };
  std::size_t w = 0;
  for (const auto& j : m.joints) {
    for (; w < m.wrenches.size() && m.wrenches[w].first <= j.first; ++w) {
      const geometry_msgs::Wrench& msg = m.wrenches[w].second.wrench;
      const Eigen::Vector3d f(msg.force.x, msg.force.y, msg.force.z);
      const Eigen::Vector3d mo(msg.torque.x, msg.torque.y, msg.torque.z);
      const Eigen::Vector3d f_link = kR_link8_tcp * f;
      const Eigen::Vector3d m_link = kR_link8_tcp * mo + kP_link8_tcp.cross(f_link);
      estimator.addWrench(0, rel(m.wrenches[w].first), f_link, m_link);
    }
    std::vector<double> q(static_cast<std::size_t>(model.nq));
    for (std::size_t i = 0; i < j.second.name.size(); ++i)
      for (int k = 0; k < model.nq; ++k)
        if (model.coordinate_names[static_cast<std::size_t>(k)] == j.second.name[i])
          q[static_cast<std::size_t>(k)] = j.second.position[i];
    std::vector<double>& effort = efforts[rel(j.first)];
    for (const char* name : {"panda_joint2", "panda_joint4", "panda_joint7"})
      for (std::size_t i = 0; i < j.second.name.size(); ++i)
        if (j.second.name[i] == name) effort.push_back(j.second.effort[i]);
    if (estimator.addJointSample(rel(j.first), q.data()) != jle::SampleStatus::kPublished) continue;
    take(estimator, published, origin, efforts, e);
  }
  jle::SampleStatus status;
  while (estimator.flush(status))
    if (status == jle::SampleStatus::kPublished) take(estimator, published, origin, efforts, e);
  return e;
}

// 1e-9 relative (absolute below 1): the CSV holds 17 significant digits and both sides
// run the same arithmetic on the same inputs, so any difference is a plumbing defect
// (a wrong frame, sign, pairing or order moves the loads by far more).
void expectClose(double actual, double expected, const std::string& what) {
  EXPECT_NEAR(actual, expected, 1e-9 * std::max(1.0, std::abs(expected))) << what;
}

// The status column (last): the records of the first plausibility/settle_time (0.05 s)
// after the start are settling (bit 1), every later one trusted (0): the wrench is fresh.
void expectStatus(const Table& csv) {
  ASSERT_FALSE(csv.rows.empty());
  const double start = csv.rows.front()[0];
  EXPECT_EQ(static_cast<int>(csv.rows.front().back()) & 1, 1);
  int trusted = 0;
  for (const std::vector<double>& row : csv.rows)
    if (row[0] > start + 0.06) {
      EXPECT_EQ(row.back(), 0.0) << "at " << row[0];
      ++trusted;
    }
  EXPECT_GT(trusted, 50);
}

TEST_F(ProcessBagTest, CsvEqualsTheEstimatorDrivenWithTheSameMessages) {
  const Messages m = makeMessages();
  writeBag(path("in.bag"), m);
  writeFile(path("config.yaml"), kConfig);
  const Result r = run(std::string(JLE_PROCESS_BAG) + " --bag " + quote(path("in.bag")) +
                       " --urdf " + quote(kPanda) + " --config " + quote(path("config.yaml")) +
                       " --csv " + quote(path("out.csv")));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("samples/s"), std::string::npos) << r.output;
  // The extra joint is reported once, by name.
  EXPECT_NE(r.output.find("'not_in_the_model'"), std::string::npos) << r.output;

  const Expected e = expectedLoads(m);
  const Table csv = readCsv(path("out.csv"));
  const std::vector<std::string> header = {"t",
                                           "panda_joint2.fx",
                                           "panda_joint2.fy",
                                           "panda_joint2.fz",
                                           "panda_joint2.mx",
                                           "panda_joint2.my",
                                           "panda_joint2.mz",
                                           "panda_joint2.effort",
                                           "panda_joint4.fx",
                                           "panda_joint4.fy",
                                           "panda_joint4.fz",
                                           "panda_joint4.mx",
                                           "panda_joint4.my",
                                           "panda_joint4.mz",
                                           "panda_joint4.effort",
                                           "panda_joint7.fx",
                                           "panda_joint7.fy",
                                           "panda_joint7.fz",
                                           "panda_joint7.mx",
                                           "panda_joint7.my",
                                           "panda_joint7.mz",
                                           "panda_joint7.effort",
                                           "status"};
  EXPECT_EQ(csv.header, header);
  // 300 samples, the first 10 fill the window, every second one is published.
  ASSERT_EQ(e.t.size(), 145u);
  ASSERT_EQ(csv.rows.size(), e.t.size());
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    ASSERT_EQ(csv.rows[i].size(), header.size());
    expectClose(csv.rows[i][0], e.t[i], "t, row " + std::to_string(i));
    for (std::size_t c = 1; c + 1 < header.size(); ++c)
      expectClose(csv.rows[i][c], e.values[i][c - 1], header[c] + ", row " + std::to_string(i));
  }
  expectStatus(csv);
}

// The smoothed stream (on by default) against its estimator driven by hand: the same
// samples, the smoother's loads 0.2 s behind, every sample once (the last ones at the end).
TEST_F(ProcessBagTest, SmoothedCsvEqualsTheSmootherDrivenWithTheSameMessages) {
  const Messages m = makeMessages();
  writeBag(path("in.bag"), m);
  writeFile(path("config.yaml"), kConfig);
  const Result r = run(std::string(JLE_PROCESS_BAG) + " --bag " + quote(path("in.bag")) +
                       " --urdf " + quote(kPanda) + " --config " + quote(path("config.yaml")) +
                       " --smoothed-csv " + quote(path("smoothed.csv")));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("smoothed stream (lag 0.2 s)"), std::string::npos) << r.output;
  const Expected e = expectedLoads(m, true);
  const Table csv = readCsv(path("smoothed.csv"));
  ASSERT_EQ(csv.header.size(), 23u);
  EXPECT_EQ(csv.header.back(), "status");
  // Every second of the 300 samples (decimation 2): all of them reach the smoothed
  // stream, the end of the bag included.
  ASSERT_EQ(e.t.size(), 150u);
  ASSERT_EQ(csv.rows.size(), e.t.size());
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    expectClose(csv.rows[i][0], e.t[i], "t, row " + std::to_string(i));
    for (std::size_t c = 1; c + 1 < csv.header.size(); ++c)
      expectClose(csv.rows[i][c], e.values[i][c - 1], csv.header[c] + ", row " + std::to_string(i));
  }
  expectStatus(csv);
}

TEST_F(ProcessBagTest, BagOutputHoldsTheLoadsAndTheMeasuredEfforts) {
  const Messages m = makeMessages();
  writeBag(path("in.bag"), m);
  writeFile(path("config.yaml"), kConfig);
  const Result r = run(std::string(JLE_PROCESS_BAG) + " --bag " + quote(path("in.bag")) +
                       " --urdf " + quote(kPanda) + " --config " + quote(path("config.yaml")) +
                       " --output " + quote(path("out.bag")) + " --topic-prefix estimate/");
  ASSERT_EQ(r.status, 0) << r.output;
  const Expected e = expectedLoads(m);

  rosbag::Bag bag(path("out.bag"), rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery("/estimate/joint_loads"));
  // And the smoothed stream's, every sample once (checked against its estimator below).
  rosbag::View smoothed(bag, rosbag::TopicQuery("/estimate/smoothed/joint_loads"));
  EXPECT_EQ(smoothed.size(), expectedLoads(m, true).t.size());
  EXPECT_EQ(view.size() + smoothed.size(), rosbag::View(bag).size());
  std::size_t i = 0;
  for (const rosbag::MessageInstance& instance : view) {
    EXPECT_EQ(instance.getTopic(), "/estimate/joint_loads");
    const auto msg = instance.instantiate<joint_load_estimator::JointLoads>();
    ASSERT_TRUE(msg != nullptr);
    ASSERT_LT(i, e.t.size());
    // Bag time = the estimate's stamp, which lags the newest sample by the delay.
    EXPECT_EQ(instance.getTime(), msg->header.stamp);
    expectClose(msg->header.stamp.toSec(), e.t[i], "stamp");
    ASSERT_EQ(msg->name,
              (std::vector<std::string>{"panda_joint2", "panda_joint4", "panda_joint7"}));
    for (std::size_t j = 0; j < 3; ++j) {
      const geometry_msgs::Wrench& w = msg->wrench[j];
      const double got[] = {w.force.x,  w.force.y,  w.force.z,     w.torque.x,
                            w.torque.y, w.torque.z, msg->effort[j]};
      for (int c = 0; c < 7; ++c)
        expectClose(got[c], e.values[i][7 * j + c], "message " + std::to_string(i));
      // The measured effort of the sample the estimate describes, exactly.
      EXPECT_EQ(msg->measured_effort[j], e.measured[i][j]);
    }
    ++i;
  }
  EXPECT_EQ(i, e.t.size());
}

// ------------------------------------------------- the analytic bag of make_example_bag

// A Savitzky-Golay fit centred on the estimate, whose error on these slow sines is
// tiny; the sensor's wrench, expressed at the TCP (make_example_bag --sensor-frame
// panda_hand_tcp), acts on panda_link8: 0.1034 m and -pi/4 about z away.
const char* const kCentredConfig = R"(differentiator:
  type: savitzky_golay
  window: 21
  order: 4
  delay: centred
wrenches:
  - topic: /ft_sensor/wrench
    link: panda_link8
)";

struct Comparison {
  std::size_t rows = 0;
  double max_error = 0.0;   // max |estimated - exact effort| over joints and rows [N m]
  double max_effort = 0.0;  // max |exact effort|
};

// make_example_bag's analytic bag of `seconds` at `bag` (seed 7, efforts stored, the
// sensor's wrench at the TCP).
Result makeExampleBag(const std::string& bag, int seconds) {
  return run(std::string(JLE_MAKE_EXAMPLE_BAG) + " --urdf " + quote(kPanda) + " --output " +
             quote(bag) + " --duration " + std::to_string(seconds) +
             " --effort --seed 7 --sensor-frame panda_hand_tcp");
}

// The estimated efforts against the exact ones make_example_bag stored in the joint states;
// rows less than `margin` [s] from the first or the last row left out.
Comparison compareWithExact(const std::string& csv_path, const std::string& bag_path,
                            double margin = 0.0) {
  std::map<long long, std::map<std::string, double>> exact;  // by stamp [ns]
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/joint_states"))) {
    const auto js = m.instantiate<sensor_msgs::JointState>();
    for (std::size_t i = 0; i < js->name.size(); ++i)
      exact[static_cast<long long>(js->header.stamp.toNSec())][js->name[i]] = js->effort[i];
  }
  const Table csv = readCsv(csv_path);
  Comparison c;
  for (const std::vector<double>& row : csv.rows) {
    if (row[0] - csv.rows.front()[0] < margin || csv.rows.back()[0] - row[0] < margin) continue;
    const long long ns = std::llround(row[0] * 1e6) * 1000;  // stamps are whole microseconds
    const auto it = exact.find(ns);
    EXPECT_NE(it, exact.end()) << "no joint state at " << row[0];
    if (it == exact.end()) continue;
    for (std::size_t col = 1; col < csv.header.size(); ++col) {
      const std::string& name = csv.header[col];
      const std::size_t dot = name.rfind('.');
      if (dot == std::string::npos || name.substr(dot) != ".effort") continue;  // status
      const double truth = it->second.at(name.substr(0, dot));
      c.max_error = std::max(c.max_error, std::abs(row[col] - truth));
      c.max_effort = std::max(c.max_effort, std::abs(truth));
    }
    ++c.rows;
  }
  return c;
}

TEST_F(ProcessBagTest, AgreesWithTheExactEffortsOfTheExampleBag) {
  Result r = makeExampleBag(path("example.bag"), 1);
  ASSERT_EQ(r.status, 0) << r.output;
  writeFile(path("centred.yaml"), kCentredConfig);
  r = run(std::string(JLE_PROCESS_BAG) + " --bag " + quote(path("example.bag")) + " --urdf " +
          quote(kPanda) + " --config " + quote(path("centred.yaml")) + " --csv " +
          quote(path("loads.csv")));
  ASSERT_EQ(r.status, 0) << r.output;
  const Comparison with = compareWithExact(path("loads.csv"), path("example.bag"));
  // 1000 samples, the first 20 fill the window.
  EXPECT_EQ(with.rows, 980u);
  EXPECT_GT(with.max_effort, 10.0);
  // A centred 4th-order fit over 21 ms of sines below 0.4 Hz (w <= 2.5 rad/s): its
  // acceleration error is of order A w^6 T^4 ~ 1e-6 * 1e-8 rad/s^2 (T = 10 ms), and the
  // rounding of stamps near 1000 s (1e-13 s) and of positions adds about 1e-9 rad/s^2;
  // with inertias below 1 kg m^2 the efforts agree to about 1e-8 N m. 1e-6 N m leaves
  // a margin and is far below what a wrong sign, frame or instant of the wrench gives
  // (the payload and push move the efforts by newtons, 1 ms of lag by 1e-3 N m).
  EXPECT_LT(with.max_error, 1e-6);

  // The same without the sensor: the payload and the push are missing, so the check
  // above is not blind to the wrench.
  writeFile(path("none.yaml"),
            "differentiator: {type: savitzky_golay, window: 21, order: 4, "
            "delay: centred}\n");
  r = run(std::string(JLE_PROCESS_BAG) + " --bag " + quote(path("example.bag")) + " --urdf " +
          quote(kPanda) + " --config " + quote(path("none.yaml")) + " --csv " +
          quote(path("bare.csv")));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_GT(compareWithExact(path("bare.csv"), path("example.bag")).max_error, 1.0);
}

// --zero-phase: the whole bag smoothed zero-phase first, then the message path with
// central differences. The example bag's sines (below 0.4 Hz) pass a 10 Hz cutoff with a
// gain of 1 - 7e-12; central differences at 1 kHz err by (w h)^2 / 12 < 1e-6 relative.
// Near the ends, odd reflection pulls the acceleration towards zero (docs/studies/zero_phase.md):
// the comparison leaves out 0.5 s (five periods of the cutoff) at each end, where that
// transient has decayed from 16 N m at the ends to below 1e-4 N m (measured: 6.3e-5; 0.016
// at 0.25 s). 1e-3 N m leaves a margin and is far below what a wrench left unfiltered,
// unfed or filtered at another cutoff gives (the push moves the efforts by newtons).
TEST_F(ProcessBagTest, ZeroPhaseSmoothingAgreesWithTheExactEffortsAwayFromTheEnds) {
  Result r = makeExampleBag(path("example.bag"), 3);
  ASSERT_EQ(r.status, 0) << r.output;
  writeFile(path("centred.yaml"), kCentredConfig);
  const std::string base = std::string(JLE_PROCESS_BAG) + " --bag " + quote(path("example.bag")) +
                           " --urdf " + quote(kPanda) + " --config " + quote(path("centred.yaml"));
  r = run(base + " --zero-phase 10 --csv " + quote(path("smoothed.csv")));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("cutoff 10 Hz (given)"), std::string::npos) << r.output;
  const Comparison inner = compareWithExact(path("smoothed.csv"), path("example.bag"), 0.5);
  EXPECT_EQ(inner.rows, 1998u);  // 2998 loads (not of the first and last sample), 1000 left out
  EXPECT_GT(inner.max_effort, 10.0);
  EXPECT_LT(inner.max_error, 1e-3);

  r = run(base + " --zero-phase auto --csv " + quote(path("auto.csv")));
  ASSERT_EQ(r.status, 0) << r.output;
  // The default rule without velocities in the joint states: the noise spectrum, which
  // finds no noise floor in the example bag's exact positions and says so.
  EXPECT_NE(r.output.find("(noise spectrum)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("process_bag: warning: zero-phase cutoff: 50 Hz (noise spectrum) is "
                          "on the search's highest bound"),
            std::string::npos)
      << r.output;
  r = run(base + " --zero-phase 0 --csv " + quote(path("bad.csv")));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--zero-phase"), std::string::npos) << r.output;
  r = run(base + " --zero-phase 10 --cutoff-rule gcv --csv " + quote(path("bad.csv")));
  EXPECT_EQ(r.status, 2) << r.output;
}

TEST_F(ProcessBagTest, ExampleBagIsDeterministic) {
  const std::string base =
      std::string(JLE_MAKE_EXAMPLE_BAG) + " --urdf " + quote(kPanda) + " --samples 200 --output ";
  ASSERT_EQ(run(base + quote(path("a.bag"))).status, 0);
  ASSERT_EQ(run(base + quote(path("b.bag"))).status, 0);
  ASSERT_EQ(run(base + quote(path("c.bag")) + " --seed 2").status, 0);
  EXPECT_EQ(readFile(path("a.bag")), readFile(path("b.bag")));
  EXPECT_NE(readFile(path("a.bag")), readFile(path("c.bag")));
  EXPECT_FALSE(fs::exists(path("a.bag.partial")));
}

// ---------------------------------------------------------------------------- bad input

// rosbag record may write the latched /tf_static after the first messages that need it:
// its frames hold from the bag's start (the node's listener waits for them, tf_wait).
// Wrenches in a frame that only a /tf_static at the bag's end gives (panda_link8 ->
// ft_sensor, the pose of panda_hand_tcp) give the loads of the same wrenches in
// panda_hand_tcp; before, each was dropped for an unresolved frame.
TEST_F(ProcessBagTest, StaticTransformsWrittenLateHoldFromTheStart) {
  Messages m = makeMessages();
  writeBag(path("urdf_frame.bag"), m);
  for (auto& w : m.wrenches) w.second.header.frame_id = "ft_sensor";
  {
    rosbag::Bag bag(path("late_static.bag"), rosbag::bagmode::Write);
    for (const auto& j : m.joints) bag.write("/arm/joint_states", j.first, j.second);
    for (const auto& w : m.wrenches) bag.write("/ft", w.first, w.second);
    geometry_msgs::TransformStamped t;
    t.header.stamp = m.joints.back().first;
    t.header.frame_id = "panda_link8";
    t.child_frame_id = "ft_sensor";
    t.transform.translation.z = 0.1034;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(-M_PI / 4.0, Eigen::Vector3d::UnitZ()));
    t.transform.rotation.w = q.w();
    t.transform.rotation.z = q.z();
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(t);
    bag.write("/tf_static", m.joints.back().first + ros::Duration(0.01), tf);
  }
  writeFile(path("config.yaml"), kConfig);
  const std::string tool = std::string(JLE_PROCESS_BAG) + " --urdf " + quote(kPanda) +
                           " --config " + quote(path("config.yaml"));
  Result r =
      run(tool + " --bag " + quote(path("urdf_frame.bag")) + " --csv " + quote(path("a.csv")));
  ASSERT_EQ(r.status, 0) << r.output;
  r = run(tool + " --bag " + quote(path("late_static.bag")) + " --csv " + quote(path("b.csv")));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("unresolved frame"), std::string::npos) << r.output;
  const Table a = readCsv(path("a.csv")), b = readCsv(path("b.csv"));
  ASSERT_EQ(a.header, b.header);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  ASSERT_EQ(a.rows.size(), 145u);
  for (std::size_t i = 0; i < a.rows.size(); ++i)
    for (std::size_t c = 0; c < a.header.size(); ++c)
      EXPECT_NEAR(b.rows[i][c], a.rows[i][c], 1e-9) << a.header[c] << ", row " << i;
}

// The Panda with panda_link7's inertia turned into one no rigid body has (ixx negated,
// as an identified parameter set may give it): refused by default naming the link and
// the violation; accepted with --accept-nonphysical-inertia or the setting
// accept_nonphysical_inertia: true, with a warning naming them.
// ------------------------------------------ external efforts: issue 40's contact scene

// jle_testing::PandaContacts (three step contacts; efforts from KDL's RNE with external
// forces, 0.1 N m of effort noise, 1e-4 rad of position noise) as a bag, through
// process_bag with two contact links. Its ~contact events and ~external_wrench/<link>
// against the scene's truth: each contact starts within 20 ms of its onset and none
// elsewhere; from 20 ms into a contact the last event names its link, and its `contacts`
// the configured contact acting (none for link 4's: no configured contact can load joint 4
// alone); every event is a start, an end or a change of joint, never a repeat; and a
// contact link's wrench is nonzero only while its contact acts (or is released).
const char* const kContactConfig = R"(external_effort:
  enabled: true
  noise_multiple: 6.0
  contacts:
    - {link: panda_hand_tcp, point: [0.0, 0.05, 0.0], force_only: true}
    - {link: panda_link5, point: [0.0, 0.08, -0.1], force_only: true}
)";

struct ContactEvent {
  double t = 0.0;  // [s] from the bag's first stamp
  bool in_contact = false;
  std::string joint, link, contacts;  // contacts: space-separated
};

void writeContactScene(const std::string& bag_path, const jle_testing::PandaContacts& scene) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
  std::mt19937 rng(40);
  std::normal_distribution<double> gauss(0.0, 1.0);
  sensor_msgs::JointState js;
  for (int i = 1; i <= 7; ++i) js.name.push_back("panda_joint" + std::to_string(i));
  js.position.resize(7);
  const int n = static_cast<int>(jle_testing::PandaContacts::kDuration * 1000.0);
  for (int k = 0; k < n; ++k) {
    Eigen::VectorXd q, qd, qdd;
    scene.state(k * 1e-3, q, qd, qdd);
    js.effort = scene.efforts(k * 1e-3);
    for (int i = 0; i < 7; ++i) js.position[i] = q[i] + 1e-4 * gauss(rng);
    for (double& e : js.effort) e += 0.1 * gauss(rng);
    js.header.stamp.fromNSec(1000000000000ULL + static_cast<std::uint64_t>(k) * 1000000ULL);
    bag.write("/joint_states", js.header.stamp, js);
  }
}

std::vector<ContactEvent> readContactEvents(rosbag::Bag& bag) {
  std::vector<ContactEvent> events;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/est/contact"))) {
    const auto msg = m.instantiate<joint_load_estimator::Contact>();
    if (msg == nullptr) continue;
    ContactEvent e;
    e.t = (msg->header.stamp - ros::Time(1000.0)).toSec();
    e.in_contact = msg->in_contact;
    e.joint = msg->joint;
    e.link = msg->link;
    for (const std::string& c : msg->contacts) e.contacts += c + " ";
    events.push_back(e);
  }
  return events;
}

TEST_F(ProcessBagTest, ContactEventsAndWrenchesFollowTheScene) {
  const std::string urdf = kData + "/urdf/chains/panda_chain.urdf";
  const jle_testing::PandaContacts scene(readFile(urdf));
  writeContactScene(path("contacts.bag"), scene);
  writeFile(path("contacts.yaml"), kContactConfig);
  const Result r = run(std::string(JLE_PROCESS_BAG) + " --bag " + quote(path("contacts.bag")) +
                       " --urdf " + quote(urdf) + " --config " + quote(path("contacts.yaml")) +
                       " --output " + quote(path("contacts_out.bag")) + " --topic-prefix /est");
  ASSERT_EQ(r.status, 0) << r.output;
  rosbag::Bag bag(path("contacts_out.bag"), rosbag::bagmode::Read);
  const std::vector<ContactEvent> events = readContactEvents(bag);
  ASSERT_FALSE(events.empty());
  for (const ContactEvent& e : events)
    std::printf("contact event %.3f s: %s %s (%s) [%s]\n", e.t, e.in_contact ? "in" : "out",
                e.joint.c_str(), e.link.c_str(), e.contacts.c_str());
  const auto acting = [&](double t) {  // the scene contact acting or released at t, -1 none
    for (std::size_t c = 0; c < scene.contacts.size(); ++c)
      if (t >= scene.contacts[c].t_on && t < scene.contacts[c].t_off + 0.15)
        return static_cast<int>(c);
    return -1;
  };
  const char* const expected_contacts[3] = {"panda_hand_tcp ", "", "panda_link5 "};
  std::vector<int> starts(scene.contacts.size(), 0);
  for (std::size_t i = 0; i < events.size(); ++i) {
    const ContactEvent& e = events[i];
    const bool was = i > 0 && events[i - 1].in_contact;
    if (e.in_contact && was) {
      EXPECT_NE(e.joint, events[i - 1].joint) << "a repeated event at " << e.t;
    }
    if (!e.in_contact) {
      EXPECT_TRUE(was) << "an end without a start at " << e.t;
    }
    if (!e.in_contact || was) continue;
    const int c = acting(e.t);
    ASSERT_GE(c, 0) << "a contact started at " << e.t << " s, in free motion";
    EXPECT_LE(e.t - scene.contacts[c].t_on, 0.020) << scene.contacts[c].link;
    ++starts[c];
  }
  for (std::size_t c = 0; c < scene.contacts.size(); ++c) {
    EXPECT_EQ(starts[c], 1) << scene.contacts[c].link;
    // From 20 ms into the contact to its end, the state the last event set.
    for (double t = scene.contacts[c].t_on + 0.02; t < scene.contacts[c].t_off; t += 0.01) {
      const ContactEvent* last = nullptr;
      for (const ContactEvent& e : events)
        if (e.t <= t + 1e-9) last = &e;
      ASSERT_NE(last, nullptr);
      EXPECT_TRUE(last->in_contact) << t;
      EXPECT_EQ(last->link, scene.contacts[c].detected_link) << t;
      EXPECT_EQ(last->contacts, expected_contacts[c]) << t;
    }
  }
  // Each contact link's wrench: nonzero only while its own contact acts (or is released),
  // and present from 20 ms into it.
  const char* const links[2] = {"panda_hand_tcp", "panda_link5"};
  const int scene_contact[2] = {0, 2};
  for (int k = 0; k < 2; ++k) {
    long messages = 0, phantom = 0, missing = 0;
    for (const rosbag::MessageInstance& m :
         rosbag::View(bag, rosbag::TopicQuery(std::string("/est/external_wrench/") + links[k]))) {
      const auto w = m.instantiate<geometry_msgs::WrenchStamped>();
      ASSERT_NE(w, nullptr);
      ++messages;
      const double t = (w->header.stamp - ros::Time(1000.0)).toSec();
      const bool reported =
          w->wrench.force.x != 0.0 || w->wrench.force.y != 0.0 || w->wrench.force.z != 0.0;
      const jle_testing::StepContact& own = scene.contacts[scene_contact[k]];
      if (reported && acting(t) != scene_contact[k]) ++phantom;
      if (!reported && t >= own.t_on + 0.02 && t < own.t_off) ++missing;
      EXPECT_EQ(w->header.frame_id, links[k]);
    }
    EXPECT_GT(messages, 4000) << links[k];
    EXPECT_EQ(phantom, 0) << links[k];
    EXPECT_EQ(missing, 0) << links[k];
  }
}

TEST_F(ProcessBagTest, IdentifiedInertiaNeedsTheFlagOrTheSetting) {
  writeBag(path("in.bag"), makeMessages());
  writeFile(path("config.yaml"), kConfig);
  std::string urdf = readFile(kPanda);
  const std::string link7 = "<inertia ixx=\"0.012516\"";
  ASSERT_NE(urdf.find(link7), std::string::npos);
  urdf.replace(urdf.find(link7), link7.size(), "<inertia ixx=\"-0.012516\"");
  writeFile(path("identified.urdf"), urdf);
  const std::string tool = std::string(JLE_PROCESS_BAG) + " --urdf " +
                           quote(path("identified.urdf")) + " --bag " + quote(path("in.bag")) +
                           " --csv " + quote(path("o.csv")) + " --config ";
  const std::string violation = "link 'panda_link7': inertia is not positive semi-definite";
  Result r = run(tool + quote(path("config.yaml")));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find(violation), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("o.csv")));
  r = run(tool + quote(path("config.yaml")) + " --accept-nonphysical-inertia");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("process_bag: warning: robot model: " + violation), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("not physical"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(path("o.csv")));
  fs::remove(path("o.csv"));
  writeFile(path("accept.yaml"), std::string(kConfig) + "accept_nonphysical_inertia: true\n");
  r = run(tool + quote(path("accept.yaml")));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(violation), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(path("o.csv")));
}

// Never silently wrong (docs/node.md): joint states no arm produces between the samples (a
// position of 1e300 rad, one joint 3 rad off) are refused, counted and named; the loads
// are those of the bag without them, to the bit, and the tool exits 0.
TEST_F(ProcessBagTest, AbsurdAndGlitchedPositionsChangeNoLoad) {
  const Messages m = makeMessages();
  writeBag(path("clean.bag"), m);
  Messages hostile = m;
  const auto glitch = [&](int after, double q2) {  // panda_joint2 set to q2, 0.5 ms later
    sensor_msgs::JointState js = m.joints[static_cast<std::size_t>(after)].second;
    js.header.stamp += ros::Duration(0.0005);
    for (std::size_t i = 0; i < js.name.size(); ++i)
      if (js.name[i] == "panda_joint2") js.position[i] = q2;
    hostile.joints.emplace_back(js.header.stamp, js);
  };
  glitch(100, 1e300);
  glitch(200, position(1, 0.2) + 3.0);
  writeBag(path("hostile.bag"), hostile);
  const Result r = runBesideClean("hostile");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("position of joint 'panda_joint2' is 1e+300"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("2 implausible"), std::string::npos) << r.output;  // the summary
  expectCleanCsv("hostile");
}

// Measured velocities (issue 37) through process_bag with the default settings: joint
// states that carry the exact velocities give other loads than the same positions alone
// (they are used); a NaN velocity of panda_joint2 in every tenth message drops no message
// (it costs that velocity only); velocities that are all NaN are none: the loads are the
// positions-only ones, bit for bit, every message kept.
TEST_F(ProcessBagTest, MeasuredVelocitiesAreUsedAndNaNOnesDropNothingElse) {
  const Messages m = makeMessages();
  // Joint k's exact rate at time t (position()'s derivative; the fingers still).
  const auto rate = [](std::size_t k, double t) {
    if (k == 7) return 0.0;
    const double w = 2 * kPi * (0.3 + 0.1 * static_cast<double>(k));
    return 0.3 * w * std::cos(w * t + static_cast<double>(k));
  };
  // The messages with velocity(sample, joint k) (names as makeMessages orders them).
  const auto withVelocities = [&](const std::string& bag, auto velocity) {
    Messages v = m;
    for (std::size_t i = 0; i < v.joints.size(); ++i) {
      sensor_msgs::JointState& js = v.joints[i].second;
      js.velocity.assign(js.name.size(), 0.0);
      for (std::size_t n = 1; n < js.name.size(); ++n)
        js.velocity[n] = velocity(i, kJoints.size() - n);
    }
    writeBag(path(bag), v);
  };
  writeBag(path("q.bag"), m);
  withVelocities("qv.bag", [&](std::size_t i, std::size_t k) { return rate(k, 0.001 * i); });
  withVelocities("nan10.bag", [&](std::size_t i, std::size_t k) {
    return k == 1 && i % 10 == 5 ? std::nan("") : rate(k, 0.001 * i);
  });
  withVelocities("nan.bag", [](std::size_t, std::size_t) { return std::nan(""); });
  writeFile(path("config.yaml"), "joint_states_topic: arm/joint_states\n");
  std::map<std::string, Table> csv;
  for (const char* name : {"q", "qv", "nan10", "nan"}) {
    const Result r =
        run(std::string(JLE_PROCESS_BAG) + " --urdf " + quote(kPanda) + " --config " +
            quote(path("config.yaml")) + " --bag " + quote(path(name + std::string(".bag"))) +
            " --csv " + quote(path(name + std::string(".csv"))));
    ASSERT_EQ(r.status, 0) << name << ": " << r.output;
    EXPECT_EQ(r.output.find("invalid"), std::string::npos) << name << ": " << r.output;
    csv[name] = readCsv(path(name + std::string(".csv")));
  }
  const Table& q = csv["q"];
  ASSERT_GT(q.rows.size(), 250u);
  double moved = 0.0;  // the largest change of a load that the velocities make
  for (const char* name : {"qv", "nan10", "nan"}) {
    const Table& t = csv[name];
    ASSERT_EQ(t.header, q.header) << name;
    ASSERT_EQ(t.rows.size(), q.rows.size()) << name << ": a message dropped";
  }
  for (std::size_t i = 0; i < q.rows.size(); ++i) {
    EXPECT_EQ(csv["nan"].rows[i], q.rows[i]) << "row " << i;
    for (std::size_t c = 1; c < q.rows[i].size(); ++c)
      moved = std::max(moved, std::abs(csv["qv"].rows[i][c] - q.rows[i][c]));
  }
  // Far above the CSV's rounding (17 digits): the velocities change the loads.
  EXPECT_GT(moved, 1e-6);
  std::printf("largest change of a load by the measured velocities: %.3g\n", moved);
}

// Every joint state of the clean bag split over two publishers (names 0-3, the unknown
// joint among them, and 4-8, at the same stamp): merged into one sample per instant, the
// CSV is the clean one's, row for row; the summary counts the merged messages, none held
// (before, half of them were dropped as `stamp order` and their positions used late).
TEST_F(ProcessBagTest, SplitPublishersGiveTheLoadsOfOnePublisher) {
  const Messages m = makeMessages();
  writeBag(path("clean.bag"), m);
  Messages split = m;
  split.joints.clear();
  for (const auto& [stamp, js] : m.joints) {
    sensor_msgs::JointState a = js, b = js;
    const auto part = [](auto& v, std::size_t from, std::size_t to) {
      v.assign(v.begin() + static_cast<long>(from), v.begin() + static_cast<long>(to));
    };
    const std::size_t n = js.name.size();
    part(a.name, 0, 4), part(a.position, 0, 4), part(a.effort, 0, 4);
    part(b.name, 4, n), part(b.position, 4, n), part(b.effort, 4, n);
    split.joints.emplace_back(stamp, a);
    split.joints.emplace_back(stamp, b);
  }
  writeBag(path("split.bag"), split);
  const Result r = runBesideClean("split");
  ASSERT_EQ(r.status, 0) << r.output;
  // The first message waits for the other half, never received yet; 299 merged.
  EXPECT_NE(r.output.find("process_bag: 299 joint states merged with other publishers'"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("1 waiting for a joint"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("held a joint"), std::string::npos) << r.output;
  expectCleanCsv("split");
}

TEST_F(ProcessBagTest, RefusesBadInputNamingTheCulprit) {
  const Messages m = makeMessages();
  writeBag(path("in.bag"), m);
  writeFile(path("config.yaml"), kConfig);
  const std::string tool = std::string(JLE_PROCESS_BAG) + " --urdf " + quote(kPanda);

  // A missing bag.
  Result r = run(tool + " --bag " + quote(path("missing.bag")) + " --csv " + quote(path("o.csv")));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find(path("missing.bag")), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("o.csv")));

  // A misspelt key in the settings.
  writeFile(path("bad.yaml"), std::string(kConfig) + "decimaton: 3\n");
  r = run(tool + " --bag " + quote(path("in.bag")) + " --config " + quote(path("bad.yaml")) +
          " --csv " + quote(path("o.csv")));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("'decimaton'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(path("bad.yaml")), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("o.csv")));

  // The joint states on another topic than the bag has (the default joint_states).
  r = run(tool + " --bag " + quote(path("in.bag")) + " --csv " + quote(path("o.csv")));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("'/joint_states'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("/arm/joint_states"), std::string::npos) << r.output;  // what there is
  EXPECT_FALSE(fs::exists(path("o.csv")));

  // A wrench in a frame that moves relative to its link (tf2 would be needed).
  std::string moving = kConfig;
  moving.replace(moving.find("link: panda_link8"), 17, "link: panda_link3");
  writeFile(path("moving.yaml"), moving);
  r = run(tool + " --bag " + quote(path("in.bag")) + " --config " + quote(path("moving.yaml")) +
          " --output " + quote(path("o.bag")));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("'panda_hand_tcp'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("'panda_link3'"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("o.bag")));
  EXPECT_FALSE(fs::exists(path("o.bag.partial")));

  // A bag cut short (a recorder killed): rosbag's words and the repair.
  fs::copy_file(path("in.bag"), path("cut.bag"));
  fs::resize_file(path("cut.bag"), fs::file_size(path("cut.bag")) * 2 / 3);
  r = run(tool + " --bag " + quote(path("cut.bag")) + " --config " + quote(path("config.yaml")) +
          " --csv " + quote(path("o.csv")));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("'rosbag reindex " + path("cut.bag") + "'"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(path("o.csv")));

  // Usage errors.
  r = run(tool + " --bag " + quote(path("in.bag")) + " --csv a.csv --output b.bag");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("exclude"), std::string::npos) << r.output;
  r = run(std::string(JLE_PROCESS_BAG) + " --bag " + quote(path("in.bag")));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--urdf"), std::string::npos) << r.output;
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
